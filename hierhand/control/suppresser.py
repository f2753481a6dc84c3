"""The suppresser block: lets voluntary motion override the grasping reflex, joint by joint.

Its law is ``suppresser_law`` (compiled, ``hierhand/csrc/suppresser.c``).
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from blocks import Block
from blocks.arrays import flat_float64, float_array
from blocks.engine.kernel import Kernel, Tunable

from ..layouts import SUPPRESS_GIVEN as GIVEN, SUPPRESS_INPUTS, SUPPRESS_OUT, SUPPRESS_RECORD, port_columns, ports
from ..model.port_info import DescribesHandPorts
from ..records import KERNELS, context_of, record
from .suppresser_law import check_steepness, mode_code, pack_params, suppress_output, suppress_update

_PORTS = port_columns(SUPPRESS_OUT)
"""The output ports (tau, tau_g_eff, share) and their columns of the law's output."""


class Suppresser(DescribesHandPorts, Block):
    """Actuator command ``tau = tau_g * sigmoid(S_a (S_b - g(tau_m))) + tau_m`` per joint.

    An optional input ``tau_ff`` (zero when unconnected) is added to the command
    unsuppressed: the manipulation controller's feedforward (finger gravity, the object's
    weight), which is not voluntary motion and must not weigh against the grasp.

    ``mode: signed`` is the paper's literal formula, g = tau_m, with tau_m signed positive
    against the joint's grasping torque: only voluntary motion that pulls against the grasp
    suppresses it (the paper gives no joint convention; in this hand's counter-clockwise
    angles the forefinger's pull off the object is a negative torque, the thumb's a positive
    one). ``mode: magnitude`` uses g = |tau_m|, which also suppresses a grasp that voluntary
    motion pushes along. ``enabled: false`` passes tau_g through unchanged, for the paper's
    comparison run without suppression.

    ``time_constant`` > 0 low-passes g before the sigmoid (first order, at the block's
    period; the block then needs one). The sigmoid closes a loop from the manipulation
    torque through the grasping torque and the finger back to the manipulation torque, of
    gain |tau_g| S_a / 4 where the sigmoid is steepest: several times what the 10 ms PD
    tolerates, so without the filter a holding finger whose torque strays to S_b can start
    an oscillation at the PD's rate that throws the object. 0 is the paper's static law.

    Output ``share``: per finger, what the suppresser lets through of its grasping torque
    (``tau_g_eff . tau_g / |tau_g|^2``, 1 when disabled); the reflex stops squeezing for a
    finger as it falls (``GraspReflex`` parameter ``release_share``).

    The nine joints are done in one native call (``suppress_output``).

    Parameters
    ----------
    S_a : scalar or 9 values
        sigmoid steepness, 1/(N m)
    S_b : scalar or 9 values
        manipulation torque, N m, at which the grasping torque is halved
    mode : str
        'signed' (the paper's formula, tau_m signed against the grasp) or 'magnitude'
        (suppress by |tau_m|)
    enabled : bool
        false passes the grasping torque through unsuppressed
    time_constant : float
        seconds; > 0 low-passes the manipulation torque the sigmoid reads (needs a period),
        0 reads it as it is
    """

    type_name = "Suppresser"

    def __init__(self, S_a: Any = 100.0, S_b: Any = 0.03, mode: str = "signed", enabled: bool = True,
                 time_constant: float = 0.0):
        code = mode_code(mode)
        self.S_a = float_array(S_a, "S_a", ndim=1, width=9, broadcast=True)
        self.S_b = float_array(S_b, "S_b", ndim=1, width=9, broadcast=True)
        check_steepness(self.S_a)
        if isinstance(time_constant, bool) or not isinstance(time_constant, (int, float)):
            raise ValueError(f"parameter 'time_constant' must be a time >= 0 in seconds, got {time_constant!r}")
        self.mode = mode
        self.enabled = bool(enabled)
        self.time_constant = float(time_constant)
        self.inputs = dict(SUPPRESS_INPUTS)
        self.input_defaults = {"tau_ff": np.zeros(9)}
        self.outputs = dict(ports(SUPPRESS_OUT))
        self.feedthrough = (True if not self.filtered else
                            {"tau": {"tau_g", "tau_m", "tau_ff"}, "tau_g_eff": {"tau_g"}, "share": {"tau_g"}})
        given = np.empty(GIVEN.size)
        given[GIVEN.slice("S_A")], given[GIVEN.slice("S_B")] = self.S_a, self.S_b
        given[GIVEN.MODE], given[GIVEN.ENABLED], given[GIVEN.TIME_CONSTANT] = code, self.enabled, self.time_constant
        self._given = given
        # the native calls' parameters, checked and packed in C (the filter's step by bind)
        self._params = pack_params(given, None, np.nan)

    @property
    def filtered(self) -> bool:
        """Whether the sigmoid reads the low-passed manipulation torque (the block's state)."""
        return self.time_constant > 0

    def bind(self, period) -> None:
        """Take the period the low-pass filter steps at (a filtered suppresser needs one)."""
        if self.filtered:
            if period is None:
                raise ValueError("a Suppresser with a time_constant needs an explicit period (its filter's step), "
                                 "e.g. the reflex's 1 ms")
            self._params = pack_params(self._given, None, float(period))
        super().bind(period)
        self._kernel = None

    def initial_state(self) -> np.ndarray | None:
        """The low-passed suppression inputs (9, zero at the start), or None for the static law."""
        return np.zeros(9) if self.filtered else None

    def output(self, t: float, state: Any, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """One native call on the parameters packed in ``__init__`` and ``bind`` (so S_a, S_b
        or the mode changed on the object afterwards are not seen). Inputs the native call
        refuses for their type (lists, other dtypes, strided views) are converted to float64
        first; inputs of the wrong width raise ``ValueError`` naming the port."""
        out = np.empty(SUPPRESS_OUT.size)
        tau_g, tau_m, tau_ff = inputs["tau_g"], inputs["tau_m"], inputs.get("tau_ff", self.input_defaults["tau_ff"])
        try:
            suppress_output(self._params, tau_g, state, tau_m, tau_ff, out)
        except TypeError:
            suppress_output(self._params, flat_float64(tau_g), state, flat_float64(tau_m), flat_float64(tau_ff), out)
        return {port: out[columns] for port, columns in _PORTS}

    def update(self, t: float, state: Any, inputs: Mapping[str, np.ndarray]) -> Any:
        """The low-pass step of the suppression inputs (a fresh array); None when static."""
        if state is None:
            return None
        nxt = np.empty(9)
        suppress_update(self._params, state, flat_float64(inputs["tau_g"]), flat_float64(inputs["tau_m"]), nxt)
        return nxt

    def kernel(self) -> Kernel | None:
        """``output`` (and, when filtered, ``update``) in C (kernel type ``Suppresser``:
        the same native law), in a context its constructor builds from the record
        ``[given, period]``. In an exported FMU ``S_a``, ``S_b`` and (for a filtered one)
        ``time_constant`` are tunable."""
        held = getattr(self, "_kernel", None)
        if held is None:
            period = float(self.period) if self.period is not None else 0.0
            rec = record("Suppresser", self._given, [period], tunables=_TUNABLES if self.filtered else _TUNABLES[:18])
            ctx = context_of(rec)
            held = self._kernel = Kernel(context=ctx.address, output=KERNELS["Suppresser.output"],
                                         update=KERNELS["Suppresser.update"] if self.filtered else 0, owners=(ctx,),
                                         nogil=True, record=rec)
        return held


_GIVEN_AT = SUPPRESS_RECORD.GIVEN
_TUNABLES = (
    *(Tunable(f"S_a[{j + 1}]", _GIVEN_AT + GIVEN.S_A + j, f"joint {j + 1} sigmoid steepness", "1/(N m)",
              minimum=0.0) for j in range(9)),
    *(Tunable(f"S_b[{j + 1}]", _GIVEN_AT + GIVEN.S_B + j, f"joint {j + 1} manipulation torque halving the grasping "
              "torque", "N m") for j in range(9)),
    Tunable("time_constant", _GIVEN_AT + GIVEN.TIME_CONSTANT, "time constant of the low-pass before the sigmoid (> 0)",
            "s", minimum=0.0),
)
"""Suppresser's parameters an exported FMU lets an importer set (time_constant only when
it filters: 0 would change the block's state and feedthrough)."""
