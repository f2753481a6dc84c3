"""The controller blocks on their own: reflex forces, PD tracking, suppresser modes."""

from __future__ import annotations

import numpy as np
import pytest

from blocks import Block
from hierhand.control.grasp_reflex import GraspReflex
from hierhand.control.manipulation_pd import ManipulationPD
from hierhand.control.suppresser import Suppresser
from hierhand.model import Hand


def cross(r, f) -> float:
    return float(r[0] * f[1] - r[1] * f[0])


def reflex_inputs(hand, fn, ft=(0.0, 0.0, 0.0), normals=((1, 0), (-1, 0), (0, 0))):
    q = hand.q0
    tips = hand.tip_poses(q)
    return {"q": q, "tip": tips.ravel(), "fn": np.array(fn, float), "ft": np.array(ft, float),
            "normal": np.array(normals, float).ravel()}


def make_reflex(**params):
    reflex = GraspReflex(hand=Hand.default(), **params)
    reflex.bind(0.001)
    return reflex


def test_reflex_forces_are_internal_and_map_through_the_jacobian():
    reflex = make_reflex()
    hand = reflex.hand
    state = reflex.initial_state()
    state[0] = 2.5
    inputs = reflex_inputs(hand, fn=[2.0, 2.0, 0.0])
    f, grasp = reflex.forces(state, inputs)
    assert grasp.tolist() == [True, True, False]
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-12)  # no net force on the object
    tips = hand.tip_positions(hand.q0)
    moment = sum(cross(tips[i] - tips.mean(axis=0), f[i]) for i in range(3))
    assert abs(moment) < 1e-12
    assert f[0, 0] > 0 and f[1, 0] < 0  # thumb pushes right, forefinger left: a squeeze
    out = reflex.output(0.0, state, inputs)
    jac = hand.tip_jacobians(hand.q0)
    expected = np.concatenate([jac[i].T @ f[i] for i in range(3)])
    np.testing.assert_allclose(out["tau_g"], expected, rtol=1e-12)


def test_reflex_three_contacts_push_along_the_normals_as_far_as_equilibrium_allows():
    reflex = make_reflex(grasp=["thumb", "fore", "middle"])
    hand = reflex.hand
    q = hand.q0
    inputs = reflex_inputs(hand, fn=[2.0, 2.0, 2.0], normals=((1, 0), (-1, 0), (-1, 0)))
    state = reflex.initial_state()
    state[0] = 1.0
    f, _ = reflex.forces(state, inputs)
    tips = hand.tip_positions(q)
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-12)
    assert abs(sum(cross(tips[i], f[i]) for i in range(3))) < 1e-12
    normals = inputs["normal"].reshape(3, 2)
    assert np.all(np.einsum("ij,ij->i", f, normals) > 0)  # every finger pushes into the object


@pytest.mark.parametrize("ft", [0.0, 1.0, 3.0])
def test_reflex_integrates_towards_the_force_the_friction_ratio_needs(ft):
    """With the measured normal force standing still, the scale moves at ki * shortfall."""
    reflex = make_reflex(ki=50.0, min_force=1.0, margin=0.05, safety_ratio=0.6)
    state = reflex.initial_state()
    state[0] = 2.0
    inputs = reflex_inputs(reflex.hand, fn=[2.0, 2.0, 0.0], ft=[ft, -ft, 0.0])
    new = reflex.update(0.0, state, inputs)
    need = max(1.0, ft / (0.6 / 1.05))
    assert new[0] == pytest.approx(2.0 + 50.0 * 0.001 * (need - 2.0), rel=1e-9)


def test_reflex_follows_the_contacts_and_lets_a_finger_go():
    reflex = make_reflex()
    state = reflex.initial_state()
    # before any contact the grasp fingers approach each other
    f, grasp = reflex.forces(state, reflex_inputs(reflex.hand, fn=[0, 0, 0]))
    assert grasp.tolist() == [True, True, False]
    assert np.linalg.norm(f[0]) == pytest.approx(reflex.approach_force)
    state = reflex.update(0.0, state, reflex_inputs(reflex.hand, fn=[1, 1, 0]))
    assert state[1:].tolist() == [0.0, 0.0, 0.0]  # both held by the reflex
    # a finger that bounces off while the reflex holds it is pushed back
    _, grasp = reflex.forces(state, reflex_inputs(reflex.hand, fn=[1, 0, 0]))
    assert grasp.tolist() == [True, True, False]
    # voluntary motion takes the forefinger over (its command keeps a third of its grasp torque) ...
    taken = dict(reflex_inputs(reflex.hand, fn=[1, 1, 1]), share=np.array([1.0, 0.3, 1.0]))
    handed_at = state[0]
    state = reflex.update(0.0, state, taken)
    assert state[1:].tolist() == [0.0, handed_at, 0.0]
    # ... keeps at most the squeeze it had then while the others' squeeze rises ...
    state[0] = 3 * handed_at
    f, _ = reflex.forces(state, reflex_inputs(reflex.hand, fn=[1, 1, 1], normals=((1, 0), (-1, 0), (-1, 0))))
    g, _, _ = reflex.directions(state, *(reflex_inputs(reflex.hand, fn=[1, 1, 1], normals=(
        (1, 0), (-1, 0), (-1, 0)))[k] for k in ("tip", "normal", "fn")))
    np.testing.assert_allclose(f[1], handed_at * g[1], rtol=1e-12)
    np.testing.assert_allclose(f[0], 3 * handed_at * g[0], rtol=1e-12)
    # ... so once it has let go it is no longer pushed back
    _, grasp = reflex.forces(state, reflex_inputs(reflex.hand, fn=[1, 0, 1], normals=((1, 0), (0, 0), (-1, 0))))
    assert grasp.tolist() == [True, False, True]


def test_a_finger_handed_to_voluntary_motion_does_not_drive_the_squeeze():
    """The forefinger's friction need would raise the scale; once its share of the grasp
    torque is below release_share only the thumb's need counts (the anti-windup)."""
    reflex = make_reflex(ki=50.0, min_force=1.0, release_share=0.8)
    state = reflex.initial_state()
    state[0] = 2.0
    inputs = reflex_inputs(reflex.hand, fn=[2.0, 2.0, 2.0], ft=[0.0, 3.0, 0.0])
    held = reflex.update(0.0, state, dict(inputs, share=np.ones(3)))
    taken = reflex.update(0.0, state, dict(inputs, share=np.array([1.0, 0.79, 1.0])))
    assert held[0] > 2.0 > taken[0]


def test_a_pinch_keeps_both_fingers_whatever_their_share():
    """Two fingers are the grasp: a posture PD that resists the squeeze lowers both shares,
    but handing either over would leave the reflex nothing to hold the object with."""
    reflex = make_reflex(ki=50.0, min_force=3.0, release_share=0.8)
    state = reflex.initial_state()
    state[0] = 2.0
    inputs = reflex_inputs(reflex.hand, fn=[1.0, 1.5, 0.0], ft=[0.5, -0.5, 0.0])
    low = reflex.update(0.0, state, dict(inputs, share=np.array([0.5, 0.6, 1.0])))
    whole = reflex.update(0.0, state, dict(inputs, share=np.ones(3)))
    assert low[0] > 2.0  # the squeeze still rises towards min_force
    np.testing.assert_array_equal(low, whole)


def test_reflex_rejects_unknown_fingers():
    with pytest.raises(ValueError, match="unknown finger"):
        GraspReflex(hand=Hand.default(), grasp=["thumb", "pinky"])


def test_manipulation_pd_tracks_its_trajectory_with_gravity_feedforward():
    hand = Hand.default()
    tips = hand.tip_poses(hand.q0)
    goal = tips[1] + [0.004, 0.0, -0.1]
    pd = ManipulationPD(hand=hand, kp=1.0, kd=0.0, load_compensation=False,
                        trajectories={"fore": {"waypoints": [[0.0, *tips[1]], [0.1, *goal]]}})
    pd.bind(0.01)
    inputs = {"q": hand.q0, "qd": np.zeros(9), "fn": np.zeros(3)}
    start = pd.output(0.0, None, inputs)
    np.testing.assert_allclose(start["tau_m"], 0.0, atol=1e-9)
    np.testing.assert_allclose(start["tau_ff"], hand.bias(hand.q0, np.zeros(9)), rtol=1e-12)
    end = pd.output(0.2, None, inputs)
    q_ref = end["q_ref"]
    np.testing.assert_allclose(hand.tip_poses(q_ref)[1], goal, atol=1e-9)
    np.testing.assert_allclose(end["tau_m"], q_ref - hand.q0, atol=1e-12)  # kp = 1


def test_manipulation_pd_shares_the_object_weight_among_touching_fingers():
    hand = Hand.default()
    pd = ManipulationPD(hand=hand, gravity_compensation=False)
    out = pd.output(0.0, None, {"q": hand.q0, "qd": np.zeros(9), "fn": np.array([2.0, 2.0, 0.0])})
    jac = hand.tip_jacobians(hand.q0)
    lift = -hand.params.object.mass * hand.gravity / 2
    np.testing.assert_allclose(out["tau_ff"][:3], jac[0].T @ lift, rtol=1e-12)
    np.testing.assert_allclose(out["tau_ff"][6:], 0.0)


def test_manipulation_pd_carries_only_what_the_support_does_not():
    hand = Hand.default()
    pd = ManipulationPD(hand=hand, gravity_compensation=False)
    weight = hand.params.object.mass * hand.gravity
    inputs = {"q": hand.q0, "qd": np.zeros(9), "fn": np.array([2.0, 2.0, 0.0])}
    carried = pd.output(0.0, None, dict(inputs, support=np.array([-weight[0], -weight[1], 0.0])))
    np.testing.assert_allclose(carried["tau_ff"], 0.0, atol=1e-15)
    half = pd.output(0.0, None, dict(inputs, support=np.array([0.0, -weight[1] / 2, 0.0])))
    full = pd.output(0.0, None, inputs)
    np.testing.assert_allclose(half["tau_ff"], full["tau_ff"] / 2, rtol=1e-12, atol=1e-15)


def test_manipulation_pd_rejects_an_unreachable_waypoint_naming_finger_and_time():
    with pytest.raises(ValueError, match=r"finger 'fore': the waypoint at t = 0.5 s .* unreachable"):
        ManipulationPD(hand=Hand.default(),
                       trajectories={"fore": {"waypoints": [[0.0, 0.033, 0.06, 3.0], [0.5, 0.2, 0.2, 0.0]]}})


@pytest.mark.parametrize("mode", ["magnitude", "signed"])
def test_suppresser_modes_and_limits(mode):
    s = Suppresser(S_a=200.0, S_b=0.1, mode=mode)
    tau_g = np.full(9, 0.3)
    quiet = s.output(0, None, {"tau_g": tau_g, "tau_m": np.zeros(9)})
    np.testing.assert_allclose(quiet["tau_g_eff"], tau_g / (1 + np.exp(-20.0)), rtol=1e-12)
    big = np.full(9, 0.5)
    pushed = s.output(0, None, {"tau_g": tau_g, "tau_m": big})
    np.testing.assert_allclose(pushed["tau_g_eff"], 0.0, atol=1e-30)
    np.testing.assert_allclose(pushed["tau"], big, atol=1e-30)
    pulled = s.output(0, None, {"tau_g": tau_g, "tau_m": -big})["tau_g_eff"]
    if mode == "magnitude":
        np.testing.assert_allclose(pulled, 0.0, atol=1e-30)
    else:
        np.testing.assert_allclose(pulled, tau_g, rtol=1e-12)


def test_disabled_suppresser_passes_the_grasp_torque_through():
    s = Suppresser(enabled=False)
    assert isinstance(s, Block)
    out = s.output(0, None, {"tau_g": np.arange(9.0), "tau_m": np.ones(9)})
    np.testing.assert_array_equal(out["tau_g_eff"], np.arange(9.0))
    np.testing.assert_array_equal(out["tau"], np.arange(9.0) + 1)


def test_suppresser_adds_the_feedforward_unsuppressed():
    s = Suppresser(S_a=200.0, S_b=0.1)
    tau_ff = np.linspace(-0.2, 0.2, 9)
    big = np.full(9, 0.5)
    out = s.output(0, None, {"tau_g": np.full(9, 0.3), "tau_m": big, "tau_ff": tau_ff})
    np.testing.assert_allclose(out["tau"], big + tau_ff, atol=1e-30)
    assert s.input_defaults["tau_ff"].tolist() == [0.0] * 9


@pytest.mark.parametrize("make, message", [
    (lambda: ManipulationPD(hand=Hand.default(), kp=[1.0, 2.0]), "parameter 'kp' must have width 9 (or be a scalar)"),
    (lambda: ManipulationPD(hand=Hand.default(), kd=float("nan")), "parameter 'kd' must be finite"),
    (lambda: ManipulationPD(hand=Hand.default(), kp=-1.0), "kp and kd must be non-negative"),
    (lambda: Suppresser(S_b="soft"), "parameter 'S_b' must be numeric"),
    (lambda: Suppresser(S_a=[1.0] * 8), "parameter 'S_a' must have width 9 (or be a scalar)"),
])
def test_per_joint_gains_are_a_scalar_or_nine_finite_values(make, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        make()
    assert np.array_equal(Suppresser(S_a=3.0).S_a, np.full(9, 3.0))
    assert np.array_equal(ManipulationPD(hand=Hand.default(), kd=list(range(9))).kd, np.arange(9.0))
