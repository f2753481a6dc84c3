"""The penalty contact law: action = reaction, the friction cone, stick and slip, release."""

import numpy as np
import pytest

from .sim import DT, make_plant, pinch_torques, run


def cross(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


@pytest.fixture(scope="module")
def pinched():
    """Thumb and fore squeezing the object under gravity, 60 ms after closing."""
    plant = make_plant()
    mg2 = plant.hand.params.object.mass * 9.81 / 2
    state, logs, _ = run(plant, plant.initial_state(), 0.06, lambda t: pinch_torques(plant.hand, 2.5, mg2), kp=0.3, kd=0.003)
    assert logs["contact"][-1].tolist() == [1.0, 1.0, 0.0]
    return plant, state


def test_forces_on_object_and_fingertips_are_equal_and_opposite(pinched):
    plant, state = pinched
    cw = plant.contact_wrenches(state)
    assert np.all(cw.fn[:2] > 1.0)
    assert np.array_equal(cw.on_finger, -cw.on_object)
    # same lines of action: the moments about the object's centre cancel as well
    o = plant.views(state).obj[:2]
    finger_about_o = cw.finger_moment + cross(cw.tip[:, :2] - o, cw.on_finger)
    assert np.allclose(cw.object_moment + finger_about_o, 0.0, atol=1e-12)


def test_reported_contact_forces_are_the_ones_that_accelerate_both_bodies(pinched):
    plant, state = pinched
    hand = plant.hand
    state = state.copy()
    views = plant.views(state)
    q, qd, v = views.q.copy(), views.qd.copy(), views.obj_vel.copy()
    cw = plant.contact_wrenches(state)
    tau = pinch_torques(hand, 2.5, 1.0)
    f_ext = np.array([0.1, -0.2, 1e-3])
    plant.update(0.0, state, {"tau": tau, "f_ext": f_ext})
    obj = hand.params.object
    # object: m dv/dt = sum of contact forces + weight + f_ext
    force = cw.on_object.sum(axis=0) + obj.mass * hand.gravity + f_ext[:2]
    assert np.allclose(obj.mass * (views.obj_vel[:2] - v[:2]) / DT, force, rtol=1e-9, atol=1e-9)
    torque = cw.object_moment.sum() + f_ext[2]
    assert obj.inertia * (views.obj_vel[2] - v[2]) / DT == pytest.approx(torque, rel=1e-9, abs=1e-12)
    # fingers: M qdd + h - tau = J^T (force on the tip) + (moment about the tip centre)
    jac = hand.tip_jacobians(q)
    generalized = np.concatenate([jac[f].T @ cw.on_finger[f] + cw.finger_moment[f] for f in range(3)])
    lhs = hand.mass_matrix(q) @ (views.qd - qd) / DT + hand.bias(q, qd) - tau
    assert np.allclose(lhs, generalized, rtol=1e-7, atol=1e-9)


def test_friction_cone_holds_at_every_step_and_sliding_uses_mu_d():
    """A squeeze too weak for the weight: the object slides down through the fingers."""
    plant = make_plant()
    c = plant.hand.params.contact
    mg2 = plant.hand.params.object.mass * 9.81 / 2
    _, logs, _ = run(plant, plant.initial_state(), 0.08, lambda t: pinch_torques(plant.hand, 1.0, mg2), kp=0.3, kd=0.003)
    ratio, fn, ft = logs["ratio"], logs["fn"], logs["ft"]
    assert np.all(fn >= 0.0)
    assert np.all(np.abs(ft) <= c.mu_s * fn + 1e-12)
    assert np.all(ratio <= c.mu_s + 1e-12)
    sliding = (logs["obj_vel"][:, 1] < -0.05) & (fn[:, 0] > 0.1) & (fn[:, 1] > 0.1)
    assert sliding.sum() > 100
    assert np.allclose(ratio[sliding][:, :2], c.mu_d, atol=1e-9)


@pytest.mark.parametrize("fraction, slips", [(0.85, False), (1.15, True)])
def test_tangential_load_above_mu_s_fn_slips_and_below_sticks(fraction, slips):
    """No gravity; after the squeeze settles, a vertical force on the object is ramped in.

    The fingers' torques include their share of it, so a sticking grasp stays in static
    equilibrium; whether it sticks is decided by friction alone.
    """
    plant = make_plant(gravity=[0.0, 0.0])
    hand = plant.hand
    squeeze = 2.0
    state, logs, _ = run(plant, plant.initial_state(), 0.05, lambda t: pinch_torques(hand, squeeze, 0.0), kp=0.3, kd=0.003)
    capacity = hand.params.contact.mu_s * logs["fn"][-1, :2].sum()
    assert capacity == pytest.approx(2 * squeeze, rel=0.05)
    load = fraction * capacity
    ramp = lambda t: min(t / 0.05, 1.0) * load  # noqa: E731
    state, logs, t = run(
        plant, state, 0.25,
        lambda t: pinch_torques(hand, squeeze, -ramp(t) / 2),
        f_ext=lambda t: [0.0, ramp(t), 0.0],
        kp=0.3, kd=0.003,
    )
    y = logs["obj"][:, 1]
    after_ramp = t > 0.06
    moved = y[after_ramp].max() - y[after_ramp].min()
    if slips:
        assert moved > 5e-3
        assert logs["obj_vel"][-1, 1] > 0.05
    else:
        assert moved < 0.3e-3  # elastic settling of the springs only
        assert abs(logs["obj_vel"][-1, 1]) < 1e-3
        assert np.all(logs["ratio"][after_ramp, :2] < hand.params.contact.mu_s)


def test_anchors_are_released_when_the_fingers_open(pinched):
    plant, state = pinched
    state = state.copy()
    views = plant.views(state)
    assert views.touching.sum() > 4
    hand = plant.hand
    opening = pinch_torques(hand, -3.0, 0.0)
    state, rows = plant.advance(0.0, state, {"tau": opening}, 300)
    assert rows["contact"][-1].tolist() == [0.0, 0.0, 0.0]
    assert np.all(rows["fn"] >= 0.0)  # no adhesion while pulling away
    assert views.touching.sum() == 0
