"""Planar finger kinematics (compiled): link directions, joint points, Jacobians.

Joint angles are relative: link i of a finger points at ``base_angle + q1 + ... + qi``
(counter-clockwise from +x). Link 3 ends at the fingertip-circle centre.
"""

from __future__ import annotations

import math

from numba import njit

from .layout import F_BASE_ANGLE, F_BASE_X, F_BASE_Y, F_LINK0, F_LINK_STRIDE, L_LENGTH


@njit(cache=True, inline="always")
def finger_frames(fingers, f, q, q_off, u, pts):
    """Fill link directions ``u[f]`` (3, 2) and points ``pts[f]`` (4, 2) of finger ``f``.

    ``fingers`` holds the parameter rows, ``q[q_off:q_off + 3]`` the finger's joint angles.
    ``pts[f]`` gets joints 1-3 and the tip centre. Returns the absolute angle of link 3.
    (Whole arrays and an index rather than views: views cost reference counting.)
    """
    th = fingers[f, F_BASE_ANGLE]
    x = fingers[f, F_BASE_X]
    y = fingers[f, F_BASE_Y]
    for i in range(3):
        pts[f, i, 0] = x
        pts[f, i, 1] = y
        th += q[q_off + i]
        c = math.cos(th)
        s = math.sin(th)
        u[f, i, 0] = c
        u[f, i, 1] = s
        length = fingers[f, F_LINK0 + F_LINK_STRIDE * i + L_LENGTH]
        x += length * c
        y += length * s
    pts[f, 3, 0] = x
    pts[f, 3, 1] = y
    return th


@njit(cache=True, inline="always")
def point_jacobian(pts, f, px, py, jac):
    """Jacobian ``jac[f]`` (2, 3) of finger f's link-3 point at (px, py).

    Column j is ``z x (p - joint_j)``, the velocity of the point per unit rate of joint j.
    """
    for j in range(3):
        jac[f, 0, j] = -(py - pts[f, j, 1])
        jac[f, 1, j] = px - pts[f, j, 0]
