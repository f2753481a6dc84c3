"""``Hand``: a validated hand file packed for the C core, with kinematics and dynamics.

Vectors follow the hand file's order: q = thumb joints 1-3, fore 1-3, middle 1-3
(proximal to distal, relative angles). The methods call the same C functions the plant's
step uses (``hierhand/csrc``), so what a controller computes from them is what the plant
does.
"""

from __future__ import annotations

import functools
import json

from pathlib import Path
from typing import Any, Mapping

import numpy as np

from blocks.arrays import float_array

from .. import _native
from ..layouts import BODY, DIMENSIONS, EDGE, FINGER_ROW
from .handfile import HandFileError, HandParams, merge_with_default, parse_hand, read_hand_file


def load_hand(path_or_dict: str | Path | Mapping[str, Any]) -> "Hand":
    """A hand from a hand file (path) or its content (dict); missing sections default.
    HandFileError for an invalid hand, with the line of each problem when read from a file.

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
    data = read_hand_file(source)
    try:
        return Hand(parse_hand(merge_with_default(data), source))
    except HandFileError as exc:
        raise exc.located(data) from None


@functools.lru_cache(maxsize=64)
def _hand_from_json(key: str) -> "Hand":
    return Hand(parse_hand(merge_with_default(json.loads(key))))


class Hand:
    """Three planar 3-link fingers with circular tips, and a square object.

    ``native`` is the hand packed for the C core (a ``hierhand._native.Model`` without a
    step); ``fingers``, ``body`` and ``edges`` are read-only copies of its packed
    parameter rows, ``vector`` the hand's numbers in the core's order.
    """

    n_joints = 9

    def __init__(self, params: HandParams):
        self.params = params
        self.names = tuple(f.name for f in params.fingers)
        self.vector = params.vector
        self.native = _native.Model(self.vector)
        self.fingers = np.empty((3, FINGER_ROW.size))
        self.body = np.empty(BODY.size)
        self.edges = np.empty((DIMENSIONS["EDGES"], EDGE.size))
        self.q0 = np.empty(9)
        pose0 = np.empty(3)
        self.native.pack_into(self.fingers, self.body, self.edges, self.q0, pose0)
        self.n_points = self.native.npts
        self.tip_radius = self.fingers[:, FINGER_ROW.TIP_RADIUS].copy()
        self.gravity = np.array(params.gravity, dtype=float)
        self._pose0 = pose0
        for array in (self.fingers, self.body, self.edges, self.q0, self.tip_radius, self.gravity, pose0):
            array.flags.writeable = False

    @classmethod
    def default(cls) -> "Hand":
        """The shipped default hand (``default_hand.yaml``)."""
        return load_hand({})

    @property
    def object_pose0(self) -> np.ndarray:
        """(3,): the object's initial x, y and angle."""
        return self._pose0.copy()

    # -- kinematics ---------------------------------------------------------------

    def _frames(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        q = _vector(q, 9, "q")
        u = np.empty((3, 3, 2))
        pts = np.empty((3, 4, 2))
        phi = np.empty(3)
        _native.frames(self.native, q, u, pts, phi)
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
        q = _vector(q, 9, "q")
        tips = self.tip_positions(q)
        jac = np.empty((3, 2, 3))
        for f in range(3):
            _native.point_jacobian(self.native, q, f, tips[f, 0], tips[f, 1], jac[f])
        return jac

    def point_jacobian(self, q: np.ndarray, finger: int, point: np.ndarray) -> np.ndarray:
        """(2, 3): Jacobian of the point of link 3 of ``finger`` now at ``point``."""
        jac = np.empty((2, 3))
        _native.point_jacobian(self.native, _vector(q, 9, "q"), int(finger), float(point[0]), float(point[1]), jac)
        return jac

    # -- dynamics -----------------------------------------------------------------

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """(9, 9): joint-space mass matrix including armature (block-diagonal per finger)."""
        m = np.empty((9, 9))
        _native.mass_matrix(self.native, _vector(q, 9, "q"), m)
        return m

    def bias(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """(9,): Coriolis/centrifugal + gravity + joint damping; tau = M qdd + bias."""
        h = np.empty(9)
        _native.bias(self.native, _vector(q, 9, "q"), _vector(qd, 9, "qd"), h)
        return h

    def static_torques(self, q: np.ndarray, forces: np.ndarray, points: np.ndarray | None = None) -> np.ndarray:
        """(9,): torques holding ``q`` at rest against gravity while fingertip f pushes
        the object with ``forces[f]`` (3, 2) applied at ``points[f]`` (default: tip centres).
        """
        q = _vector(q, 9, "q")
        forces = np.asarray(forces, dtype=float).reshape(3, 2)
        tau = self.bias(q, np.zeros(9))
        points = self.tip_positions(q) if points is None else np.asarray(points, dtype=float).reshape(3, 2)
        for f in range(3):
            tau[3 * f : 3 * f + 3] += self.point_jacobian(q, f, points[f]).T @ forces[f]
        return tau

    # -- object -------------------------------------------------------------------

    def surface_points(self, pose: np.ndarray | None = None) -> np.ndarray:
        """(n_points, 2): the object's surface points, in the object frame or at ``pose``."""
        local = np.empty((self.n_points, 2))
        for row in self.edges:
            k = np.arange(int(row[EDGE.COUNT]))
            s = int(row[EDGE.START])
            local[s : s + k.size, 0] = row[EDGE.OX] + (k * row[EDGE.SPACING]) * row[EDGE.DX]
            local[s : s + k.size, 1] = row[EDGE.OY] + (k * row[EDGE.SPACING]) * row[EDGE.DY]
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
    """``x`` as the float64 vector of width ``n`` that a native call takes."""
    return float_array(x, name, width=n, finite=False, what="argument")
