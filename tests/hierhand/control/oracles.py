"""Readable numpy formulations of the controllers' laws: the oracles the compiled laws are
checked against.

The package has one implementation of each law, in C (``hierhand/csrc``), which the
blocks and the Python API of ``hierhand.control`` call. These are independent of it:
written from the formulas (``numpy.linalg.pinv`` for the grasp-matrix projection, the
link walk for the kinematics, ``numpy.searchsorted`` for the trajectory segments), so the
tests can tell a wrong formula from round-off. Most were the package's numpy
implementations before the laws were written once (issue 14), rewritten with the laws
since; the C agrees with them to round-off, often to the bit.
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


def suppression_input(tau_g: Any, tau_m: Any, mode: str) -> np.ndarray:
    """``g(tau_m)``: ``|tau_m|``, or ``tau_m`` signed positive against the grasping torque."""
    tau_g, tau_m = np.asarray(tau_g, dtype=float), np.asarray(tau_m, dtype=float)
    return np.abs(tau_m) if mode == "magnitude" else np.where(tau_g >= 0, -tau_m, tau_m)


def suppress(tau_g: Any, tau_m: Any, s_a: Any, s_b: Any, mode: str = "signed") -> np.ndarray:
    """``tau_g * sigmoid(S_a (S_b - g(tau_m)))``."""
    g = suppression_input(tau_g, tau_m, mode)
    return np.asarray(tau_g, dtype=float) * sigmoid(np.asarray(s_a, dtype=float) * (np.asarray(s_b, dtype=float) - g))


def finger_shares(tau_g: Any, tau_g_eff: Any) -> np.ndarray:
    """Per finger ``tau_g_eff_i . tau_g_i / |tau_g_i|^2``, 1 where ``tau_g_i = 0``."""
    g = np.asarray(tau_g, dtype=float).reshape(3, 3)
    kept = np.asarray(tau_g_eff, dtype=float).reshape(3, 3)
    squared = (g * g).sum(axis=1)
    along = (kept * g).sum(axis=1)
    return np.where(squared > 0.0, along / np.where(squared > 0.0, squared, 1.0), 1.0)


def suppresser_output(block, inputs: Mapping[str, np.ndarray], state: Any = None) -> dict[str, np.ndarray]:
    """A ``Suppresser`` block's output ports; ``state``: the low-passed g of a filtered one."""
    tau_g, tau_m = np.asarray(inputs["tau_g"], dtype=float), np.asarray(inputs["tau_m"], dtype=float)
    tau_ff = np.asarray(inputs.get("tau_ff", np.zeros(9)), dtype=float)
    if not block.enabled:
        return {"tau": (tau_g + tau_m) + tau_ff, "tau_g_eff": tau_g.copy(), "share": np.ones(3)}
    g = suppression_input(tau_g, tau_m, block.mode) if state is None else np.asarray(state, dtype=float)
    effective = tau_g * sigmoid(block.S_a * (block.S_b - g))
    return {"tau": (effective + tau_m) + tau_ff, "tau_g_eff": effective, "share": finger_shares(tau_g, effective)}


def suppresser_update(block, state: np.ndarray, inputs: Mapping[str, np.ndarray], period: float) -> np.ndarray:
    """A filtered ``Suppresser``'s next state: g low-passed with time constant ``block.time_constant``."""
    if not block.enabled:
        return np.asarray(state, dtype=float).copy()
    alpha = 1.0 - math.exp(-period / block.time_constant)
    g = suppression_input(inputs["tau_g"], inputs["tau_m"], block.mode)
    return state + alpha * (g - state)


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
    that are not touching and were not marked handed over when they last touched."""
    touching = fn > reflex.threshold
    approaching = reflex.initial & (state[1:4] == 0.0) & ~touching
    return touching | approaching, touching


def acting_points(reflex, tip, normal, touching) -> np.ndarray:
    """(3, 2): a touching finger's contact point (tip centre plus radius along the normal), else its tip centre."""
    points = np.asarray(tip, dtype=float).reshape(3, 3)[:, :2]
    return points + np.where(touching, reflex.hand.tip_radius, 0.0)[:, None] * np.asarray(normal, dtype=float).reshape(3, 2)


def _squeeze(points, push, members) -> tuple[np.ndarray, bool]:
    """(g (3, 2) over the members, largest row 1; whether the centroid squeeze was the fallback)."""
    g = np.zeros((3, 2))
    idx = np.flatnonzero(members)
    internal = project_internal(points[idx], push[idx].ravel()).reshape(-1, 2)
    fallback = bool(np.any(np.einsum("ij,ij->i", internal, push[idx]) <= 0))
    if fallback:
        internal = internal_directions(points[idx])
    g[idx] = internal / np.max(np.linalg.norm(internal, axis=1))
    return g, fallback


def _toward(tip, members, i) -> np.ndarray:
    """A unit push from finger i's tip centre toward the members' tip centres' centroid."""
    centres = np.asarray(tip, dtype=float).reshape(3, 3)[:, :2]
    toward = centres[members & (np.arange(3) != i)].mean(axis=0) - centres[i]
    return toward / max(np.linalg.norm(toward), 1e-12)


def reflex_directions(reflex, state, tip, normal, fn) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """(g (3, 2), grasp, touching, whether the centroid squeeze was the fallback)."""
    grasp, touching = reflex_members(reflex, state, fn)
    g = np.zeros((3, 2))
    if grasp.sum() < 2:
        return g, grasp, touching, False
    points = acting_points(reflex, tip, normal, touching)
    push = np.asarray(normal, dtype=float).reshape(3, 2).copy()
    if touching.sum() < 2:  # all of the grasp close on each other
        for i in np.flatnonzero(grasp & ~touching):
            push[i] = _toward(tip, grasp, i)
        g, fallback = _squeeze(points, push, grasp)
        return g, grasp, touching, fallback
    g, fallback = _squeeze(points, push, touching)
    hold = state[4:7]
    partial = [i for i in np.flatnonzero(touching) if hold[i] < 1.0]
    if touching.sum() == 3 and partial:
        i = min(partial, key=lambda j: hold[j])
        two, fallback_two = _squeeze(points, push, touching & (np.arange(3) != i))
        g = hold[i] * g + (1.0 - hold[i]) * two
        fallback = fallback or fallback_two
    for i in np.flatnonzero(grasp & ~touching):  # approaching the touching ones
        g[i] = _toward(tip, touching, i)
    return g, grasp, touching, fallback


def reflex_forces(reflex, state, inputs) -> tuple[np.ndarray, np.ndarray]:
    """(f (3, 2), grasp): ``s g_i`` touching, else ``g_i`` scaled to the approach force."""
    g, grasp, touching, _ = reflex_directions(reflex, state, inputs["tip"], inputs["normal"], inputs["fn"])
    length = np.linalg.norm(g, axis=1)
    scale = np.where(touching, state[0], reflex.approach_force / np.maximum(length, 1e-300))
    return g * scale[:, None], grasp


def reflex_output(reflex, state, inputs) -> dict[str, np.ndarray]:
    """A ``GraspReflex`` block's output ports: ``J_i^T f_i`` at the acting points (their offsets
    from the measured tip centres carried to the tips at ``q``), ``|f_i|``, the grasp flags."""
    f, grasp = reflex_forces(reflex, state, inputs)
    touching = np.asarray(inputs["fn"]) > reflex.threshold
    offsets = acting_points(reflex, inputs["tip"], inputs["normal"], touching) - np.asarray(
        inputs["tip"], dtype=float).reshape(3, 3)[:, :2]
    q = np.asarray(inputs["q"], dtype=float)
    points = reflex.hand.tip_positions(q) + offsets
    tau = np.concatenate([reflex.hand.point_jacobian(q, i, points[i]).T @ f[i] for i in range(3)])
    return {"tau_g": tau, "force": np.linalg.norm(f, axis=1), "active": grasp.astype(float)}


def reflex_holds(reflex, state, share, touching) -> np.ndarray:
    """How much the reflex holds each finger: the two touching ones with the largest share 1, a
    third 1 down to hold_share falling linearly to 0 at release_share; one out of contact keeps its hold."""
    hold = np.asarray(state[4:7], dtype=float).copy()
    order = sorted(np.flatnonzero(touching), key=lambda i: -share[i])  # stable: the first of equals
    for rank, i in enumerate(order):
        if rank < 2 or not reflex.follow_suppression:
            hold[i] = 1.0
        else:
            hold[i] = min(max((share[i] - reflex.release_share) / (reflex.hold_share - reflex.release_share), 0.0), 1.0)
    return hold


def reflex_update(reflex, state, inputs) -> np.ndarray:
    """A ``GraspReflex`` block's next state: the holds, the integral step weighted by them, the marks."""
    fn, ft = inputs["fn"], inputs["ft"]
    g, grasp, touching, _ = reflex_directions(reflex, state, inputs["tip"], inputs["normal"], fn)
    hold = reflex_holds(reflex, state, np.asarray(inputs.get("share", np.ones(3)), dtype=float), touching)
    scale = state[0]
    if touching.sum() >= 2:
        normal = inputs["normal"].reshape(3, 2)[touching]
        gain = np.einsum("ij,ij->i", g[touching], normal)
        need = np.maximum(reflex.min_force * np.linalg.norm(g[touching], axis=1),
                          np.abs(ft[touching]) / reflex.ratio_target)
        driving = hold[touching] > 0  # a finger wholly handed over does not count at all
        if driving.any():
            shortfall = float(np.max((hold[touching] * (need - fn[touching]) / np.maximum(gain, 1e-3))[driving]))
            scale = min(max(scale + reflex.ki * reflex.dt * shortfall, 0.0), reflex.max_force)
    handed = np.where(touching, (hold < 1.0).astype(float), state[1:4])
    return np.concatenate(([scale], handed, hold))


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


def matched_gains(inertia: float, kp: float, kd: float, period: float) -> tuple[float, float]:
    """The held gains whose sampled loop on a pure inertia has the poles exp(s T) of the
    continuous loop J s^2 + kd s + kp: from the ZOH model x+ = x + T v + T^2 u / (2J),
    v+ = v + T u / J with u = -kp_T x - kd_T v, whose characteristic polynomial is
    z^2 - (2 - a/2 - b) z + (1 - b + a/2) (a = kp_T T^2 / J, b = kd_T T / J)."""
    s = np.roots([inertia, kd, kp])
    z = np.exp(s * period)
    trace, det = float(np.real(z.sum())), float(np.real(np.prod(z)))
    b = (3.0 - trace - det) / 2.0
    a = 2.0 * (2.0 - trace - b)
    return a * inertia / period ** 2, b * inertia / period


def distribute(points: np.ndarray, weights: np.ndarray, origin: np.ndarray, wrench: np.ndarray) -> np.ndarray:
    """(k, 2): forces with the least sum of |f_i|^2 / w_i giving ``wrench`` (fx, fy, moment
    about origin): the weighted pseudo-inverse of the grasp matrix, by numpy. One point
    cannot balance a moment: it takes the force and the moment is dropped (the pseudo-inverse
    about ``origin`` would trade some of the force for the moment)."""
    if len(points) == 1:
        return np.asarray(wrench, dtype=float)[None, :2].copy()
    g = grasp_matrix(points, origin)
    w = np.repeat(np.asarray(weights, dtype=float), 2)
    f = w * (g.T @ np.linalg.pinv(g @ (w[:, None] * g.T)) @ np.asarray(wrench, dtype=float))
    return f.reshape(-1, 2)


def manipulation_output(pd, t: float, inputs: Mapping[str, np.ndarray], step: float = 1e-3) -> dict[str, np.ndarray]:
    """A ``ManipulationPD`` block's output ports: targets by IK of the sampled trajectories
    (velocity by central differences ``step`` either side), moved for fingers in contact by
    fn / k_n along their normal, joint PD (gains matched to each joint's inertia for a
    'matched' PD), gravity and load feedforward through the hand model (the load shared by the
    grasp matrix at the contact points, weighted by the normal forces). ``ValueError`` for a
    target out of reach."""
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
    fn, normal = np.asarray(inputs["fn"], dtype=float), np.asarray(inputs["normal"], dtype=float).reshape(3, 2)
    carrying = fn > pd.threshold
    if pd.contact_compensation:
        for f in np.flatnonzero(carrying):
            base, angle, lengths = finger_geometry(hand, f)
            x, y, phi = finger_fk(base, angle, lengths, q_ref[3 * f:3 * f + 3])
            depth = fn[f] / hand.params.contact.k_n
            moved = finger_ik_near(hand, f, (x + depth * normal[f, 0], y + depth * normal[f, 1], phi),
                                   q_ref[3 * f:3 * f + 3])
            if moved is not None:
                q_ref[3 * f:3 * f + 3] = moved
    kp, kd = np.array(pd.kp, dtype=float), np.array(pd.kd, dtype=float)
    if pd.discretization == "matched":
        inertia = np.diag(hand.mass_matrix(q))
        for j in range(9):
            kp[j], kd[j] = matched_gains(inertia[j], kp[j], kd[j], float(pd.period))
    tau_m = kp * (q_ref - q) + kd * (qd_ref - qd)
    tau_ff = hand.bias(q, np.zeros(9)) if pd.gravity_compensation else np.zeros(9)
    if pd.load_compensation and carrying.any():
        support = np.asarray(inputs.get("support", np.zeros(3)), dtype=float)
        tips = hand.tip_positions(q)
        idx = np.flatnonzero(carrying)
        points = tips[idx] + hand.tip_radius[idx, None] * normal[idx]
        load = np.concatenate((-(pd.weight + support[:2]), [-support[2]]))
        shares = distribute(points, fn[idx], np.asarray(inputs["obj"], dtype=float)[:2], load)
        for share, f, point in zip(shares, idx, points):
            tau_ff[3 * f:3 * f + 3] += hand.point_jacobian(q, f, point).T @ share
    return {"tau_m": tau_m, "tau_ff": tau_ff, "q_ref": q_ref}
