"""Exact inverse kinematics of the planar three-joint fingers.

Joint angles are relative: link ``i`` points at ``base_angle + q1 + ... + qi``
(counter-clockwise from +x) and link 3 ends at the fingertip-circle centre. A fingertip
target is ``(x, y, phi)`` with ``phi`` the absolute angle of link 3; fixing ``phi`` makes
the problem exact: the wrist (joint 3) sits at ``tip - l3 (cos phi, sin phi)`` and joints
1-2 solve the two-link problem for it, which has two branches (elbows).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["UnreachableError", "finger_ik", "finger_fk", "hand_ik", "wrap_angle"]

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
    w = math.pi - np.mod(math.pi - np.asarray(a, dtype=float), 2 * math.pi)
    # np.mod(-tiny, 2 pi) rounds to exactly 2 pi, which would give -pi.
    w = np.where(w <= -math.pi, w + 2 * math.pi, w)
    return float(w) if w.ndim == 0 else w


def _lengths(lengths: Any) -> np.ndarray:
    ls = np.asarray(lengths, dtype=float).reshape(-1)
    if ls.shape != (3,) or not np.all(ls > 0):
        raise ValueError(f"lengths must be three positive link lengths, got {lengths!r}")
    return ls


def finger_fk(base: Any, base_angle: float, lengths: Any, q: Any) -> tuple[float, float, float]:
    """Fingertip-circle centre ``(x, y)`` and link-3 absolute angle ``phi`` (not wrapped)."""
    ls = _lengths(lengths)
    q = np.asarray(q, dtype=float).reshape(3)
    th = base_angle + np.cumsum(q)
    x = float(base[0] + np.sum(ls * np.cos(th)))
    y = float(base[1] + np.sum(ls * np.sin(th)))
    return x, y, float(th[2])


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
    l1, l2, l3 = _lengths(lengths)
    wx = x - l3 * math.cos(phi) - base[0]
    wy = y - l3 * math.sin(phi) - base[1]
    r = math.hypot(wx, wy)
    r_min, r_max = abs(l1 - l2), l1 + l2
    tol = _REACH_RTOL * r_max
    if not (r_min - tol <= r <= r_max + tol):
        raise UnreachableError(r, r_min, r_max)
    c2 = (r * r - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    q2 = elbow * math.acos(min(1.0, max(-1.0, c2)))
    th1 = math.atan2(wy, wx) - math.atan2(l2 * math.sin(q2), l1 + l2 * math.cos(q2))
    q1 = th1 - base_angle
    q3 = phi - th1 - q2
    return wrap_angle(np.array([q1, q2, q3]))


def _finger_geometry(hand: Any) -> list[tuple[str, tuple[float, float], float, tuple[float, float, float]]]:
    """(name, base, base_angle, link lengths) per finger, from ``hand.params``."""
    return [
        (f.name, f.base, f.base_angle, tuple(link.length for link in f.links))
        for f in hand.params.fingers
    ]


def hand_ik(hand: Any, targets: Any, q_ref: Any) -> np.ndarray:
    """Joint angles (9,) for fingertip targets ``(3, 3)``: rows ``(x, y, phi)`` for thumb,
    fore, middle.

    Per finger, of the two elbow branches the one closer to ``q_ref`` (wrapped angle
    differences, summed squares) is taken, and each angle is returned as its
    representative nearest ``q_ref`` (``q_ref + wrap(q - q_ref)``, the same
    configuration), so a joint-space controller tracking it never turns the long way
    round. Geometry comes from ``hand.params.fingers`` (a ``hierhand.model.Hand``).
    Raises ``UnreachableError`` naming the finger.
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
    elbow branch nearer ``q_ref``, each angle as its representative nearest ``q_ref``."""
    name, base, base_angle, lengths = _finger_geometry(hand)[finger]
    ref = np.asarray(q_ref, dtype=float)
    try:
        branches = [finger_ik(base, base_angle, lengths, *target, elbow=e) for e in (1, -1)]
    except UnreachableError as err:
        raise UnreachableError(err.distance, err.r_min, err.r_max, name) from None
    steps = [wrap_angle(b - ref) for b in branches]
    return ref + min(steps, key=lambda d: float(np.dot(d, d)))
