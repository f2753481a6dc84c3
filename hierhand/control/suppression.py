"""The suppresser: the manipulation torque turns the grasping torque down, per joint.

``tau_g' = tau_g * sigmoid(S_a (S_b - g(tau_m)))``; the actuator command is then
``tau_g' + tau_m``. Without it the grasping reflex fights a finger that manipulation wants
to lift off (re-grasp), and both torques grow against each other.

Two readings of ``g``:

- ``"magnitude"`` (default), ``g = |tau_m|``: suppression grows with the size of the
  manipulation torque, whichever its sign, as the paper's prose says.
- ``"signed"``, ``g = tau_m``: the paper's literal formula; only positive ``tau_m``
  suppresses, a large negative one passes ``tau_g`` through almost unchanged.

``S_b`` is the manipulation torque at which ``tau_g`` is halved and ``S_a`` (>= 0) the
steepness. Note that ``S_a = 0`` halves ``tau_g`` everywhere; "no suppression" is a large
``S_a * S_b``, or bypassing the suppresser.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["sigmoid", "suppress", "finger_shares", "MODES"]

MODES = ("magnitude", "signed")


def sigmoid(x: Any) -> Any:
    """Logistic function ``1 / (1 + exp(-x))``, without overflow for large ``|x|``.

    Scalars give a float, arrays an array of the same shape.
    """
    x = np.asarray(x, dtype=float)
    e = np.exp(-np.abs(x))
    out = np.where(x >= 0, 1.0 / (1.0 + e), e / (1.0 + e))
    return float(out) if out.ndim == 0 else out


def suppress(tau_g: Any, tau_m: Any, S_a: Any, S_b: Any, mode: str = "magnitude") -> Any:
    """Suppressed grasping torque ``tau_g * sigmoid(S_a * (S_b - g(tau_m)))``, elementwise.

    ``S_a`` and ``S_b`` may be scalars or per-joint arrays (broadcast with the torques).
    Raises ``ValueError`` for an unknown ``mode`` or a negative ``S_a``.
    """
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    s_a = np.asarray(S_a, dtype=float)
    if np.any(s_a < 0) or np.any(np.isnan(s_a)):
        raise ValueError(f"S_a must be >= 0, got {S_a!r}")
    tau_m = np.asarray(tau_m, dtype=float)
    g = np.abs(tau_m) if mode == "magnitude" else tau_m
    out = np.asarray(tau_g, dtype=float) * sigmoid(s_a * (np.asarray(S_b, dtype=float) - g))
    return float(out) if np.ndim(out) == 0 else out


def finger_shares(tau_g: Any, tau_g_eff: Any, tau_m: Any) -> np.ndarray:
    """Per finger (3), how much of its grasping torque survives in the voluntary part of its
    command: ``(tau_g_eff_i + tau_m_i) . tau_g_i / |tau_g_i|^2``, 1 where ``tau_g_i`` is zero.

    1 means the reflex's torque reaches the joints whole; below 1 the suppresser and the
    manipulation torque are taking the finger over (0: cancelled, negative: pulled back).
    """
    g = np.asarray(tau_g, dtype=float).reshape(3, 3)
    kept = (np.asarray(tau_g_eff, dtype=float) + np.asarray(tau_m, dtype=float)).reshape(3, 3)
    squared = (g * g).sum(axis=1)
    along = (kept * g).sum(axis=1)
    return np.where(squared > 0.0, along / np.where(squared > 0.0, squared, 1.0), 1.0)
