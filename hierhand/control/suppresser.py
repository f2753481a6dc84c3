"""The suppresser: lets voluntary motion override the grasping reflex, joint by joint."""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from blocks import Block

from .. import _native
from .suppression import MODES, finger_shares, suppress

_L = _native.LAYOUT
P_S_A: int = _L["SUPPRESS_P_S_A"]  # 9 sigmoid steepnesses
P_S_B: int = _L["SUPPRESS_P_S_B"]  # 9 half-suppression torques
P_MODE: int = _L["SUPPRESS_P_MODE"]  # PASS, MAGNITUDE or SIGNED
N_PARAMS: int = _L["SUPPRESS_N_PARAMS"]
PASS: int = _L["SUPPRESS_PASS"]
MAGNITUDE: int = _L["SUPPRESS_MAGNITUDE"]
SIGNED: int = _L["SUPPRESS_SIGNED"]
O_TAU: int = _L["SUPPRESS_O_TAU"]
O_TAU_G_EFF: int = _L["SUPPRESS_O_TAU_G_EFF"]
O_SHARE: int = _L["SUPPRESS_O_SHARE"]
N_OUT: int = _L["SUPPRESS_N_OUT"]

suppress_output = _native.suppress
"""``suppress_output(params, tau_g, tau_m, tau_ff, out)``: ``out[O_TAU_G_EFF:]`` =
``suppress(tau_g, tau_m, S_a, S_b)`` (or ``tau_g`` for mode ``PASS``), ``out[O_TAU:]`` =
that ``+ tau_m + tau_ff``, over the 9 joints; the law in C (``hierhand/csrc/suppresser.c``)
with the same operations as ``suppression.suppress`` (whose numpy ``exp`` may differ from
libm's in the last bit). Takes C-contiguous float64 arrays only (``TypeError`` otherwise)."""


def pack_params(S_a: np.ndarray, S_b: np.ndarray, mode: int) -> np.ndarray:
    """The ``params`` vector of ``suppress_output``: 9 values each of S_a and S_b, a mode."""
    if mode not in (PASS, MAGNITUDE, SIGNED):
        raise ValueError(f"mode must be PASS, MAGNITUDE or SIGNED ({PASS}, {MAGNITUDE}, {SIGNED}), got {mode!r}")
    p = np.empty(N_PARAMS)
    p[P_S_A:P_S_A + 9] = S_a
    p[P_S_B:P_S_B + 9] = S_b
    p[P_MODE] = mode
    return p


class Suppresser(Block):
    """Actuator command ``tau = tau_g * sigmoid(S_a (S_b - g(tau_m))) + tau_m`` per joint.

    An optional input ``tau_ff`` (zero when unconnected) is added to the command
    unsuppressed: the manipulation controller's feedforward (finger gravity, the object's
    weight), which is not voluntary motion and must not weigh against the grasp.

    ``mode: magnitude`` (default) uses g = |tau_m|: the larger the manipulation torque of
    a joint, in either direction, the more its grasping torque is suppressed, as the
    paper's prose describes. ``mode: signed`` is the paper's literal formula (g = tau_m),
    which only suppresses against positive manipulation torques. ``enabled: false``
    passes tau_g through unchanged, for the paper's comparison run without suppression.

    The nine joints are done in one native call (``suppress_output``); ``output_reference``
    is the numpy form on ``suppression.suppress``.
    """

    type_name = "Suppresser"
    param_docs = {
        "S_a": "sigmoid steepness, 1/(N m) (scalar or 9 values)",
        "S_b": "manipulation torque, N m, at which the grasping torque is halved (scalar or 9 values)",
        "mode": "'magnitude' (suppress by |tau_m|, default) or 'signed' (the paper's literal formula)",
        "enabled": "false passes the grasping torque through unsuppressed",
    }

    def __init__(self, S_a: Any = 100.0, S_b: Any = 0.1, mode: str = "magnitude", enabled: bool = True):
        if mode not in MODES:
            raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
        self.S_a = np.broadcast_to(np.asarray(S_a, dtype=float), (9,)).copy()
        self.S_b = np.broadcast_to(np.asarray(S_b, dtype=float), (9,)).copy()
        suppress(np.zeros(9), np.zeros(9), self.S_a, self.S_b, mode)  # validates S_a, S_b
        self.mode = mode
        self.enabled = bool(enabled)
        self.inputs = {"tau_g": 9, "tau_m": 9, "tau_ff": 9}
        self.input_defaults = {"tau_ff": np.zeros(9)}
        self.outputs = {"tau": 9, "tau_g_eff": 9, "share": 3}
        self.feedthrough = True
        self._params = pack_params(self.S_a, self.S_b,
                                   (MAGNITUDE if mode == "magnitude" else SIGNED) if self.enabled else PASS)

    def output(self, t: float, state: Any, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """One native call on the parameters packed in ``__init__`` (so S_a, S_b or the mode
        changed on the object afterwards are not seen). Inputs the native call refuses
        (anything but C-contiguous float64 arrays of 9 values) go through
        ``output_reference``."""
        out = np.empty(N_OUT)
        try:
            suppress_output(self._params, inputs["tau_g"], inputs["tau_m"],
                            inputs.get("tau_ff", self.input_defaults["tau_ff"]), out)
        except (TypeError, ValueError):
            return self.output_reference(t, state, inputs)
        return {"tau": out[O_TAU:O_TAU + 9], "tau_g_eff": out[O_TAU_G_EFF:O_TAU_G_EFF + 9],
                "share": out[O_SHARE:O_SHARE + 3]}

    def output_reference(self, t: float, state: Any, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """``output`` in numpy, on ``suppression.suppress``."""
        tau_g, tau_m = inputs["tau_g"], inputs["tau_m"]
        tau_ff = np.asarray(inputs.get("tau_ff", self.input_defaults["tau_ff"]), dtype=float)
        effective = suppress(tau_g, tau_m, self.S_a, self.S_b, self.mode) if self.enabled else tau_g.copy()
        return {"tau": (effective + tau_m) + tau_ff, "tau_g_eff": effective,
                "share": finger_shares(tau_g, effective, tau_m) if self.enabled else np.ones(3)}
