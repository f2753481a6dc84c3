"""Exact inverse kinematics of the planar three-joint fingers.

Joint angles are relative: link ``i`` points at ``base_angle + q1 + ... + qi``
(counter-clockwise from +x) and link 3 ends at the fingertip-circle centre. A fingertip
target is ``(x, y, phi)`` with ``phi`` the absolute angle of link 3; fixing ``phi`` makes
the problem exact: the wrist (joint 3) sits at ``tip - l3 (cos phi, sin phi)`` and joints
1-2 solve the two-link problem for it, which has two branches (elbows).

The manipulation controller's law, compiled (``hierhand/csrc/manipulation.c``): every
function here calls the C the ``ManipulationPD`` block runs (``finger_fk`` the plant's
own kinematics), checking and shaping the arguments and naming what is out of reach.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from blocks.arrays import flat_float64

from .. import _native

__all__ = ["UnreachableError", "finger_ik", "finger_ik_near", "finger_fk", "hand_ik", "wrap_angle"]

# Wrist distances this close (relative to l1 + l2) outside the reachable annulus are
# treated as on its boundary, so that targets computed by forward kinematics at a fully
# stretched or folded finger still solve.
_REACH_RTOL = 1e-9


class UnreachableError(ValueError):
    """The wrist point of a fingertip target is outside the reachable annulus."""

    def __init__(self, distance: float, r_min: float, r_max: float, finger: str | None = None):
        self.distance = distance
        self.r_min = r_min
        self.r_max = r_max
        self.finger = finger
        who = f"{finger}: " if finger else ""
        super().__init__(
            f"{who}unreachable fingertip target: the wrist point is {distance:.6g} m from the "
            f"finger base, the reachable range is [{r_min:.6g}, {r_max:.6g}] m"
        )


def wrap_angle(a: Any) -> Any:
    """Angle(s) wrapped to (-pi, pi]: a float for a scalar, else an array."""
    values = flat_float64(a)
    out = np.empty_like(values)
    _native.wrap_angles(values, out)
    return float(out[0]) if np.ndim(a) == 0 else out.reshape(np.shape(a))


def _geometry(base: Any, base_angle: float, lengths: Any) -> np.ndarray:
    """The C's finger geometry: base x, base y, base angle, the three link lengths."""
    ls = np.asarray(lengths, dtype=float).reshape(-1)
    if ls.shape != (3,) or not np.all(ls > 0):
        raise ValueError(f"lengths must be three positive link lengths, got {lengths!r}")
    return np.array([base[0], base[1], base_angle, *ls], dtype=float)


def finger_fk(base: Any, base_angle: float, lengths: Any, q: Any) -> tuple[float, float, float]:
    """Fingertip-circle centre ``(x, y)`` and link-3 absolute angle ``phi`` (not wrapped)."""
    pose = np.empty(3)
    _native.finger_fk(_geometry(base, base_angle, lengths), flat_float64(q), pose)
    return float(pose[0]), float(pose[1]), float(pose[2])


def finger_ik(
    base: Any, base_angle: float, lengths: Any, x: float, y: float, phi: float, elbow: int = 1
) -> np.ndarray:
    """Joint angles (3,) placing the fingertip-circle centre at ``(x, y)`` with link 3 at
    absolute angle ``phi``.

    ``elbow`` picks the branch: +1 gives ``q2 >= 0``, -1 gives ``q2 <= 0``. Angles are
    wrapped to (-pi, pi] (at a fully folded finger, ``q2 = pi``, the branches coincide).
    Raises ``UnreachableError`` when the wrist point's distance from the base is outside
    ``[|l1 - l2|, l1 + l2]``; its message gives that distance and the range.
    """
    if elbow not in (1, -1):
        raise ValueError(f"elbow must be +1 or -1, got {elbow!r}")
    q, reach = np.empty(3), np.empty(3)
    if not _native.finger_ik(_geometry(base, base_angle, lengths), _REACH_RTOL, x, y, phi, int(elbow), q, reach):
        raise UnreachableError(*map(float, reach))
    return q


def hand_ik(hand: Any, targets: Any, q_ref: Any) -> np.ndarray:
    """Joint angles (9,) for fingertip targets ``(3, 3)``: rows ``(x, y, phi)`` for thumb,
    fore, middle.

    Per finger, of the two elbow branches the one closer to ``q_ref`` (wrapped angle
    differences, summed squares) is taken, and each angle is returned as its
    representative nearest ``q_ref`` (``q_ref + wrap(q - q_ref)``, the same
    configuration), so a joint-space controller tracking it never turns the long way
    round. Geometry comes from ``hand`` (a ``hierhand.model.Hand``). Raises
    ``UnreachableError`` naming the finger.
    """
    targets = np.asarray(targets, dtype=float)
    if targets.shape != (3, 3):
        raise ValueError(f"targets must have shape (3, 3) (rows x, y, phi), got {targets.shape}")
    q_ref = np.asarray(q_ref, dtype=float).reshape(-1)
    if q_ref.shape != (9,):
        raise ValueError(f"q_ref must have shape (9,), got {q_ref.shape}")
    q = np.empty(9)
    for f in range(3):
        q[3 * f : 3 * f + 3] = finger_ik_near(hand, f, targets[f], q_ref[3 * f : 3 * f + 3])
    return q


def finger_ik_near(hand: Any, finger: int, target: Any, q_ref: Any) -> np.ndarray:
    """Joint angles (3,) of one finger of ``hand`` for a tip target ``(x, y, phi)``: the
    elbow branch nearer ``q_ref``, each angle as its representative nearest ``q_ref``
    (elbow +1 on a tie). Raises ``UnreachableError`` naming the finger."""
    x, y, phi = (float(v) for v in target)
    q, reach = np.empty(3), np.empty(3)
    if not _native.ik_near(hand.native, finger, _REACH_RTOL, x, y, phi, flat_float64(q_ref), q, reach):
        raise UnreachableError(*map(float, reach), hand.names[finger])
    return q
