"""Fingertip trajectories through timed waypoints ``(t, x, y, phi)``.

The manipulation controller is given these beforehand (one per finger), samples them,
turns the samples into joint targets by exact inverse kinematics and tracks them with a
joint PD. Minimum-jerk segments (``s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5``) start and
end at rest, so a finger passes every waypoint with zero velocity and acceleration;
linear segments have constant velocity. ``phi`` is interpolated as given (not wrapped):
write 3.1 -> 3.3 rather than 3.1 -> -2.98.

Sampling is the manipulation controller's law, compiled (``hierhand/csrc/manipulation.c``):
``sample`` and ``velocity`` call the C the ``ManipulationPD`` block runs; this class
checks and holds the waypoints.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from .. import _native
from ..layouts import MANIP_INTERP

__all__ = ["Trajectory"]

INTERPOLATIONS = {name.lower(): code for name, code, _ in MANIP_INTERP.slots}
"""The interpolations by name ("linear", "minjerk"), with their codes in the C's trajectory arrays."""


class Trajectory:
    """Piecewise interpolation of waypoints ``(t, x, y, phi)`` with strictly increasing t.

    Before the first waypoint the trajectory holds it, after the last it holds the last.
    """

    def __init__(self, waypoints: Sequence[Sequence[float]] | np.ndarray, interpolation: str = "minjerk"):
        if interpolation not in INTERPOLATIONS:
            raise ValueError(f"interpolation must be one of {', '.join(INTERPOLATIONS)}, got {interpolation!r}")
        w = np.asarray(waypoints, dtype=float)
        if w.ndim != 2 or w.shape[1] != 4 or w.shape[0] < 1:
            raise ValueError(f"waypoints must be a non-empty list of (t, x, y, phi), got shape {w.shape}")
        if not np.all(np.isfinite(w)):
            bad = int(np.flatnonzero(~np.all(np.isfinite(w), axis=1))[0])
            raise ValueError(f"waypoint {bad} is not finite: {tuple(w[bad])}")
        for i in range(1, w.shape[0]):
            if not w[i, 0] > w[i - 1, 0]:
                raise ValueError(
                    f"waypoint {i}: t = {w[i, 0]:g} is not after waypoint {i - 1}'s t = {w[i - 1, 0]:g} "
                    "(times must be strictly increasing)"
                )
        self.interpolation = interpolation
        self._code = INTERPOLATIONS[interpolation]
        self._w = np.array(w, order="C")  # rows (t, x, y, phi), the C's layout; a copy

    @property
    def times(self) -> np.ndarray:
        """(n,) waypoint times."""
        return self._w[:, 0].copy()

    @property
    def points(self) -> np.ndarray:
        """(n, 3) waypoint poses ``(x, y, phi)``."""
        return self._w[:, 1:].copy()

    @property
    def duration(self) -> float:
        """Time from the first to the last waypoint."""
        return float(self._w[-1, 0] - self._w[0, 0])

    def sample(self, t: float) -> np.ndarray:
        """(3,) pose ``(x, y, phi)`` at time ``t``."""
        pose = np.empty(3)
        _native.trajectory_sample(self._w, self._code, float(t), pose)
        return pose

    def velocity(self, t: float) -> np.ndarray:
        """(3,) analytic time derivative of ``sample``.

        Right-continuous: at a waypoint time it is the velocity of the segment starting
        there; zero before the first waypoint and from the last one on (held). Linear
        interpolation jumps at waypoints; minimum jerk is continuous (zero there).
        """
        velocity = np.empty(3)
        _native.trajectory_velocity(self._w, self._code, float(t), velocity)
        return velocity

    def __repr__(self) -> str:
        t = self._w[:, 0]
        return f"Trajectory({t.size} waypoints, {self.interpolation}, t in [{t[0]:g}, {t[-1]:g}])"

    @classmethod
    def from_config(cls, config: Any) -> "Trajectory":
        """From ``{"waypoints": [[t, x, y, phi], ...], "interpolation": ...}`` or a bare list."""
        if isinstance(config, dict):
            unknown = set(config) - {"waypoints", "interpolation"}
            if unknown:
                raise ValueError(f"unknown trajectory keys: {', '.join(sorted(unknown))} (allowed: waypoints, interpolation)")
            if "waypoints" not in config:
                raise ValueError("a trajectory needs waypoints")
            return cls(config["waypoints"], config.get("interpolation", "minjerk"))
        return cls(config)
