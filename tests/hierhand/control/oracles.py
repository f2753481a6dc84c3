"""Readable numpy formulations of the controllers' laws: the oracles the compiled laws are
checked against.

The package has one implementation of each law, in C (``hierhand/csrc``), which the
blocks and the Python API of ``hierhand.control`` call. These are independent of it:
written from the formulas (``numpy.linalg.pinv`` for the grasp-matrix projection, the
link walk for the kinematics, ``numpy.searchsorted`` for the trajectory segments), so the
tests can tell a wrong formula from round-off. Most were the package's numpy
implementations before the laws were written once (issue 14); the C agrees with them to
round-off, often to the bit.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

COINCIDENT_RTOL = 1e-12
"""Points this close, relative to their size, coincide (``internal_forces._COINCIDENT_RTOL``)."""
REACH_RTOL = 1e-9
"""Wrist distances this close (relative to l1 + l2) outside the annulus count as on it."""


# -- suppresser ----------------------------------------------------------------------------


def sigmoid(x: Any) -> np.ndarray:
    """``1 / (1 + exp(-x))`` in the form that cannot overflow."""
    x = np.asarray(x, dtype=float)
    e = np.exp(-np.abs(x))
    return np.where(x >= 0, 1.0 / (1.0 + e), e / (1.0 + e))


def suppress(tau_g: Any, tau_m: Any, s_a: Any, s_b: Any, mode: str = "magnitude") -> np.ndarray:
    """``tau_g * sigmoid(S_a (S_b - g(tau_m)))``, ``g = |tau_m|`` or ``tau_m``."""
    tau_m = np.asarray(tau_m, dtype=float)
    g = np.abs(tau_m) if mode == "magnitude" else tau_m
    return np.asarray(tau_g, dtype=float) * sigmoid(np.asarray(s_a, dtype=float) * (np.asarray(s_b, dtype=float) - g))


def finger_shares(tau_g: Any, tau_g_eff: Any, tau_m: Any) -> np.ndarray:
    """Per finger ``(tau_g_eff_i + tau_m_i) . tau_g_i / |tau_g_i|^2``, 1 where ``tau_g_i = 0``."""
    g = np.asarray(tau_g, dtype=float).reshape(3, 3)
    kept = (np.asarray(tau_g_eff, dtype=float) + np.asarray(tau_m, dtype=float)).reshape(3, 3)
    squared = (g * g).sum(axis=1)
    along = (kept * g).sum(axis=1)
    return np.where(squared > 0.0, along / np.where(squared > 0.0, squared, 1.0), 1.0)


def suppresser_output(block, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """A ``Suppresser`` block's output ports."""
    tau_g, tau_m = np.asarray(inputs["tau_g"], dtype=float), np.asarray(inputs["tau_m"], dtype=float)
    tau_ff = np.asarray(inputs.get("tau_ff", np.zeros(9)), dtype=float)
    if not block.enabled:
        return {"tau": (tau_g + tau_m) + tau_ff, "tau_g_eff": tau_g.copy(), "share": np.ones(3)}
    effective = suppress(tau_g, tau_m, block.S_a, block.S_b, block.mode)
    return {"tau": (effective + tau_m) + tau_ff, "tau_g_eff": effective,
            "share": finger_shares(tau_g, effective, tau_m)}


# -- internal forces -------------------------------------------------------------------------


def grasp_matrix(points: np.ndarray, center: np.ndarray) -> np.ndarray:
    """(3, 2k): contact i contributes columns ``[I2; (-r_iy, r_ix)]``, ``r_i = p_i - center``."""
    r = np.asarray(points, dtype=float) - np.asarray(center, dtype=float)
    g = np.zeros((3, 2 * len(r)))
    g[0, 0::2] = 1.0
    g[1, 1::2] = 1.0
    g[2, 0::2] = -r[:, 1]
    g[2, 1::2] = r[:, 0]
    return g


def project_internal(points: np.ndarray, f: np.ndarray) -> np.ndarray:
    """``(I - G^+ G) f`` with ``numpy.linalg.pinv``."""
    g = grasp_matrix(points, np.zeros(2))
    f = np.asarray(f, dtype=float).reshape(-1)
    return f - np.linalg.pinv(g) @ (g @ f)


def internal_directions(points: np.ndarray) -> np.ndarray:
    """The centroid squeeze ``c - p_i`` over its longest row; ``ValueError`` when the points coincide."""
    p = np.asarray(points, dtype=float)
    f = p.mean(axis=0) - p
    spread = float(np.max(np.hypot(f[:, 0], f[:, 1])))
    if spread <= COINCIDENT_RTOL * max(float(np.max(np.abs(p))), np.finfo(float).tiny):
        raise ValueError("internal forces are undefined: all contact points coincide")
    return f / spread


# -- grasping reflex ---------------------------------------------------------------------------


def reflex_members(reflex, state: np.ndarray, fn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(fingers in the grasp, fingers touching): touching ones, and those listed in 'grasp'
    that are not touching and were not handed over when they last touched."""
    touching = fn > reflex.threshold
    approaching = reflex.initial & (state[1:] == 0.0) & ~touching
    return touching | approaching, touching


def reflex_directions(reflex, state, tip, normal, fn) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """(g (3, 2), grasp, touching, whether the centroid squeeze was the fallback)."""
    grasp, touching = reflex_members(reflex, state, fn)
    g = np.zeros((3, 2))
    if grasp.sum() < 2:
        return g, grasp, touching, False
    points = tip.reshape(3, 3)[:, :2]
    push = normal.reshape(3, 2).copy()
    for i in np.flatnonzero(grasp & ~touching):
        toward = points[grasp & (np.arange(3) != i)].mean(axis=0) - points[i]
        push[i] = toward / max(np.linalg.norm(toward), 1e-12)
    idx = np.flatnonzero(grasp)
    internal = project_internal(points[idx], push[idx].ravel()).reshape(-1, 2)
    fallback = bool(np.any(np.einsum("ij,ij->i", internal, push[idx]) <= 0))
    if fallback:
        internal = internal_directions(points[idx])
    g[idx] = internal / np.max(np.linalg.norm(internal, axis=1))
    return g, grasp, touching, fallback


def reflex_forces(reflex, state, inputs) -> tuple[np.ndarray, np.ndarray]:
    """(f (3, 2), grasp): ``s g_i`` touching (at most the scale handed over at), else ``g_i``
    scaled to the approach force."""
    g, grasp, touching, _ = reflex_directions(reflex, state, inputs["tip"], inputs["normal"], inputs["fn"])
    length = np.linalg.norm(g, axis=1)
    held_at = np.where(state[1:] > 0, np.minimum(state[0], state[1:]), state[0])
    scale = np.where(touching, held_at, reflex.approach_force / np.maximum(length, 1e-300))
    return g * scale[:, None], grasp


def reflex_output(reflex, state, inputs) -> dict[str, np.ndarray]:
    """A ``GraspReflex`` block's output ports: ``J_i^T f_i``, ``|f_i|``, the grasp flags."""
    f, grasp = reflex_forces(reflex, state, inputs)
    jac = reflex.hand.tip_jacobians(inputs["q"])
    tau = np.concatenate([jac[i].T @ f[i] for i in range(3)])
    return {"tau_g": tau, "force": np.linalg.norm(f, axis=1), "active": grasp.astype(float)}


def reflex_update(reflex, state, inputs) -> np.ndarray:
    """A ``GraspReflex`` block's next state: the integral step over the fingers it holds."""
    fn, ft = inputs["fn"], inputs["ft"]
    g, grasp, touching, _ = reflex_directions(reflex, state, inputs["tip"], inputs["normal"], fn)
    share = inputs.get("share", np.ones(3))
    released = np.zeros(3, dtype=bool)
    for i in np.argsort(share, kind="stable"):  # the least share first, while two others stay held
        if grasp[i] and touching[i] and share[i] < reflex.release_share and (grasp & touching & ~released).sum() > 2:
            released[i] = True
    held = grasp & touching & ~released
    scale = state[0]
    if held.sum() >= 2:
        normal = inputs["normal"].reshape(3, 2)[held]
        gain = np.einsum("ij,ij->i", g[held], normal)
        need = np.maximum(reflex.min_force * np.linalg.norm(g[held], axis=1), np.abs(ft[held]) / reflex.ratio_target)
        shortfall = float(np.max((need - fn[held]) / np.maximum(gain, 1e-3)))
        scale = min(max(scale + reflex.ki * reflex.dt * shortfall, 0.0), reflex.max_force)
    first = np.where(state[1:] > 0, state[1:], max(state[0], np.finfo(float).tiny))
    return np.concatenate(([scale], np.where(touching, np.where(released, first, 0.0), state[1:])))


# -- kinematics ----------------------------------------------------------------------------------


def wrap_angle(a: Any) -> np.ndarray:
    """To (-pi, pi]."""
    w = math.pi - np.mod(math.pi - np.asarray(a, dtype=float), 2 * math.pi)
    return np.where(w <= -math.pi, w + 2 * math.pi, w)  # np.mod(-tiny, 2 pi) rounds to 2 pi


def finger_fk(base, base_angle: float, lengths, q) -> np.ndarray:
    """(x, y, phi) of the tip centre: the links' directions summed."""
    th = base_angle + np.cumsum(np.asarray(q, dtype=float))
    ls = np.asarray(lengths, dtype=float)
    return np.array([base[0] + np.sum(ls * np.cos(th)), base[1] + np.sum(ls * np.sin(th)), th[2]])


def finger_ik(base, base_angle: float, lengths, x: float, y: float, phi: float, elbow: int = 1) -> np.ndarray | None:
    """Wrapped joint angles of the elbow branch (+1: q2 >= 0), None out of reach."""
    l1, l2, l3 = lengths
    wx = x - l3 * math.cos(phi) - base[0]
    wy = y - l3 * math.sin(phi) - base[1]
    r = math.hypot(wx, wy)
    tol = REACH_RTOL * (l1 + l2)
    if not abs(l1 - l2) - tol <= r <= l1 + l2 + tol:
        return None
    q2 = elbow * math.acos(min(1.0, max(-1.0, (r * r - l1 * l1 - l2 * l2) / (2 * l1 * l2))))
    th1 = math.atan2(wy, wx) - math.atan2(l2 * math.sin(q2), l1 + l2 * math.cos(q2))
    return wrap_angle(np.array([th1 - base_angle, q2, phi - th1 - q2]))


def finger_geometry(hand, f: int) -> tuple[tuple[float, float], float, tuple[float, float, float]]:
    """(base, base angle, link lengths) of finger f of a ``Hand``."""
    finger = hand.params.fingers[f]
    return tuple(finger.base), finger.base_angle, tuple(link.length for link in finger.links)


def finger_ik_near(hand, f: int, target, q_ref) -> np.ndarray | None:
    """The branch nearer q_ref (elbow +1 on a tie), each angle nearest q_ref; None out of reach."""
    ref = np.asarray(q_ref, dtype=float)
    branches = [finger_ik(*finger_geometry(hand, f), *target, elbow=e) for e in (1, -1)]
    if branches[0] is None:
        return None
    steps = [wrap_angle(b - ref) for b in branches]
    return ref + min(steps, key=lambda d: float(np.dot(d, d)))


# -- trajectories -------------------------------------------------------------------------------


def minjerk(tau: float) -> float:
    """``s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5``."""
    return tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau))


def minjerk_rate(tau: float) -> float:
    """``ds/dtau = 30 tau^2 (1 - tau)^2``."""
    return 30.0 * tau * tau * (1.0 - tau) ** 2


def _segment(times: np.ndarray, t: float) -> tuple[int, float, float]:
    i = min(max(int(np.searchsorted(times, t, side="right")) - 1, 0), times.size - 2)
    span = times[i + 1] - times[i]
    return i, (t - times[i]) / span, span


def trajectory_sample(waypoints, interpolation: str, t: float) -> np.ndarray:
    """Pose at t: held before the first and after the last waypoint."""
    w = np.asarray(waypoints, dtype=float)
    times, points = w[:, 0], w[:, 1:]
    if t <= times[0]:
        return points[0].copy()
    if t >= times[-1]:
        return points[-1].copy()
    i, tau, _ = _segment(times, t)
    s = minjerk(tau) if interpolation == "minjerk" else tau
    return points[i] + s * (points[i + 1] - points[i])


def trajectory_velocity(waypoints, interpolation: str, t: float) -> np.ndarray:
    """Right-continuous time derivative of ``trajectory_sample``."""
    w = np.asarray(waypoints, dtype=float)
    times, points = w[:, 0], w[:, 1:]
    if t < times[0] or t >= times[-1]:
        return np.zeros(3)
    i, tau, span = _segment(times, t)
    rate = minjerk_rate(tau) if interpolation == "minjerk" else 1.0
    return (rate / span) * (points[i + 1] - points[i])


# -- manipulation PD ----------------------------------------------------------------------------


def manipulation_output(pd, t: float, inputs: Mapping[str, np.ndarray], step: float = 1e-3) -> dict[str, np.ndarray]:
    """A ``ManipulationPD`` block's output ports: targets by IK of the sampled trajectories
    (velocity by central differences ``step`` either side), joint PD, gravity and load
    feedforward through the hand model. ``ValueError`` for a target out of reach."""
    hand = pd.hand
    q_ref, qd_ref = hand.q0.copy(), np.zeros(9)
    for f, traj in enumerate(pd.trajectories):
        if traj is None:
            continue
        waypoints, near = np.column_stack([traj.times, traj.points]), hand.q0[3 * f:3 * f + 3]

        def target(when: float) -> np.ndarray:
            q = finger_ik_near(hand, f, trajectory_sample(waypoints, traj.interpolation, when), near)
            if q is None:
                raise ValueError(f"finger {f}: the target at t = {when} is out of reach")
            return q

        q_ref[3 * f:3 * f + 3] = target(t)
        if np.any(trajectory_velocity(waypoints, traj.interpolation, t)):
            qd_ref[3 * f:3 * f + 3] = (target(t + step) - target(t - step)) / (2 * step)
    q, qd = np.asarray(inputs["q"], dtype=float), np.asarray(inputs["qd"], dtype=float)
    tau_m = pd.kp * (q_ref - q) + pd.kd * (qd_ref - qd)
    tau_ff = hand.bias(q, np.zeros(9)) if pd.gravity_compensation else np.zeros(9)
    carrying = np.asarray(inputs["fn"]) > pd.threshold
    if pd.load_compensation and carrying.any():
        support = np.asarray(inputs.get("support", np.zeros(3)), dtype=float)
        share = -(pd.weight + support[:2]) / carrying.sum()
        jac = hand.tip_jacobians(q)
        for f in np.flatnonzero(carrying):
            tau_ff[3 * f:3 * f + 3] += jac[f].T @ share
    return {"tau_m": tau_m, "tau_ff": tau_ff, "q_ref": q_ref}
