"""Fingertip trajectories through timed waypoints ``(t, x, y, phi)``.

The manipulation controller is given these beforehand (one per finger), samples them,
turns the samples into joint targets by exact inverse kinematics and tracks them with a
joint PD. Minimum-jerk segments start and end at rest, so a finger passes every
waypoint with zero velocity and acceleration; linear segments have constant velocity.
``phi`` is interpolated as given (not wrapped): write 3.1 -> 3.3 rather than 3.1 -> -2.98.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

__all__ = ["Trajectory", "minjerk", "minjerk_rate"]

INTERPOLATIONS = ("linear", "minjerk")


def minjerk(tau: float) -> float:
    """Minimum-jerk blend ``s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5`` on [0, 1]."""
    return tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau))


def minjerk_rate(tau: float) -> float:
    """``ds/dtau = 30 tau^2 (1 - tau)^2``."""
    return 30.0 * tau * tau * (1.0 - tau) ** 2


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
        self._t = w[:, 0].copy()
        self._p = w[:, 1:].copy()

    @property
    def times(self) -> np.ndarray:
        """(n,) waypoint times."""
        return self._t.copy()

    @property
    def points(self) -> np.ndarray:
        """(n, 3) waypoint poses ``(x, y, phi)``."""
        return self._p.copy()

    @property
    def duration(self) -> float:
        """Time from the first to the last waypoint."""
        return float(self._t[-1] - self._t[0])

    def _segment(self, t: float) -> tuple[int, float, float]:
        """Segment index, its normalised time tau in [0, 1] and its length."""
        i = int(np.searchsorted(self._t, t, side="right")) - 1
        i = min(max(i, 0), self._t.size - 2)
        span = self._t[i + 1] - self._t[i]
        return i, (t - self._t[i]) / span, span

    def sample(self, t: float) -> np.ndarray:
        """(3,) pose ``(x, y, phi)`` at time ``t``."""
        t = float(t)
        if t <= self._t[0]:
            return self._p[0].copy()
        if t >= self._t[-1]:
            return self._p[-1].copy()
        i, tau, _ = self._segment(t)
        s = minjerk(tau) if self.interpolation == "minjerk" else tau
        return self._p[i] + s * (self._p[i + 1] - self._p[i])

    def velocity(self, t: float) -> np.ndarray:
        """(3,) analytic time derivative of ``sample``.

        Right-continuous: at a waypoint time it is the velocity of the segment starting
        there; zero before the first waypoint and from the last one on (held). Linear
        interpolation jumps at waypoints; minimum jerk is continuous (zero there).
        """
        t = float(t)
        if t < self._t[0] or t >= self._t[-1]:
            return np.zeros(3)
        i, tau, span = self._segment(t)
        rate = minjerk_rate(tau) if self.interpolation == "minjerk" else 1.0
        return (rate / span) * (self._p[i + 1] - self._p[i])

    def __repr__(self) -> str:
        return f"Trajectory({self._t.size} waypoints, {self.interpolation}, t in [{self._t[0]:g}, {self._t[-1]:g}])"

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
