"""``Hand``: a validated hand file packed for the kernels, with kinematics and dynamics.

Vectors follow the hand file's order: q = thumb joints 1-3, fore 1-3, middle 1-3
(proximal to distal, relative angles). The methods evaluate the same compiled functions
the plant's kernel uses, so what a controller computes from them is what the plant does.
"""

from __future__ import annotations

import functools
import json

from pathlib import Path
from typing import Any, Mapping

import numpy as np

from .dynamics import finger_bias, finger_mass_matrix
from .handfile import HandParams, merge_with_default, parse_hand, read_hand_file
from .kinematics import finger_frames, point_jacobian
from .layout import (
    B_C_N,
    B_C_T,
    B_GX,
    B_GY,
    B_HALF_A,
    B_HALF_B,
    B_INERTIA,
    B_K_N,
    B_K_T,
    B_MASS,
    B_MU_D,
    B_MU_S,
    E_COUNT,
    E_DX,
    E_DY,
    E_OX,
    E_OY,
    E_SPACING,
    E_START,
    F_ARMATURE,
    F_BASE_ANGLE,
    F_BASE_X,
    F_BASE_Y,
    F_DAMPING,
    F_LINK0,
    F_LINK_STRIDE,
    F_TIP_RADIUS,
    L_COM_ACROSS,
    L_COM_ALONG,
    L_INERTIA,
    L_LENGTH,
    L_MASS,
    N_BODY_PARAMS,
    N_EDGE_COLS,
    N_EDGES,
    N_FINGER_PARAMS,
)


def load_hand(path_or_dict: str | Path | Mapping[str, Any]) -> "Hand":
    """A hand from a hand file (path) or its content (dict); missing sections default.

    Hands built from equal contents are one shared object (the plant and both
    controllers of a diagram read the same hand); treat a Hand as read-only.
    """
    if isinstance(path_or_dict, Mapping):
        try:
            key = json.dumps(path_or_dict, sort_keys=True)
        except (TypeError, ValueError):  # contents JSON cannot hold: no sharing, same checks
            return Hand(parse_hand(merge_with_default(path_or_dict)))
        return _hand_from_json(key)
    source = str(path_or_dict)
    return Hand(parse_hand(merge_with_default(read_hand_file(source)), source))


@functools.lru_cache(maxsize=64)
def _hand_from_json(key: str) -> "Hand":
    return Hand(parse_hand(merge_with_default(json.loads(key))))


class Hand:
    """Three planar 3-link fingers with circular tips, and a square object."""

    n_joints = 9

    def __init__(self, params: HandParams):
        self.params = params
        self.names = tuple(f.name for f in params.fingers)
        self.fingers = _pack_fingers(params)
        self.body = _pack_body(params)
        self.edges = _pack_edges(params)
        self.n_points = int(self.edges[:, E_COUNT].sum())
        self.tip_radius = self.fingers[:, F_TIP_RADIUS].copy()
        self.q0 = np.array([x for f in params.fingers for x in f.q0], dtype=float)
        self.gravity = np.array(params.gravity, dtype=float)

    @classmethod
    def default(cls) -> "Hand":
        """The shipped default hand (``default_hand.yaml``)."""
        return load_hand({})

    @property
    def object_pose0(self) -> np.ndarray:
        o = self.params.object
        return np.array([o.pos[0], o.pos[1], o.angle])

    # -- kinematics ---------------------------------------------------------------

    def _frames(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        q = _vector(q, 9, "q")
        u = np.empty((3, 3, 2))
        pts = np.empty((3, 4, 2))
        phi = np.empty(3)
        for f in range(3):
            phi[f] = finger_frames(self.fingers, f, q, 3 * f, u, pts)
        return u, pts, phi

    def joint_positions(self, q: np.ndarray) -> np.ndarray:
        """(3, 4, 2): per finger joints 1-3 and the tip centre."""
        return self._frames(q)[1]

    def tip_positions(self, q: np.ndarray) -> np.ndarray:
        """(3, 2): fingertip-circle centres."""
        return self._frames(q)[1][:, 3, :].copy()

    def tip_poses(self, q: np.ndarray) -> np.ndarray:
        """(3, 3): tip centre x, y and phi, the absolute angle of link 3."""
        _, pts, phi = self._frames(q)
        return np.column_stack([pts[:, 3, :], phi])

    def tip_jacobians(self, q: np.ndarray) -> np.ndarray:
        """(3, 2, 3): d(tip centre of finger f)/d(its three joint angles)."""
        _, pts, _ = self._frames(q)
        jac = np.empty((3, 2, 3))
        for f in range(3):
            point_jacobian(pts, f, pts[f, 3, 0], pts[f, 3, 1], jac)
        return jac

    def point_jacobian(self, q: np.ndarray, finger: int, point: np.ndarray) -> np.ndarray:
        """(2, 3): Jacobian of the point of link 3 of ``finger`` now at ``point``."""
        _, pts, _ = self._frames(q)
        jac = np.empty((3, 2, 3))
        point_jacobian(pts, finger, float(point[0]), float(point[1]), jac)
        return jac[finger]

    # -- dynamics -----------------------------------------------------------------

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """(9, 9): joint-space mass matrix including armature (block-diagonal per finger)."""
        u, _, _ = self._frames(q)
        m = np.zeros((9, 9))
        block = np.empty((3, 3))
        for f in range(3):
            finger_mass_matrix(self.fingers, f, u, block)
            m[3 * f : 3 * f + 3, 3 * f : 3 * f + 3] = block
        return m

    def bias(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """(9,): Coriolis/centrifugal + gravity + joint damping; tau = M qdd + bias."""
        qd = _vector(qd, 9, "qd")
        u, _, _ = self._frames(q)
        h = np.empty(9)
        gx, gy = self.gravity
        for f in range(3):
            h[3 * f : 3 * f + 3] = finger_bias(
                self.fingers, f, u, qd[3 * f], qd[3 * f + 1], qd[3 * f + 2], gx, gy
            )
        return h

    def static_torques(self, q: np.ndarray, forces: np.ndarray, points: np.ndarray | None = None) -> np.ndarray:
        """(9,): torques holding ``q`` at rest against gravity while fingertip f pushes
        the object with ``forces[f]`` (3, 2) applied at ``points[f]`` (default: tip centres).
        """
        forces = np.asarray(forces, dtype=float).reshape(3, 2)
        tau = self.bias(q, np.zeros(9))
        _, pts, _ = self._frames(q)
        if points is None:
            points = pts[:, 3, :]
        points = np.asarray(points, dtype=float).reshape(3, 2)
        jac = np.empty((3, 2, 3))
        for f in range(3):
            point_jacobian(pts, f, points[f, 0], points[f, 1], jac)
            tau[3 * f : 3 * f + 3] += jac[f].T @ forces[f]
        return tau

    # -- object -------------------------------------------------------------------

    def surface_points(self, pose: np.ndarray | None = None) -> np.ndarray:
        """(n_points, 2): the object's surface points, in the object frame or at ``pose``."""
        local = np.empty((self.n_points, 2))
        for e in range(N_EDGES):
            row = self.edges[e]
            k = np.arange(int(row[E_COUNT]))
            s = int(row[E_START])
            local[s : s + k.size, 0] = row[E_OX] + (k * row[E_SPACING]) * row[E_DX]
            local[s : s + k.size, 1] = row[E_OY] + (k * row[E_SPACING]) * row[E_DY]
        if pose is None:
            return local
        x, y, th = np.asarray(pose, dtype=float)
        c, s_ = np.cos(th), np.sin(th)
        return np.column_stack([x + c * local[:, 0] - s_ * local[:, 1], y + s_ * local[:, 0] + c * local[:, 1]])

    def object_corners(self, pose: np.ndarray) -> np.ndarray:
        """(4, 2): the square's corners at ``pose``, counter-clockwise from bottom left."""
        a, b = self.params.object.size
        local = np.array([[-a / 2, -b / 2], [a / 2, -b / 2], [a / 2, b / 2], [-a / 2, b / 2]])
        x, y, th = np.asarray(pose, dtype=float)
        c, s = np.cos(th), np.sin(th)
        return np.column_stack([x + c * local[:, 0] - s * local[:, 1], y + s * local[:, 0] + c * local[:, 1]])


def _vector(x: Any, n: int, name: str) -> np.ndarray:
    arr = np.ascontiguousarray(x, dtype=float)
    if arr.shape != (n,):
        raise ValueError(f"{name} must have shape ({n},), got {arr.shape}")
    return arr


def _pack_fingers(params: HandParams) -> np.ndarray:
    rows = np.zeros((3, N_FINGER_PARAMS))
    for f, finger in enumerate(params.fingers):
        row = rows[f]
        row[F_BASE_X], row[F_BASE_Y] = finger.base
        row[F_BASE_ANGLE] = finger.base_angle
        for i, link in enumerate(finger.links):
            k = F_LINK0 + F_LINK_STRIDE * i
            row[k + L_LENGTH] = link.length
            row[k + L_MASS] = link.mass
            row[k + L_COM_ALONG] = link.com_along
            row[k + L_COM_ACROSS] = link.com_across
            row[k + L_INERTIA] = link.inertia
        row[F_DAMPING : F_DAMPING + 3] = finger.damping
        row[F_ARMATURE : F_ARMATURE + 3] = finger.armature
        row[F_TIP_RADIUS] = finger.tip_radius
    return rows


def _pack_body(params: HandParams) -> np.ndarray:
    """Gravity, object and contact parameters; the step (B_DT) is set by the plant."""
    body = np.zeros(N_BODY_PARAMS)
    body[B_GX], body[B_GY] = params.gravity
    o = params.object
    body[B_MASS] = o.mass
    body[B_INERTIA] = o.inertia
    body[B_HALF_A] = o.size[0] / 2
    body[B_HALF_B] = o.size[1] / 2
    c = params.contact
    body[B_K_N] = c.k_n
    body[B_C_N] = c.c_n
    body[B_K_T] = c.k_t
    body[B_C_T] = c.c_t
    body[B_MU_S] = c.mu_s
    body[B_MU_D] = c.mu_d
    return body


def _pack_edges(params: HandParams) -> np.ndarray:
    """The square's four edges counter-clockwise from the bottom-left corner.

    Each edge of length L gets round(L / surface_spacing) points, evenly spaced, so the
    spacing is as close to the requested one as a whole number of points allows.
    """
    a, b = params.object.size
    corners = [(-a / 2, -b / 2), (a / 2, -b / 2), (a / 2, b / 2), (-a / 2, b / 2)]
    edges = np.zeros((N_EDGES, N_EDGE_COLS))
    start = 0
    for e in range(N_EDGES):
        (x0, y0), (x1, y1) = corners[e], corners[(e + 1) % N_EDGES]
        length = float(np.hypot(x1 - x0, y1 - y0))
        count = max(1, int(round(length / params.object.surface_spacing)))
        dx, dy = (x1 - x0) / length, (y1 - y0) / length
        edges[e] = [x0, y0, dx, dy, dy, -dx, length / count, count, start]
        start += count
    return edges
