"""Penalty contact between a fingertip circle and the object's surface points (compiled).

The paper's law, per object surface point inside a fingertip circle:

- normal ``n``: from the tip centre through the point; penetration ``d = r - |p - c|``
  (the anchor's normal coordinate is the circle itself, which is rigid);
  ``f_n = k_n d + c_n d'``, clipped at 0 (no adhesion);
- tangent ``t = z x n``; the anchor is the fingertip material point the surface point
  first touched, kept in the frame of link 3 so that it moves (and rolls) with the
  fingertip; ``f_t = -k_t e - c_t v_t`` with ``e = t . (p - anchor)`` and ``v_t`` the
  tangential velocity of the object point relative to the fingertip;
- stick while ``|f_t| < mu_s f_n``; otherwise slip with ``f_t = mu_d f_n sign(f_t)`` and the
  anchor moved so the spring alone gives that slip force;
- a point that leaves the circle loses its anchor.

``f_n n + f_t t`` acts on the object at the point and its opposite on link 3 at the same
point, so every pair is equal and opposite with a common line of action.

Only points that can lie in the circle are visited: per edge of the square, the tip
centre is projected on the edge line and only the points within the chord
``|s_k - s| <= sqrt(r^2 - dist^2)`` are tested. The visited index range per edge (the
"window") is stored in the state, so that at the next commit the points of the previous
window that are no longer visited are released; points outside every window never hold
an anchor. Contact evaluation is a pure function of the state: anchor changes are
written to a pending buffer and only ``commit`` (part of an update) applies them, so the
forces reported at a hit and the forces that drive the step from it are identical.
"""

from __future__ import annotations

import math

from numba import njit

from .layout import (
    B_C_N,
    B_C_T,
    B_HALF_A,
    B_HALF_B,
    B_K_N,
    B_K_T,
    B_MU_D,
    B_MU_S,
    E_COUNT,
    E_DX,
    E_DY,
    E_NX,
    E_NY,
    E_OX,
    E_OY,
    E_SPACING,
    E_START,
    ERR_PENETRATION,
    N_EDGES,
    OK,
    S_TOUCH,
    S_WINDOW,
)

# Per-finger contact summary written by ``finger_contact`` (wrench[f, :]).
W_OBJ_FX = 0  # force on the object
W_OBJ_FY = 1
W_OBJ_M = 2  # its moment about the object's centre
W_TIP_M = 3  # moment of the force on the object about the tip centre (the finger gets minus)
W_FN = 4  # summed normal force
W_FT = 5  # summed tangential force (signed, along t = z x n)
W_FN_PX = 6  # sum of f_n * p, for the force-weighted contact point
W_FN_PY = 7
N_WRENCH = 8


@njit(cache=True, inline="always")
def finger_contact(
    state, f, npts, body, edges,
    cx, cy, cphi, sphi, vcx, vcy, wphi, radius,
    ox, oy, co, so, ovx, ovy, ow,
    window, pend_anchor, pend_flag, wrench,
):
    """Contact forces between finger ``f``'s tip and the object, from the state alone.

    Tip: centre (cx, cy), link-3 direction (cphi, sphi), centre velocity (vcx, vcy),
    angular rate wphi. Object: pose (ox, oy, angle with cos co / sin so), velocity
    (ovx, ovy, ow). Fills this finger's new ``window[f]`` (4, 2), the pending anchors and
    flags of the visited points in window order, and ``wrench[f]`` (N_WRENCH,). Returns
    ``ERR_PENETRATION`` if the tip centre lies inside the object (penetration deeper than
    the radius), else ``OK``.
    """
    for i in range(N_WRENCH):
        wrench[f, i] = 0.0
    dx = cx - ox
    dy = cy - oy
    lx = co * dx + so * dy
    ly = -so * dx + co * dy
    if abs(lx) < body[B_HALF_A] and abs(ly) < body[B_HALF_B]:
        return ERR_PENETRATION
    k_n = body[B_K_N]
    c_n = body[B_C_N]
    k_t = body[B_K_T]
    c_t = body[B_C_T]
    mu_s = body[B_MU_S]
    mu_d = body[B_MU_D]
    r2 = radius * radius
    touch = S_TOUCH + f * npts
    anchor = S_TOUCH + 3 * npts + 2 * f * npts
    j = 0
    for e in range(N_EDGES):
        window[f, e, 0] = 0
        window[f, e, 1] = -1
        ex = edges[e, E_OX]
        ey = edges[e, E_OY]
        edx = edges[e, E_DX]
        edy = edges[e, E_DY]
        rx = lx - ex
        ry = ly - ey
        dist = rx * edges[e, E_NX] + ry * edges[e, E_NY]
        if dist >= radius or dist <= -radius:
            continue
        h = edges[e, E_SPACING]
        s = rx * edx + ry * edy
        half = math.sqrt(r2 - dist * dist)
        lo = max(0, int(math.ceil((s - half) / h)))
        hi = min(int(edges[e, E_COUNT]) - 1, int(math.floor((s + half) / h)))
        if lo > hi:
            continue
        window[f, e, 0] = lo
        window[f, e, 1] = hi
        start = int(edges[e, E_START])
        for k in range(lo, hi + 1):
            idx = start + k
            plx = ex + (k * h) * edx
            ply = ey + (k * h) * edy
            px = ox + co * plx - so * ply
            py = oy + so * plx + co * ply
            relx = px - cx
            rely = py - cy
            d2 = relx * relx + rely * rely
            if d2 >= r2:
                pend_flag[f, j] = 0
                j += 1
                continue
            rho = math.sqrt(d2)
            if rho <= 1e-12 * radius:
                return ERR_PENETRATION
            nx = relx / rho
            ny = rely / rho
            tx = -ny
            ty = nx
            # velocity of the object point relative to the fingertip material point at p
            vrx = (ovx - ow * (py - oy)) - (vcx - wphi * rely)
            vry = (ovy + ow * (px - ox)) - (vcy + wphi * relx)
            fn = k_n * (radius - rho) - c_n * (nx * vrx + ny * vry)
            if fn < 0.0:
                fn = 0.0
            held = state[touch + idx] != 0.0
            if held:
                alx = state[anchor + 2 * idx]
                aly = state[anchor + 2 * idx + 1]
                awx = cx + cphi * alx - sphi * aly
                awy = cy + sphi * alx + cphi * aly
            else:
                alx = 0.0
                aly = 0.0
                awx = px
                awy = py
            stretch = tx * (px - awx) + ty * (py - awy)
            ft = -k_t * stretch - c_t * (tx * vrx + ty * vry)
            if abs(ft) < mu_s * fn:
                if not held:
                    alx = cphi * relx + sphi * rely
                    aly = -sphi * relx + cphi * rely
            else:
                if ft > 0.0:
                    ft = mu_d * fn
                elif ft < 0.0:
                    ft = -mu_d * fn
                awx = px + (ft / k_t) * tx - cx
                awy = py + (ft / k_t) * ty - cy
                alx = cphi * awx + sphi * awy
                aly = -sphi * awx + cphi * awy
            pend_anchor[f, j, 0] = alx
            pend_anchor[f, j, 1] = aly
            pend_flag[f, j] = 1
            j += 1
            fx = fn * nx + ft * tx
            fy = fn * ny + ft * ty
            wrench[f, W_OBJ_FX] += fx
            wrench[f, W_OBJ_FY] += fy
            wrench[f, W_OBJ_M] += (px - ox) * fy - (py - oy) * fx
            wrench[f, W_TIP_M] += relx * fy - rely * fx
            wrench[f, W_FN] += fn
            wrench[f, W_FT] += ft
            wrench[f, W_FN_PX] += fn * px
            wrench[f, W_FN_PY] += fn * py
    return OK


@njit(cache=True, inline="always")
def commit_anchors(state, f, npts, edges, window, pend_anchor, pend_flag):
    """Apply finger ``f``'s pending anchors: release its old window, write the new one."""
    touch = S_TOUCH + f * npts
    anchor = S_TOUCH + 3 * npts + 2 * f * npts
    for e in range(N_EDGES):
        w = S_WINDOW + 8 * f + 2 * e
        start = int(edges[e, E_START])
        for k in range(int(state[w]), int(state[w + 1]) + 1):
            state[touch + start + k] = 0.0
    j = 0
    for e in range(N_EDGES):
        w = S_WINDOW + 8 * f + 2 * e
        start = int(edges[e, E_START])
        lo = window[f, e, 0]
        hi = window[f, e, 1]
        state[w] = lo
        state[w + 1] = hi
        for k in range(lo, hi + 1):
            idx = start + k
            if pend_flag[f, j] != 0:
                state[touch + idx] = 1.0
                state[anchor + 2 * idx] = pend_anchor[f, j, 0]
                state[anchor + 2 * idx + 1] = pend_anchor[f, j, 1]
            j += 1
