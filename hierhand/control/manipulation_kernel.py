"""The manipulation controller's compiled output: trajectories, IK, PD and feedforward.

``manipulation_output`` does in one call what ``ManipulationPD.output_reference`` does
in numpy: sample the fingertip trajectories, turn the samples into joint targets by the
exact three-joint inverse kinematics (the elbow branch nearest ``q0``, each angle as its
representative nearest ``q0``), differentiate those centrally in time for the velocity
target, track both with the joint PD, and add the gravity and load feedforward. The
arithmetic follows ``inverse_kinematics.finger_ik`` / ``finger_ik_near``,
``trajectory.Trajectory.sample`` / ``velocity`` and ``Hand.bias`` / ``tip_jacobians``
operation by operation, so the two agree to round-off.

Everything comes in flat arrays (layouts below); ``pack_params`` and
``pack_trajectories`` build them. The kernel inlines the model's compiled kinematics and
dynamics (``finger_frames``, ``point_jacobian``, ``finger_bias``), so its on-disk cache
is flushed whenever those sources change (``invalidate_if_stale``), like the plant's.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numba import njit
from numba.core.registry import CPUDispatcher

from ..model.dynamics import finger_bias
from ..model.kernel_cache import invalidate_if_stale
from ..model.kinematics import finger_frames, point_jacobian
from ..model.layout import (
    F_BASE_ANGLE,
    F_BASE_X,
    F_BASE_Y,
    F_LINK0,
    F_LINK_STRIDE,
    L_LENGTH,
)
from .inverse_kinematics import _REACH_RTOL

# -- params: one float64 vector --------------------------------------------------------
P_Q0 = 0  # 9 initial joint angles (held by fingers without a trajectory; IK branch reference)
P_KP = 9  # 9 joint stiffnesses
P_KD = 18  # 9 joint dampings
P_GX = 27  # gravity
P_GY = 28
P_WX = 29  # object weight m g
P_WY = 30
P_THRESHOLD = 31  # normal force above which a finger carries the object
P_GRAVITY_COMP = 32  # 1.0: add the fingers' gravity torques
P_LOAD_COMP = 33  # 1.0: add J^T of the shared object weight
P_STEP = 34  # seconds either side of t for the velocity target
N_PARAMS = 35

# -- trajectories: waypoints (3, n_max, 4) rows (t, x, y, phi); meta (3, 2) int64 --------
M_COUNT = 0  # waypoints of the finger's trajectory (0: none, the finger holds q0)
M_INTERP = 1  # INTERP_LINEAR or INTERP_MINJERK
INTERP_LINEAR = 0
INTERP_MINJERK = 1

OK = 0
"""Return code of ``manipulation_output``; ``1 + f`` means finger f's target is unreachable."""

_TWO_PI = 2 * math.pi


def pack_params(q0, kp, kd, gravity, weight, threshold: float, gravity_compensation: bool,
                load_compensation: bool, step: float) -> np.ndarray:
    """The ``params`` vector of ``manipulation_output``."""
    p = np.zeros(N_PARAMS)
    p[P_Q0:P_Q0 + 9] = q0
    p[P_KP:P_KP + 9] = kp
    p[P_KD:P_KD + 9] = kd
    p[P_GX], p[P_GY] = gravity
    p[P_WX], p[P_WY] = weight
    p[P_THRESHOLD] = threshold
    p[P_GRAVITY_COMP] = 1.0 if gravity_compensation else 0.0
    p[P_LOAD_COMP] = 1.0 if load_compensation else 0.0
    p[P_STEP] = step
    return p


def pack_trajectories(trajectories: Sequence) -> tuple[np.ndarray, np.ndarray]:
    """``(waypoints, meta)`` of three ``Trajectory`` objects or ``None`` (no trajectory)."""
    n_max = max([1] + [traj.times.size for traj in trajectories if traj is not None])
    waypoints = np.zeros((3, n_max, 4))
    meta = np.zeros((3, 2), dtype=np.int64)
    for f, traj in enumerate(trajectories):
        if traj is None:
            continue
        n = traj.times.size
        waypoints[f, :n, 0] = traj.times
        waypoints[f, :n, 1:] = traj.points
        meta[f, M_COUNT] = n
        meta[f, M_INTERP] = INTERP_MINJERK if traj.interpolation == "minjerk" else INTERP_LINEAR
    return waypoints, meta


@njit(cache=True, inline="always")
def _wrap(a):
    """``inverse_kinematics.wrap_angle`` of a scalar: to (-pi, pi]."""
    w = math.pi - (math.pi - a) % _TWO_PI
    if w <= -math.pi:
        w += _TWO_PI
    return w


@njit(cache=True)
def ik_near(fingers, f, x, y, phi, r0, r1, r2):
    """Joint angles of finger f for the tip target (x, y, phi), as ``finger_ik_near``:
    of the two elbow branches the one nearer (r0, r1, r2), each angle as its
    representative nearest the reference. Returns (reachable, q1, q2, q3)."""
    bx = fingers[f, F_BASE_X]
    by = fingers[f, F_BASE_Y]
    ba = fingers[f, F_BASE_ANGLE]
    l1 = fingers[f, F_LINK0 + L_LENGTH]
    l2 = fingers[f, F_LINK0 + F_LINK_STRIDE + L_LENGTH]
    l3 = fingers[f, F_LINK0 + 2 * F_LINK_STRIDE + L_LENGTH]
    wx = x - l3 * math.cos(phi) - bx
    wy = y - l3 * math.sin(phi) - by
    r = math.hypot(wx, wy)
    r_min = abs(l1 - l2)
    r_max = l1 + l2
    tol = _REACH_RTOL * r_max
    if not (r_min - tol <= r <= r_max + tol):
        return False, 0.0, 0.0, 0.0
    c2 = (r * r - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    a2 = math.acos(min(1.0, max(-1.0, c2)))
    toward = math.atan2(wy, wx)
    best0 = best1 = best2 = 0.0
    best = 0.0
    for branch in range(2):
        q2 = a2 if branch == 0 else -a2  # elbow +1 first: it wins ties
        th1 = toward - math.atan2(l2 * math.sin(q2), l1 + l2 * math.cos(q2))
        q1 = th1 - ba
        q3 = phi - th1 - q2
        d0 = _wrap(_wrap(q1) - r0)
        d1 = _wrap(_wrap(q2) - r1)
        d2 = _wrap(_wrap(q3) - r2)
        dd = d0 * d0 + d1 * d1 + d2 * d2
        if branch == 0 or dd < best:
            best, best0, best1, best2 = dd, d0, d1, d2
    return True, r0 + best0, r1 + best1, r2 + best2


@njit(cache=True, inline="always")
def _segment(waypoints, f, n, t):
    """Segment index i (times[i] <= t < times[i+1], clamped), tau in [0, 1], span."""
    count = 0  # np.searchsorted(times, t, side="right")
    while count < n and waypoints[f, count, 0] <= t:
        count += 1
    i = min(max(count - 1, 0), n - 2)
    span = waypoints[f, i + 1, 0] - waypoints[f, i, 0]
    return i, (t - waypoints[f, i, 0]) / span, span


@njit(cache=True)
def sample(waypoints, meta, f, t):
    """``Trajectory.sample(t)`` of finger f as (x, y, phi)."""
    n = meta[f, M_COUNT]
    if t <= waypoints[f, 0, 0]:
        return waypoints[f, 0, 1], waypoints[f, 0, 2], waypoints[f, 0, 3]
    if t >= waypoints[f, n - 1, 0]:
        return waypoints[f, n - 1, 1], waypoints[f, n - 1, 2], waypoints[f, n - 1, 3]
    i, tau, _ = _segment(waypoints, f, n, t)
    if meta[f, M_INTERP] == INTERP_MINJERK:
        s = tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau))
    else:
        s = tau
    return (
        waypoints[f, i, 1] + s * (waypoints[f, i + 1, 1] - waypoints[f, i, 1]),
        waypoints[f, i, 2] + s * (waypoints[f, i + 1, 2] - waypoints[f, i, 2]),
        waypoints[f, i, 3] + s * (waypoints[f, i + 1, 3] - waypoints[f, i, 3]),
    )


@njit(cache=True)
def moving(waypoints, meta, f, t):
    """Whether ``Trajectory.velocity(t)`` of finger f has a non-zero component."""
    n = meta[f, M_COUNT]
    if t < waypoints[f, 0, 0] or t >= waypoints[f, n - 1, 0]:
        return False
    i, tau, span = _segment(waypoints, f, n, t)
    if meta[f, M_INTERP] == INTERP_MINJERK:
        rate = 30.0 * tau * tau * (1.0 - tau) ** 2
    else:
        rate = 1.0
    k = rate / span
    for c in range(1, 4):
        if k * (waypoints[f, i + 1, c] - waypoints[f, i, c]) != 0.0:
            return True
    return False


@njit(cache=True)
def manipulation_output(t, q, qd, fn, fingers, params, waypoints, meta, out):
    """Fill ``out`` (3, 9): rows tau_m, tau_ff, q_ref. Returns ``OK`` or ``1 + f`` when a
    target of finger f is unreachable (``out`` then incomplete)."""
    q_ref = out[2]
    qd_ref = np.zeros(9)
    for j in range(9):
        q_ref[j] = params[P_Q0 + j]
    h = params[P_STEP]
    for f in range(3):
        if meta[f, M_COUNT] == 0:
            continue
        r0 = params[P_Q0 + 3 * f]
        r1 = params[P_Q0 + 3 * f + 1]
        r2 = params[P_Q0 + 3 * f + 2]
        x, y, phi = sample(waypoints, meta, f, t)
        ok, a0, a1, a2 = ik_near(fingers, f, x, y, phi, r0, r1, r2)
        if not ok:
            return 1 + f
        q_ref[3 * f] = a0
        q_ref[3 * f + 1] = a1
        q_ref[3 * f + 2] = a2
        if moving(waypoints, meta, f, t):
            x, y, phi = sample(waypoints, meta, f, t + h)
            ok, a0, a1, a2 = ik_near(fingers, f, x, y, phi, r0, r1, r2)
            if not ok:
                return 1 + f
            x, y, phi = sample(waypoints, meta, f, t - h)
            ok, b0, b1, b2 = ik_near(fingers, f, x, y, phi, r0, r1, r2)
            if not ok:
                return 1 + f
            qd_ref[3 * f] = (a0 - b0) / (2 * h)
            qd_ref[3 * f + 1] = (a1 - b1) / (2 * h)
            qd_ref[3 * f + 2] = (a2 - b2) / (2 * h)
    for j in range(9):
        out[0, j] = params[P_KP + j] * (q_ref[j] - q[j]) + params[P_KD + j] * (qd_ref[j] - qd[j])
    tau_ff = out[1]
    for j in range(9):
        tau_ff[j] = 0.0
    gravity = params[P_GRAVITY_COMP] != 0.0
    carrying = 0
    if params[P_LOAD_COMP] != 0.0:
        for f in range(3):
            if fn[f] > params[P_THRESHOLD]:
                carrying += 1
    if not gravity and carrying == 0:
        return OK
    u = np.empty((3, 3, 2))
    pts = np.empty((3, 4, 2))
    jac = np.empty((3, 2, 3))
    gx = params[P_GX]
    gy = params[P_GY]
    for f in range(3):
        finger_frames(fingers, f, q, 3 * f, u, pts)
        if gravity:
            h0, h1, h2 = finger_bias(fingers, f, u, 0.0, 0.0, 0.0, gx, gy)
            tau_ff[3 * f] = h0
            tau_ff[3 * f + 1] = h1
            tau_ff[3 * f + 2] = h2
    if carrying:
        sx = -params[P_WX] / carrying
        sy = -params[P_WY] / carrying
        for f in range(3):
            if fn[f] > params[P_THRESHOLD]:
                point_jacobian(pts, f, pts[f, 3, 0], pts[f, 3, 1], jac)
                for j in range(3):
                    tau_ff[3 * f + j] += jac[f, 0, j] * sx + jac[f, 1, j] * sy
    return OK


# -- on-disk cache consistency -------------------------------------------------------------

# ``manipulation_output`` inlines the model's finger_frames, point_jacobian and finger_bias,
# which numba's cache does not track (it keys on this file only).
invalidate_if_stale([obj for obj in list(globals().values()) if isinstance(obj, CPUDispatcher)],
                    stamp_name="hierhand_manipulation_kernel.sha256")
