"""The free object: ballistic flight and response to the external wrench input."""

import numpy as np
import pytest

from .sim import DT, make_plant


def fly(plant, state, t_end, f_ext=None):
    inputs = {"tau": plant.hand.static_torques(plant.hand.q0, np.zeros((3, 2)))}
    if f_ext is not None:
        inputs["f_ext"] = np.asarray(f_ext, dtype=float)
    n = int(round(t_end / DT))
    state, rows = plant.advance(0.0, state, inputs, n)
    assert not rows["contact"].any()
    return state, rows, DT * np.arange(1, n + 1)


def test_free_fall_follows_the_parabola():
    plant = make_plant(object={"pos": [0.0, 0.3], "angle": 0.2})
    state = plant.initial_state()
    views = plant.views(state)
    v0 = np.array([0.2, 0.5, 3.0])
    views.obj_vel[:] = v0
    _, rows, t = fly(plant, state, 0.2)
    g = 9.81
    x = 0.0 + v0[0] * t
    y = 0.3 + v0[1] * t - 0.5 * g * t**2
    theta = 0.2 + v0[2] * t
    assert np.allclose(rows["obj"][:, 0], x, rtol=0, atol=1e-12)
    assert np.allclose(rows["obj"][:, 2], theta, rtol=0, atol=1e-12)
    # semi-implicit Euler lags the parabola by g dt t / 2: first order in dt, no drift
    err = np.abs(rows["obj"][:, 1] - y)
    assert np.all(err <= 0.5 * g * DT * t * (1 + 1e-9) + 1e-12)
    assert err[-1] < 1e-4
    assert np.allclose(rows["obj_vel"][:, 1], v0[1] - g * t, rtol=0, atol=1e-12)


def test_external_force_and_torque_accelerate_the_object():
    plant = make_plant(gravity=[0.0, 0.0], object={"pos": [0.0, 0.3]})
    obj = plant.hand.params.object
    f_ext = np.array([0.6, -0.3, 2e-4])
    _, rows, t = fly(plant, plant.initial_state(), 0.1, f_ext)
    acc = f_ext / np.array([obj.mass, obj.mass, obj.inertia])
    assert np.allclose(rows["obj_vel"], np.outer(t, acc), rtol=1e-12, atol=1e-15)
    expected = np.array([0.0, 0.3, 0.0]) + 0.5 * np.outer(t**2, acc)
    assert np.allclose(rows["obj"], expected, rtol=0, atol=np.abs(acc).max() * DT * t[-1])
    assert rows["obj"][-1, 2] == pytest.approx(0.5 * acc[2] * t[-1] ** 2, rel=2 * DT / t[-1])
