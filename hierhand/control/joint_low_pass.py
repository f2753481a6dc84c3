"""``JointLowPass``: a first-order low-pass filter of the nine joint values, compiled.

Its law is C (``hierhand/csrc/joint_low_pass.c``, kernel type ``JointLowPass``); the
executor runs that kernel, and the Python methods call the same C functions, so the
filter has one definition. Its record, ``[time_constant, period]``, is the layout
``JOINT_LOW_PASS_RECORD`` of ``hierhand/csrc/layouts.h``.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from blocks import Block
from blocks.block import BlockError
from blocks.engine import compiled
from blocks.engine.kernel import Kernel, Tunable

from ..layouts import DIMENSIONS, JOINT_LOW_PASS_INPUTS, JOINT_LOW_PASS_RECORD as RECORD
from ..records import KERNELS, context_of, record

JOINTS = DIMENSIONS["JOINTS"]


class JointLowPass(Block):
    """First-order low-pass filter per joint: ``y_k = x_k``, ``x_{k+1} = x_k + (1 - a) (u_k - x_k)``
    with ``a = exp(-T / time_constant)`` at the block's period T, the exact discretisation
    of ``time_constant dy/dt = u - y`` with ``u`` held over each period. The output starts at
    zero, so a unit step gives ``y_k = 1 - a^k``. Use it to smooth a joint signal (a torque,
    a target) before another block reads it; it needs a period of its own.

    Parameters
    ----------
    time_constant : float
        seconds (> 0); the output covers 63 % of a step in this time
    """

    type_name = "JointLowPass"
    feedthrough = False

    def __init__(self, time_constant: float = 0.01):
        if isinstance(time_constant, bool) or not isinstance(time_constant, (int, float)):
            raise ValueError(f"parameter 'time_constant' must be a time > 0 in seconds, got {time_constant!r}")
        self.time_constant = float(time_constant)
        context_of(self._record(math.nan))  # the kind's constructor checks the time constant
        self.inputs = dict(JOINT_LOW_PASS_INPUTS)
        self.outputs = {"y": JOINTS}
        self._kernel: Kernel | None = None

    def bind(self, period) -> None:
        if period is None:
            raise ValueError("JointLowPass needs an explicit period (its filter's step), e.g. '1 ms'")
        super().bind(period)
        self._kernel = None

    def initial_state(self) -> np.ndarray:
        return np.zeros(JOINTS)

    def kernel(self) -> Kernel | None:
        """``output`` and ``update`` in C, in a context the kind's constructor builds from the
        record ``[time_constant, period]``; None before ``bind``. In an exported FMU the time
        constant is tunable."""
        if self.period is None:
            return None
        if self._kernel is None:
            rec = self._record(float(self.period))
            ctx = context_of(rec)
            self._kernel = Kernel(context=ctx.address, output=KERNELS["JointLowPass.output"],
                                  update=KERNELS["JointLowPass.update"], owners=(ctx,), nogil=True, record=rec)
        return self._kernel

    def output(self, t: float, state: np.ndarray, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        out = np.empty(JOINTS)
        self._call("output", t, np.array(state, dtype=np.float64), inputs, out)
        return {"y": out}

    def update(self, t: float, state: np.ndarray, inputs: Mapping[str, np.ndarray]) -> np.ndarray:
        next_state = np.array(state, dtype=np.float64)
        self._call("update", t, next_state, inputs, None)
        return next_state

    def _record(self, period: float) -> Any:
        return record("JointLowPass", [self.time_constant, period], tunables=_TUNABLES)

    def _call(self, phase: str, t: float, state: np.ndarray, inputs: Mapping[str, np.ndarray], out: Any) -> None:
        """One call of the kernel's C function of ``phase`` (the executor's own calls are these)."""
        kernel = self.kernel()
        if kernel is None:
            raise BlockError("JointLowPass is not bound to a period; call bind(period) first")
        u = np.ascontiguousarray(inputs["u"], dtype=np.float64)
        if u.shape != (JOINTS,):
            raise BlockError(f"JointLowPass input 'u' must have {JOINTS} values, got shape {u.shape}", port="u")
        compiled.native().call(phase, getattr(kernel, phase), kernel.context, float(t), state, [u], out)


_TUNABLES = (Tunable("time_constant", RECORD.TIME_CONSTANT, "time constant of the filter (> 0)", "s", minimum=0.0),)
"""JointLowPass's parameter an exported FMU lets an importer set."""
