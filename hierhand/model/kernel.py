"""The plant's compiled step: contact evaluation, semi-implicit Euler, output rows.

One step from state k: evaluate kinematics and contact forces of state k (a pure function
of the state), commit the anchor changes, then integrate velocity first and position
with the new velocity (semi-implicit, or symplectic, Euler):

    qd += dt * M(q)^-1 (tau + J^T f_contact - h(q, qd));   q += dt * qd

and likewise for the object. Why not explicit Euler (the paper's "Euler's method"):
explicit Euler adds energy to every undamped oscillation, so a penalty contact needs
heavy damping to stay stable above about 1e4 N/m; semi-implicit Euler keeps oscillators'
energy bounded and stays stable up to about 3e5 N/m at 0.1 ms, at the same cost.

``advance_kernel`` runs n steps and the output rows after each in one call. The
evaluation of state k+1 gives both the outputs after step k and the forces of step k+1,
so it is done once; ``step_kernel`` / ``output_kernel`` call the very same functions, so
n updates each followed by an output give bit-identical results.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .contact import (
    N_WRENCH,
    W_FN,
    W_FN_PX,
    W_FN_PY,
    W_FT,
    W_OBJ_FX,
    W_OBJ_FY,
    W_OBJ_M,
    W_TIP_M,
    commit_anchors,
    finger_contact,
)
from .dynamics import finger_bias, finger_mass_matrix, solve_spd3
from .kinematics import finger_frames, point_jacobian
from .layout import (
    B_DT,
    B_GX,
    B_GY,
    B_INERTIA,
    B_MASS,
    E_COUNT,
    ERR_F_EXT,
    ERR_OBJ,
    ERR_OBJ_VEL,
    ERR_Q,
    ERR_QD,
    ERR_TAU,
    F_TIP_RADIUS,
    N_EDGES,
    O_CONTACT,
    O_FN,
    O_FT,
    O_OBJ,
    O_NORMAL,
    O_OBJ_VEL,
    O_Q,
    O_QD,
    O_RATIO,
    O_TIP,
    OK,
    S_OBJ,
    S_OBJ_VEL,
    S_Q,
    S_QD,
)


@njit(cache=True)
def n_points(edges):
    n = 0
    for e in range(N_EDGES):
        n += int(edges[e, E_COUNT])
    return n


@njit(cache=True)
def make_workspace(npts):
    """Scratch arrays for one kernel call (allocated once per call, never per step)."""
    u = np.empty((3, 3, 2))  # link directions
    pts = np.empty((3, 4, 2))  # joints 1-3 and tip centre
    jac = np.empty((3, 2, 3))  # tip-centre Jacobians
    tip = np.empty((3, 3))  # tip centre x, y and link-3 angle phi
    gen = np.empty(9)  # joint torques from contact
    wrench = np.empty((3, N_WRENCH))  # per-finger contact summary
    window = np.empty((3, N_EDGES, 2), dtype=np.int64)  # visited point ranges
    pend_anchor = np.empty((3, npts, 2))
    pend_flag = np.empty((3, npts), dtype=np.uint8)
    mass = np.empty((3, 3))
    return u, pts, jac, tip, gen, wrench, window, pend_anchor, pend_flag, mass


@njit(cache=True)
def evaluate(state, fingers, body, edges, npts, ws):
    """Kinematics and contact forces of ``state`` into the workspace; (code, finger)."""
    u, pts, jac, tip, gen, wrench, window, pend_anchor, pend_flag, mass = ws
    ox = state[S_OBJ]
    oy = state[S_OBJ + 1]
    th = state[S_OBJ + 2]
    co = math.cos(th)
    so = math.sin(th)
    ovx = state[S_OBJ_VEL]
    ovy = state[S_OBJ_VEL + 1]
    ow = state[S_OBJ_VEL + 2]
    for f in range(3):
        phi = finger_frames(fingers, f, state, S_Q + 3 * f, u, pts)
        cx = pts[f, 3, 0]
        cy = pts[f, 3, 1]
        point_jacobian(pts, f, cx, cy, jac)
        qd0 = state[S_QD + 3 * f]
        qd1 = state[S_QD + 3 * f + 1]
        qd2 = state[S_QD + 3 * f + 2]
        vcx = jac[f, 0, 0] * qd0 + jac[f, 0, 1] * qd1 + jac[f, 0, 2] * qd2
        vcy = jac[f, 1, 0] * qd0 + jac[f, 1, 1] * qd1 + jac[f, 1, 2] * qd2
        wphi = qd0 + qd1 + qd2
        tip[f, 0] = cx
        tip[f, 1] = cy
        tip[f, 2] = phi
        code = finger_contact(
            state, f, npts, body, edges,
            cx, cy, u[f, 2, 0], u[f, 2, 1], vcx, vcy, wphi, fingers[f, F_TIP_RADIUS],
            ox, oy, co, so, ovx, ovy, ow,
            window, pend_anchor, pend_flag, wrench,
        )
        if code != OK:
            return code, f
        # the finger gets minus the force on the object, and minus its moment about c
        fx = wrench[f, W_OBJ_FX]
        fy = wrench[f, W_OBJ_FY]
        mc = wrench[f, W_TIP_M]
        for j in range(3):
            gen[3 * f + j] = -(jac[f, 0, j] * fx + jac[f, 1, j] * fy) - mc
    return OK, 0


@njit(cache=True)
def commit(state, edges, npts, ws):
    window = ws[6]
    pend_anchor = ws[7]
    pend_flag = ws[8]
    for f in range(3):
        commit_anchors(state, f, npts, edges, window, pend_anchor, pend_flag)


@njit(cache=True)
def integrate(state, tau, f_ext, fingers, body, ws):
    """Semi-implicit Euler step of fingers and object with the evaluated contact forces."""
    u = ws[0]
    gen = ws[4]
    wrench = ws[5]
    mass = ws[9]
    dt = body[B_DT]
    gx = body[B_GX]
    gy = body[B_GY]
    for f in range(3):
        iq = S_Q + 3 * f
        iv = S_QD + 3 * f
        qd0 = state[iv]
        qd1 = state[iv + 1]
        qd2 = state[iv + 2]
        finger_mass_matrix(fingers, f, u, mass)
        h0, h1, h2 = finger_bias(fingers, f, u, qd0, qd1, qd2, gx, gy)
        a0, a1, a2 = solve_spd3(
            mass,
            tau[3 * f] + gen[3 * f] - h0,
            tau[3 * f + 1] + gen[3 * f + 1] - h1,
            tau[3 * f + 2] + gen[3 * f + 2] - h2,
        )
        qd0 += dt * a0
        qd1 += dt * a1
        qd2 += dt * a2
        state[iv] = qd0
        state[iv + 1] = qd1
        state[iv + 2] = qd2
        state[iq] += dt * qd0
        state[iq + 1] += dt * qd1
        state[iq + 2] += dt * qd2
    fx = f_ext[0]
    fy = f_ext[1]
    mz = f_ext[2]
    for f in range(3):
        fx += wrench[f, W_OBJ_FX]
        fy += wrench[f, W_OBJ_FY]
        mz += wrench[f, W_OBJ_M]
    vx = state[S_OBJ_VEL] + dt * (fx / body[B_MASS] + gx)
    vy = state[S_OBJ_VEL + 1] + dt * (fy / body[B_MASS] + gy)
    w = state[S_OBJ_VEL + 2] + dt * (mz / body[B_INERTIA])
    state[S_OBJ_VEL] = vx
    state[S_OBJ_VEL + 1] = vy
    state[S_OBJ_VEL + 2] = w
    state[S_OBJ] += dt * vx
    state[S_OBJ + 1] += dt * vy
    state[S_OBJ + 2] += dt * w


@njit(cache=True)
def first_non_finite(x, start, n):
    for i in range(n):
        if not math.isfinite(x[start + i]):
            return i
    return -1


@njit(cache=True)
def check_state(state):
    """(code, index) of the first non-finite quantity of the rigid-body state.

    Velocities first: a blow-up shows in them one step before it reaches the positions.
    """
    i = first_non_finite(state, S_QD, 9)
    if i >= 0:
        return ERR_QD, i
    i = first_non_finite(state, S_Q, 9)
    if i >= 0:
        return ERR_Q, i
    i = first_non_finite(state, S_OBJ_VEL, 3)
    if i >= 0:
        return ERR_OBJ_VEL, i
    i = first_non_finite(state, S_OBJ, 3)
    if i >= 0:
        return ERR_OBJ, i
    return OK, 0


@njit(cache=True)
def check_inputs(tau, f_ext):
    i = first_non_finite(tau, 0, 9)
    if i >= 0:
        return ERR_TAU, i
    i = first_non_finite(f_ext, 0, 3)
    if i >= 0:
        return ERR_F_EXT, i
    return OK, 0


@njit(cache=True)
def write_outputs(state, ws, row):
    tip = ws[3]
    wrench = ws[5]
    for i in range(9):
        row[O_Q + i] = state[S_Q + i]
        row[O_QD + i] = state[S_QD + i]
    for f in range(3):
        row[O_TIP + 3 * f] = tip[f, 0]
        row[O_TIP + 3 * f + 1] = tip[f, 1]
        row[O_TIP + 3 * f + 2] = tip[f, 2]
        fn = wrench[f, W_FN]
        ft = wrench[f, W_FT]
        row[O_FN + f] = fn
        row[O_FT + f] = ft
        row[O_NORMAL + 2 * f] = 0.0
        row[O_NORMAL + 2 * f + 1] = 0.0
        if fn > 0.0:
            row[O_RATIO + f] = abs(ft) / fn
            row[O_CONTACT + f] = 1.0
            nx = wrench[f, W_FN_PX] / fn - tip[f, 0]
            ny = wrench[f, W_FN_PY] / fn - tip[f, 1]
            length = np.sqrt(nx * nx + ny * ny)
            if length > 0.0:
                row[O_NORMAL + 2 * f] = nx / length
                row[O_NORMAL + 2 * f + 1] = ny / length
        else:
            row[O_RATIO + f] = 0.0
            row[O_CONTACT + f] = 0.0
    for i in range(3):
        row[O_OBJ + i] = state[S_OBJ + i]
        row[O_OBJ_VEL + i] = state[S_OBJ_VEL + i]


@njit(cache=True)
def start_steps(state, tau, f_ext, fingers, body, edges):
    """Check the inputs and the state and evaluate the contacts before the first update:
    (code, index, number of surface points, workspace)."""
    code, which = check_inputs(tau, f_ext)
    if code == OK:
        code, which = check_state(state)
    npts = n_points(edges)
    ws = make_workspace(npts)
    if code == OK:
        code, which = evaluate(state, fingers, body, edges, npts, ws)
    return code, which, npts, ws


@njit(cache=True)
def step_kernel(state, tau, f_ext, fingers, body, edges):
    """One update in place; returns (code, updates done when it was found, index)."""
    code, which, npts, ws = start_steps(state, tau, f_ext, fingers, body, edges)
    if code != OK:
        return code, 0, which
    commit(state, edges, npts, ws)
    integrate(state, tau, f_ext, fingers, body, ws)
    code, which = check_state(state)
    return code, 1, which


@njit(cache=True)
def output_kernel(state, fingers, body, edges, row):
    """The output row of ``state``; returns (code, index)."""
    code, which = check_state(state)
    if code != OK:
        return code, which
    npts = n_points(edges)
    ws = make_workspace(npts)
    code, which = evaluate(state, fingers, body, edges, npts, ws)
    if code != OK:
        return code, which
    write_outputs(state, ws, row)
    return OK, 0


@njit(cache=True)
def contact_kernel(state, fingers, body, edges, tips, wrenches):
    """Per-finger tip poses (3, 3) and contact summaries (3, N_WRENCH) of ``state``."""
    npts = n_points(edges)
    ws = make_workspace(npts)
    code, which = evaluate(state, fingers, body, edges, npts, ws)
    tips[:, :] = ws[3]
    wrenches[:, :] = ws[5]
    return code, which


@njit(cache=True)
def advance_kernel(state, tau, f_ext, fingers, body, edges, rows):
    """``rows.shape[0]`` updates in place, each followed by its output row.

    Returns (code, done, index): ``done`` is the number of updates completed when an
    error was found in the state (0: the starting state), ``rows.shape[0]`` on success.
    """
    n = rows.shape[0]
    code, which, npts, ws = start_steps(state, tau, f_ext, fingers, body, edges)
    if code != OK:
        return code, 0, which
    for i in range(n):
        commit(state, edges, npts, ws)
        integrate(state, tau, f_ext, fingers, body, ws)
        code, which = check_state(state)
        if code != OK:
            return code, i + 1, which
        code, which = evaluate(state, fingers, body, edges, npts, ws)
        if code != OK:
            return code, i + 1, which
        write_outputs(state, ws, rows[i])
    return OK, n, 0
