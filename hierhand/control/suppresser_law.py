"""The suppresser's law, compiled: the manipulation torque turns the grasping torque down.

``tau_g' = tau_g * sigmoid(S_a (S_b - g(tau_m)))``; the actuator command is then
``tau_g' + tau_m``. Without it the grasping reflex fights a finger that manipulation wants
to lift off (re-grasp), and both torques grow against each other.

Two readings of ``g``:

- ``"magnitude"`` (default), ``g = |tau_m|``: suppression grows with the size of the
  manipulation torque, whichever its sign, as the paper's prose says.
- ``"signed"``: the paper's literal formula, ``g = tau_m`` with ``tau_m`` signed positive
  against the joint's grasping torque (``-tau_m`` where ``tau_g >= 0``): only voluntary
  motion that works against the grasp suppresses it. The paper does not give its joint
  convention; in this hand's (every angle counter-clockwise) the torque that pulls the
  forefinger off the object is negative and the thumb's positive, so the formula read in
  it would never suppress the withdrawing forefinger.

``S_b`` is the manipulation torque at which ``tau_g`` is halved and ``S_a`` (>= 0) the
steepness. Note that ``S_a = 0`` halves ``tau_g`` everywhere; "no suppression" is a large
``S_a * S_b``, or bypassing the suppresser.

The law is C (``hierhand/csrc/suppresser.c``): ``suppress_output`` is the ``Suppresser``
block's one call per hit, and ``sigmoid``, ``suppress`` and ``finger_shares`` are the
same functions for any number of joints, for users and tests. The slots of its arrays
are declared once, in ``hierhand/csrc/layouts.h`` (``hierhand.layouts``:
``SUPPRESS_PARAMS``, ``SUPPRESS_GIVEN``, ``SUPPRESS_OUT``, ``SUPPRESS_MODE``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from blocks.arrays import flat_float64

from .. import _native
from ..layouts import SUPPRESS_MODE

__all__ = ["sigmoid", "suppress", "finger_shares", "MODES"]

MODES = {"magnitude": SUPPRESS_MODE.MAGNITUDE, "signed": SUPPRESS_MODE.SIGNED}
"""The modes a block may be given by name, with their codes in the packed parameters
(``SUPPRESS_MODE.PASS`` is a disabled block's)."""

suppress_output = _native.suppress
"""``suppress_output(params, tau_g, g, tau_m, tau_ff, out)``: over the 9 joints, into
``out`` (``SUPPRESS_OUT``), ``TAU_G_EFF`` = ``tau_g * sigmoid(S_a (S_b - g))`` (``tau_g``
for mode ``PASS``), ``TAU`` = that ``+ tau_m + tau_ff`` and ``SHARE`` = ``finger_shares``
(ones for ``PASS``). ``g``: the low-passed suppression inputs (the block's state), or None
for the static law (``g`` of ``tau_m`` now). Takes C-contiguous float64 arrays only
(``TypeError`` otherwise)."""

suppress_update = _native.suppress_update
"""``suppress_update(params, state, tau_g, tau_m, next)``: the low-passed suppression inputs
``state + alpha (g(tau_m) - state)`` (9) into ``next``."""


def mode_code(mode: str) -> int:
    """The code of a mode name; ``ValueError`` for an unknown one."""
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    return MODES[mode]


def check_steepness(S_a: Any) -> None:
    """``ValueError`` unless every ``S_a`` is >= 0 (NaN included)."""
    s_a = np.asarray(S_a, dtype=float)
    if np.any(s_a < 0) or np.any(np.isnan(s_a)):
        raise ValueError(f"S_a must be >= 0, got {S_a!r}")


_pack = _native.suppress_pack


def pack_params(given: np.ndarray, hand: None, period: float) -> np.ndarray:
    """The ``params`` vector of ``suppress_output`` from the block's parameters (``SUPPRESS_GIVEN``),
    checked (hierhand/csrc/control_params.c): mode ``PASS`` when not enabled, the low-pass
    step ``1 - exp(-period / time_constant)`` for a filtered block with a period (else 1);
    ValueError naming a bad parameter."""
    return _pack(given, hand, period)


def _shaped(out: np.ndarray, shape: tuple[int, ...]) -> Any:
    """``out`` in ``shape``: a float for a scalar."""
    return float(out[0]) if shape == () else out.reshape(shape)


def sigmoid(x: Any) -> Any:
    """Logistic function ``1 / (1 + exp(-x))``, without overflow for large ``|x|``.

    Scalars give a float, arrays an array of the same shape.
    """
    values = flat_float64(x)
    out = np.empty_like(values)
    _native.sigmoid(values, out)
    return _shaped(out, np.shape(x))


def suppress(tau_g: Any, tau_m: Any, S_a: Any, S_b: Any, mode: str = "signed") -> Any:
    """Suppressed grasping torque ``tau_g * sigmoid(S_a * (S_b - g(tau_m)))``, elementwise.

    ``S_a`` and ``S_b`` may be scalars or per-joint arrays (broadcast with the torques).
    Raises ``ValueError`` for an unknown ``mode`` or a negative ``S_a``.
    """
    code = mode_code(mode)
    check_steepness(S_a)
    arrays = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (tau_g, tau_m, S_a, S_b)))
    shape = arrays[0].shape
    flat = [flat_float64(a) for a in arrays]
    out = np.empty(flat[0].size)
    _native.suppress_joints(*flat, code, out)
    return _shaped(out, shape)


def finger_shares(tau_g: Any, tau_g_eff: Any) -> np.ndarray:
    """Per finger (3), how much of its grasping torque the suppresser lets through:
    ``tau_g_eff_i . tau_g_i / |tau_g_i|^2``, 1 where ``tau_g_i`` is zero.

    1 means the reflex's torque reaches the joints whole; toward 0 the sigmoid switches it
    off. The torques have 9 values each.
    """
    share = np.empty(3)
    _native.finger_shares(flat_float64(tau_g), flat_float64(tau_g_eff), share)
    return share
