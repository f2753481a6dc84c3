"""``ObjectSupport``: the support that carries the object until the fingers take it over.

The shipped tasks start with the object resting on a support while the fingers close on
it, and hand it over at 0.1 s. The support force is the object's weight turned upwards,
``-m g``, computed from the plant's own hand, so a heavier object (``--set
plant.object.mass=0.36``) is carried by a larger force without editing the diagram.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from blocks import Block
from blocks.engine.kernel import Kernel, Tunable

from .. import _native
from ..layouts import SUPPORT_CONTEXT, SUPPORT_RECORD
from ..records import KERNELS, context_of, hand_segment, record
from .hand_source import ModelsTheHand, hand_link, hand_of
from .port_info import DescribesHandPorts


support_pack = _native.support_pack
"""``support_pack(None, hand_vector, until) -> context``: [fx, fy, torque, until]
(``SUPPORT_CONTEXT``), the force 0 - m g (C)."""


class ObjectSupport(DescribesHandPorts, ModelsTheHand, Block):
    """The force of a support carrying the object's weight, removed at ``until``.

    Output ``y`` in the plant's ``f_ext`` layout (fx, fy, torque about the object's
    centre): ``-m g`` with torque 0 while ``t < until``, zero from ``until`` on (as a
    ``Step`` switches). ``m`` and ``g`` are those of the hand of the block named by
    ``hand`` (``hand: plant``).

    Parameters
    ----------
    hand : HandPlant or FMU
        the block that simulates the hand (hand: plant); an FMU must be one exported by
        'hierhand fmu export'; the hand is given once, on that block (from Python: the
        block or a Hand); the support carries the weight of its object
    until : float
        time, s, from which the support is gone (the hand-over); the force is zero from
        then on
    """

    type_name = "ObjectSupport"
    time_varying = True

    def __init__(self, hand, until: float = 0.1):
        self.hand = hand_of(hand)
        if isinstance(until, bool) or not isinstance(until, (int, float)) or not math.isfinite(until):
            raise ValueError(f"parameter 'until' must be a finite time in seconds, got {until!r}")
        self.until = float(until)
        self._links = hand_link(hand, SUPPORT_RECORD.SEGMENT)
        self._context = support_pack(None, self.hand.vector, self.until)  # [force, until], in C
        self.force = self._context[SUPPORT_CONTEXT.slice("FORCE")].copy()
        self.force.flags.writeable = False
        self.inputs = {}
        self.outputs = {"y": 3}
        self.feedthrough = False

    def output(self, t: float, state: Any, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        return {"y": self.force.copy() if t < self.until else np.zeros(3)}

    def kernel(self) -> Kernel | None:
        """``output`` in C (kernel type ``ObjectSupport``): the force while ``t < until``,
        zero from then on, from the record ``[hand segment, until]``. In an exported FMU
        ``until`` is tunable, and the force follows the plant's object mass."""
        held = getattr(self, "_kernel", None)
        if held is None:
            rec = record("ObjectSupport", hand_segment(self.hand, False), [self.until],
                         tunables=(Tunable("until", SUPPORT_RECORD.UNTIL, "time from which the support is gone", "s"),),
                         links=self._links)
            ctx = context_of(rec)
            held = self._kernel = Kernel(context=ctx.address, output=KERNELS["ObjectSupport.output"], owners=(ctx,),
                                         nogil=True, record=rec)
        return held
