"""Finger dynamics (compiled): recursive Newton-Euler for M(q) and h(q, qd).

Each finger is a planar serial chain on a fixed base, so the hand's 9x9 mass matrix is
block-diagonal. ``rnea`` returns the joint torques that produce given joint accelerations;
the mass matrix comes from it column by column (zero velocity and gravity, unit
acceleration), the bias from zero acceleration. Gravity enters as an upward acceleration
of the base. Armature (reflected motor inertia) adds to M's diagonal, joint viscous
damping to h, so that ``tau = M qdd + h`` for a finger without contact.
"""

from __future__ import annotations

from numba import njit

from .layout import (
    F_ARMATURE,
    F_DAMPING,
    F_LINK0,
    F_LINK_STRIDE,
    L_COM_ACROSS,
    L_COM_ALONG,
    L_INERTIA,
    L_LENGTH,
    L_MASS,
)


@njit(cache=True, inline="always")
def _com_offset(fingers, f, u, i):
    """Vector from joint i to the COM of link i, and the link's length."""
    k = F_LINK0 + F_LINK_STRIDE * i
    ux = u[f, i, 0]
    uy = u[f, i, 1]
    along = fingers[f, k + L_COM_ALONG]
    across = fingers[f, k + L_COM_ACROSS]
    return along * ux - across * uy, along * uy + across * ux, fingers[f, k + L_LENGTH]


@njit(cache=True, inline="always")
def _forward(fingers, f, u, i, ax, ay, w, al):
    """Acceleration of link i's COM and of the next joint, given joint i's acceleration."""
    rcx, rcy, length = _com_offset(fingers, f, u, i)
    w2 = w * w
    lx = length * u[f, i, 0]
    ly = length * u[f, i, 1]
    return (
        ax - al * rcy - w2 * rcx,
        ay + al * rcx - w2 * rcy,
        ax - al * ly - w2 * lx,
        ay + al * lx - w2 * ly,
    )


@njit(cache=True, inline="always")
def _backward(fingers, f, u, i, acx, acy, al, fx, fy, n):
    """Force and moment (about joint i) that link i receives from its parent joint."""
    rcx, rcy, length = _com_offset(fingers, f, u, i)
    k = F_LINK0 + F_LINK_STRIDE * i
    m = fingers[f, k + L_MASS]
    mx = m * acx
    my = m * acy
    lx = length * u[f, i, 0]
    ly = length * u[f, i, 1]
    n = fingers[f, k + L_INERTIA] * al + (rcx * my - rcy * mx) + (lx * fy - ly * fx) + n
    return mx + fx, my + fy, n


@njit(cache=True, inline="always")
def rnea(fingers, f, u, qd0, qd1, qd2, qdd0, qdd1, qdd2, gx, gy):
    """Joint torques (3-tuple) of one finger's rigid links, without armature or damping.

    ``fingers``: parameter rows; ``u``: link directions (3, 3, 2) from ``finger_frames``.
    Angular rates and accelerations of link i are the sums over joints 1..i.
    """
    w0 = qd0
    w1 = w0 + qd1
    w2 = w1 + qd2
    al0 = qdd0
    al1 = al0 + qdd1
    al2 = al1 + qdd2
    acx0, acy0, ax, ay = _forward(fingers, f, u, 0, -gx, -gy, w0, al0)
    acx1, acy1, ax, ay = _forward(fingers, f, u, 1, ax, ay, w1, al1)
    acx2, acy2, ax, ay = _forward(fingers, f, u, 2, ax, ay, w2, al2)
    fx, fy, n2 = _backward(fingers, f, u, 2, acx2, acy2, al2, 0.0, 0.0, 0.0)
    fx, fy, n1 = _backward(fingers, f, u, 1, acx1, acy1, al1, fx, fy, n2)
    fx, fy, n0 = _backward(fingers, f, u, 0, acx0, acy0, al0, fx, fy, n1)
    return n0, n1, n2


@njit(cache=True, inline="always")
def finger_mass_matrix(fingers, f, u, m):
    """Fill ``m`` (3, 3) with the finger's mass matrix including armature."""
    for j in range(3):
        a0 = 1.0 if j == 0 else 0.0
        a1 = 1.0 if j == 1 else 0.0
        a2 = 1.0 if j == 2 else 0.0
        c0, c1, c2 = rnea(fingers, f, u, 0.0, 0.0, 0.0, a0, a1, a2, 0.0, 0.0)
        m[0, j] = c0
        m[1, j] = c1
        m[2, j] = c2
    for j in range(3):
        m[j, j] += fingers[f, F_ARMATURE + j]


@njit(cache=True, inline="always")
def finger_bias(fingers, f, u, qd0, qd1, qd2, gx, gy):
    """Coriolis/centrifugal + gravity + joint viscous damping torques (3-tuple)."""
    h0, h1, h2 = rnea(fingers, f, u, qd0, qd1, qd2, 0.0, 0.0, 0.0, gx, gy)
    return (
        h0 + fingers[f, F_DAMPING] * qd0,
        h1 + fingers[f, F_DAMPING + 1] * qd1,
        h2 + fingers[f, F_DAMPING + 2] * qd2,
    )


@njit(cache=True, inline="always")
def solve_spd3(m, b0, b1, b2):
    """Solve ``m x = b`` for a symmetric positive definite 3x3 ``m`` (lower part read).

    Adjugate over determinant: one division, no square roots. The finger mass matrices
    are well conditioned (the armature bounds their smallest eigenvalue from below).
    """
    a = m[0, 0]
    b = m[1, 0]
    c = m[2, 0]
    d = m[1, 1]
    e = m[2, 1]
    f = m[2, 2]
    ca = d * f - e * e
    cb = c * e - b * f
    cc = b * e - c * d
    cd = a * f - c * c
    ce = b * c - a * e
    cf = a * d - b * b
    inv = 1.0 / (a * ca + b * cb + c * cc)
    return (
        (ca * b0 + cb * b1 + cc * b2) * inv,
        (cb * b0 + cd * b1 + ce * b2) * inv,
        (cc * b0 + ce * b1 + cf * b2) * inv,
    )
