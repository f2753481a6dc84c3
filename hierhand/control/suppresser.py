"""The suppresser: lets voluntary motion override the grasping reflex, joint by joint."""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np
from numba import njit

from blocks import Block

from .suppression import MODES, suppress

_PASS, _MAGNITUDE, _SIGNED = 0, 1, 2  # suppress_kernel's modes
_F64 = np.dtype(np.float64)
_ND = np.ndarray


@njit(cache=True)
def suppress_kernel(tau_g, tau_m, tau_ff, s_a, s_b, mode, out):
    """``out[1] = suppress(tau_g, tau_m, s_a, s_b)`` (or ``tau_g`` for mode ``_PASS``),
    ``out[0] = out[1] + tau_m + tau_ff``, over the 9 joints; the same operations as
    ``suppression.suppress`` (whose numpy ``exp`` may differ from libm's in the last bit).
    """
    for j in range(9):
        m = tau_m[j]
        if mode == _PASS:
            eff = tau_g[j]
        else:
            g = abs(m) if mode == _MAGNITUDE else m
            x = s_a[j] * (s_b[j] - g)
            e = math.exp(-abs(x))
            eff = tau_g[j] * (1.0 / (1.0 + e) if x >= 0 else e / (1.0 + e))
        out[1, j] = eff
        out[0, j] = (eff + m) + tau_ff[j]


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

    The nine joints are done in one compiled call (``suppress_kernel``);
    ``output_reference`` is the numpy form on ``suppression.suppress``.
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
        self.outputs = {"tau": 9, "tau_g_eff": 9}
        self.feedthrough = True
        self._mode = (_MAGNITUDE if mode == "magnitude" else _SIGNED) if self.enabled else _PASS

    def output(self, t: float, state: Any, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        tau_g, tau_m, tau_ff = inputs["tau_g"], inputs["tau_m"], inputs.get("tau_ff", self.input_defaults["tau_ff"])
        if not (tau_g.__class__ is _ND and tau_m.__class__ is _ND and tau_ff.__class__ is _ND
                and tau_g.dtype == _F64 and tau_m.dtype == _F64 and tau_ff.dtype == _F64
                and tau_g.shape == (9,) and tau_m.shape == (9,) and tau_ff.shape == (9,)):
            return self.output_reference(t, state, inputs)
        out = np.empty((2, 9))
        suppress_kernel(tau_g, tau_m, tau_ff, self.S_a, self.S_b, self._mode, out)
        return {"tau": out[0], "tau_g_eff": out[1]}

    def output_reference(self, t: float, state: Any, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """``output`` in numpy, on ``suppression.suppress``."""
        tau_g, tau_m = inputs["tau_g"], inputs["tau_m"]
        tau_ff = np.asarray(inputs.get("tau_ff", self.input_defaults["tau_ff"]), dtype=float)
        effective = suppress(tau_g, tau_m, self.S_a, self.S_b, self.mode) if self.enabled else tau_g.copy()
        return {"tau": (effective + tau_m) + tau_ff, "tau_g_eff": effective}
