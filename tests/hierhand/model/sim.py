"""Helpers for driving the plant block directly in tests (no executor)."""

from __future__ import annotations

import numpy as np

from hierhand.model import Hand, HandPlant

DT = 1e-4
CONTROL_PERIOD = 1e-3  # the grasp reflex's rate: torques are held for 10 plant steps


def make_plant(**params) -> HandPlant:
    plant = HandPlant(**params)
    plant.bind(DT)
    return plant


def pinch_points(hand: Hand, q: np.ndarray) -> np.ndarray:
    """(3, 2): where thumb and fore touch the object's left and right faces at ``q``."""
    c = hand.tip_positions(q)
    r = hand.tip_radius
    return np.array([c[0] + [r[0], 0.0], c[1] - [r[1], 0.0], c[2]])


def pinch_torques(hand: Hand, squeeze: float, load: float, q=None) -> np.ndarray:
    """Constant torques: gravity compensation of the fingers at ``q`` (default q0), plus
    J^T of an inward ``squeeze`` on thumb and fore and an upward ``load`` on each.

    ``load`` is each finger's share of the vertical force the object needs; with it the
    pinch is in static equilibrium at q0 if friction can carry it.
    """
    q = hand.q0 if q is None else q
    forces = np.array([[squeeze, load], [-squeeze, load], [0.0, 0.0]])
    return hand.static_torques(q, forces, pinch_points(hand, q))


def run(plant, state, t_end, torques, f_ext=None, kp=0.0, kd=0.0):
    """Simulate ``t_end`` seconds; torques(t) and f_ext(t) are held for 1 ms each.

    An optional joint PD about q0 (gains kp, kd) holds the finger posture, as the
    manipulation controller would; the zero-stiffness drift of purely torque-controlled
    fingers otherwise dominates long holds. Returns (state, dict of (n, w) logs, times).
    """
    hand = plant.hand
    views = plant.views(state)
    n_sub = int(round(CONTROL_PERIOD / DT))
    logs: dict[str, list[np.ndarray]] = {}
    n_ctrl = int(round(t_end / CONTROL_PERIOD))
    for k in range(n_ctrl):
        t = k * CONTROL_PERIOD
        tau = torques(t) + kp * (hand.q0 - views.q) - kd * views.qd
        inputs = {"tau": tau}
        if f_ext is not None:
            inputs["f_ext"] = np.asarray(f_ext(t), dtype=float)
        state, rows = plant.advance(t, state, inputs, n_sub)
        for port, values in rows.items():
            logs.setdefault(port, []).append(values)
    times = DT * np.arange(1, n_ctrl * n_sub + 1)
    return state, {p: np.concatenate(v) for p, v in logs.items()}, times
