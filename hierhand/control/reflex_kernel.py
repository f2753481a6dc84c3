"""Compiled kernels of the grasping reflex (``GraspReflex``): one call per output / update.

The reflex runs every 1 ms, so a hit must cost a few microseconds. These ``@njit``
functions do a whole ``output`` or ``update`` over flat float64 arrays, with the grasp
matrix solve written out by hand (no ``numpy.linalg``, no allocation beyond the result).
``internal_forces.py`` stays the numpy reference; the tests compare the two.

Parameters travel packed in one array (slots ``P_*``, built by ``pack_params``) so that a
call costs little to dispatch.

The internal force among the ``k`` fingers of the grasp (2 or 3) is
``(I - G^+ G) n``, with ``G`` the (3, 2k) grasp matrix about the grasp points' centroid
``c`` (columns ``[I2; (-r_iy, r_ix)]``, ``r_i = p_i - c``). ``G`` has full row rank unless
all points coincide, so ``G^+ G n = G^T x`` with ``(G G^T) x = G n``, and
``G G^T = [[k, 0, a], [0, k, b], [a, b, s]]`` (``a = -sum r_iy``, ``b = sum r_ix``, both
round-off about the centroid, ``s = sum |r_i|^2``) is solved by eliminating the two
``k`` pivots first. When the moment row is numerically dependent (Schur complement at or
below ``numpy.linalg.pinv``'s cut-off, ``1e-15`` on the singular values) the moment
equation is dropped, as ``pinv`` does.

The tip Jacobians come from the plant's own compiled kinematics (``finger_frames``,
``point_jacobian`` in ``hierhand.model.kinematics``) over ``Hand.fingers``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..model.kernel_cache import invalidate_if_stale
from ..model.kinematics import finger_frames, point_jacobian

# -- packed parameters: params[P_*] -----------------------------------------------------
P_THRESHOLD = 0  # contact_threshold, N
P_APPROACH = 1  # approach_force, N
P_KI = 2  # integral gain, 1/s
P_DT = 3  # period, s (NaN until bound)
P_MIN_FORCE = 4
P_RATIO = 5  # ratio_target = safety_ratio / (1 + margin)
P_MAX_FORCE = 6
P_INITIAL = 7  # three slots: 1.0 for the fingers listed in 'grasp'
N_PARAMS = 10

# -- output vector of reflex_output: tau_g(9) force(3) active(3) ------------------------
O_TAU = 0
O_FORCE = 9
O_ACTIVE = 12
N_OUT = 15

_PINV_RCOND2 = 1e-30  # numpy.linalg.pinv's rcond (1e-15) squared: a cut-off on eigenvalues of G G^T
_COINCIDENT_RTOL = 1e-12  # as internal_forces._COINCIDENT_RTOL
_TINY = np.finfo(np.float64).tiny


def pack_params(threshold: float, approach_force: float, ki: float, dt: float, min_force: float,
                ratio_target: float, max_force: float, initial) -> np.ndarray:
    """The reflex parameters as the kernels' flat array (``initial``: 3 booleans)."""
    p = np.empty(N_PARAMS)
    p[P_THRESHOLD] = threshold
    p[P_APPROACH] = approach_force
    p[P_KI] = ki
    p[P_DT] = dt
    p[P_MIN_FORCE] = min_force
    p[P_RATIO] = ratio_target
    p[P_MAX_FORCE] = max_force
    p[P_INITIAL : P_INITIAL + 3] = np.asarray(initial, dtype=bool)
    return p


@njit(cache=True)
def _check_inputs(state, tip, normal, fn):
    if state.shape[0] != 4:
        raise ValueError("GraspReflex: state must have 4 entries [scale, touched(3)]")
    if tip.shape[0] != 9:
        raise ValueError("GraspReflex: input 'tip' must have 9 entries")
    if normal.shape[0] != 6:
        raise ValueError("GraspReflex: input 'normal' must have 6 entries")
    if fn.shape[0] != 3:
        raise ValueError("GraspReflex: input 'fn' must have 3 entries")


@njit(cache=True, inline="always")
def _directions(params, state, tip, normal, fn, g, grasp, touching):
    """Fill ``g`` (3, 2), the internal force per finger at unit scale (largest row length
    1, zero outside the grasp), and the flags ``grasp`` / ``touching`` (3,) booleans.

    ``touching``: ``fn > contact_threshold``; ``grasp``: touching, or listed in 'grasp',
    not touched yet and not touching. With fewer than two fingers in the grasp ``g`` is 0.
    Otherwise every finger pushes along its normal, an approaching one toward the others'
    centroid, and ``g`` is ``(I - G^+ G) push`` over the grasp, or the centroid squeeze
    ``c - p_i`` when that projection leaves some finger not pushing (``g_i . push_i <= 0``).
    """
    threshold = params[P_THRESHOLD]
    k = 0
    for i in range(3):
        touching[i] = fn[i] > threshold
        approaching = params[P_INITIAL + i] != 0.0 and state[1 + i] == 0.0 and not touching[i]
        grasp[i] = touching[i] or approaching
        g[i, 0] = 0.0
        g[i, 1] = 0.0
        if grasp[i]:
            k += 1
    if k < 2:
        return
    # push directions: the contact normal, or toward the others' centroid while approaching
    push = np.empty((3, 2))
    for i in range(3):
        if not grasp[i]:
            continue
        if touching[i]:
            push[i, 0] = normal[2 * i]
            push[i, 1] = normal[2 * i + 1]
            continue
        sx = 0.0
        sy = 0.0
        m = 0
        for j in range(3):
            if j != i and grasp[j]:
                sx += tip[3 * j]
                sy += tip[3 * j + 1]
                m += 1
        tx = sx / m - tip[3 * i]
        ty = sy / m - tip[3 * i + 1]
        d = max(math.sqrt(tx * tx + ty * ty), 1e-12)
        push[i, 0] = tx / d
        push[i, 1] = ty / d
    # centroid of the grasp points
    cx = 0.0
    cy = 0.0
    for i in range(3):
        if grasp[i]:
            cx += tip[3 * i]
            cy += tip[3 * i + 1]
    cx /= k
    cy /= k
    # w = G push, and G G^T = [[k, 0, a], [0, k, b], [a, b, s]]
    w0 = 0.0
    w1 = 0.0
    w2 = 0.0
    a = 0.0
    b = 0.0
    s = 0.0
    for i in range(3):
        if grasp[i]:
            rx = tip[3 * i] - cx
            ry = tip[3 * i + 1] - cy
            w0 += push[i, 0]
            w1 += push[i, 1]
            w2 += rx * push[i, 1] - ry * push[i, 0]
            a -= ry
            b += rx
            s += rx * rx + ry * ry
    fk = float(k)
    schur = s - (a * a + b * b) / fk
    if schur > _PINV_RCOND2 * max(fk, s):
        x2 = (w2 - (a * w0 + b * w1) / fk) / schur
    else:  # all points coincide: the moment row carries nothing (pinv drops it)
        x2 = 0.0
    x0 = (w0 - a * x2) / fk
    x1 = (w1 - b * x2) / fk
    # internal = push - G^T x; fall back to the centroid squeeze if a finger would not push
    ok = True
    for i in range(3):
        if grasp[i]:
            rx = tip[3 * i] - cx
            ry = tip[3 * i + 1] - cy
            g[i, 0] = push[i, 0] - (x0 - ry * x2)
            g[i, 1] = push[i, 1] - (x1 + rx * x2)
            if g[i, 0] * push[i, 0] + g[i, 1] * push[i, 1] <= 0.0:
                ok = False
    if not ok:
        spread = 0.0
        size = 0.0
        for i in range(3):
            if grasp[i]:
                g[i, 0] = cx - tip[3 * i]
                g[i, 1] = cy - tip[3 * i + 1]
                spread = max(spread, math.hypot(g[i, 0], g[i, 1]))
                size = max(size, abs(tip[3 * i]), abs(tip[3 * i + 1]))
        if spread <= _COINCIDENT_RTOL * max(size, _TINY):
            raise ValueError("internal forces are undefined: all contact points coincide")
        for i in range(3):
            g[i, 0] /= spread
            g[i, 1] /= spread
    longest = 0.0
    for i in range(3):
        longest = max(longest, math.sqrt(g[i, 0] * g[i, 0] + g[i, 1] * g[i, 1]))
    for i in range(3):
        g[i, 0] /= longest
        g[i, 1] /= longest


@njit(cache=True, inline="always")
def _forces(params, state, g, touching, f):
    """Fill ``f`` (3, 2): ``g_i`` times the scale for a touching finger, else scaled to
    ``approach_force`` (zero where ``g_i`` is)."""
    for i in range(3):
        length = math.sqrt(g[i, 0] * g[i, 0] + g[i, 1] * g[i, 1])
        scale = state[0] if touching[i] else params[P_APPROACH] / max(length, 1e-300)
        f[i, 0] = g[i, 0] * scale
        f[i, 1] = g[i, 1] * scale


@njit(cache=True)
def reflex_directions(params, state, tip, normal, fn):
    """(g (3, 2), grasp (3,) bool, touching (3,) bool): ``GraspReflex.directions``."""
    _check_inputs(state, tip, normal, fn)
    g = np.empty((3, 2))
    grasp = np.empty(3, dtype=np.bool_)
    touching = np.empty(3, dtype=np.bool_)
    _directions(params, state, tip, normal, fn, g, grasp, touching)
    return g, grasp, touching


@njit(cache=True)
def reflex_forces(params, state, tip, normal, fn):
    """(f (3, 2), grasp (3,) bool): ``GraspReflex.forces``."""
    g, grasp, touching = reflex_directions(params, state, tip, normal, fn)
    f = np.empty((3, 2))
    _forces(params, state, g, touching, f)
    return f, grasp


@njit(cache=True)
def reflex_output(params, fingers, state, q, tip, normal, fn):
    """(15,) fresh array ``[tau_g (9), |f_i| (3), in grasp (3, 0/1)]``.

    ``tau_g`` stacks ``J_i^T f_i``, ``J_i`` the Jacobian of finger i's tip centre at ``q``.
    """
    _check_inputs(state, tip, normal, fn)
    if q.shape[0] != 9:
        raise ValueError("GraspReflex: input 'q' must have 9 entries")
    g = np.empty((3, 2))
    grasp = np.empty(3, dtype=np.bool_)
    touching = np.empty(3, dtype=np.bool_)
    _directions(params, state, tip, normal, fn, g, grasp, touching)
    f = np.empty((3, 2))
    _forces(params, state, g, touching, f)
    u = np.empty((3, 3, 2))
    pts = np.empty((3, 4, 2))
    jac = np.empty((3, 2, 3))
    out = np.empty(N_OUT)
    for i in range(3):
        finger_frames(fingers, i, q, 3 * i, u, pts)
        point_jacobian(pts, i, pts[i, 3, 0], pts[i, 3, 1], jac)
        for j in range(3):
            out[O_TAU + 3 * i + j] = jac[i, 0, j] * f[i, 0] + jac[i, 1, j] * f[i, 1]
        out[O_FORCE + i] = math.sqrt(f[i, 0] * f[i, 0] + f[i, 1] * f[i, 1])
        out[O_ACTIVE + i] = 1.0 if grasp[i] else 0.0
    return out


@njit(cache=True)
def reflex_update(params, state, tip, normal, fn, ft):
    """(4,) fresh next state ``[scale, touched (3)]``.

    With at least two fingers both in the grasp and touching, the scale moves by
    ``ki * dt * max_i (need_i - fn_i) / max(g_i . n_i, 1e-3)``, ``need_i =
    max(min_force |g_i|, |ft_i| / ratio_target)``, clipped to ``[0, max_force]``.
    """
    _check_inputs(state, tip, normal, fn)
    if ft.shape[0] != 3:
        raise ValueError("GraspReflex: input 'ft' must have 3 entries")
    dt = params[P_DT]
    if not dt > 0.0:
        raise ValueError("GraspReflex needs an explicit period (the paper's is 1 ms)")
    g = np.empty((3, 2))
    grasp = np.empty(3, dtype=np.bool_)
    touching = np.empty(3, dtype=np.bool_)
    _directions(params, state, tip, normal, fn, g, grasp, touching)
    scale = state[0]
    held = 0
    shortfall = -np.inf
    for i in range(3):
        if grasp[i] and touching[i]:
            held += 1
            gain = g[i, 0] * normal[2 * i] + g[i, 1] * normal[2 * i + 1]  # normal force per unit scale
            length = math.sqrt(g[i, 0] * g[i, 0] + g[i, 1] * g[i, 1])
            need = max(params[P_MIN_FORCE] * length, abs(ft[i]) / params[P_RATIO])
            shortfall = max(shortfall, (need - fn[i]) / max(gain, 1e-3))
    if held >= 2:
        scale = min(max(scale + params[P_KI] * dt * shortfall, 0.0), params[P_MAX_FORCE])
    new = np.empty(4)
    new[0] = scale
    for i in range(3):
        new[1 + i] = max(state[1 + i], 1.0 if touching[i] else 0.0)
    return new


# A compiled kernel also holds the kinematics it inlines: drop our cache entries when the
# model's kernel sources change (numba keys the cache on this file only).
invalidate_if_stale([_check_inputs, reflex_directions, reflex_forces, reflex_output, reflex_update],
                    stamp_name="hierhand_reflex_kernel.sha256")
