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


def contact_points(hand, inputs) -> np.ndarray:
    """(3, 2): tip centre plus tip radius along the contact normal."""
    return inputs["tip"].reshape(3, 3)[:, :2] + hand.tip_radius[:, None] * inputs["normal"].reshape(3, 2)


def test_reflex_forces_are_internal_and_map_through_the_jacobian():
    reflex = make_reflex()
    hand = reflex.hand
    state = reflex.initial_state()
    state[0] = 2.5
    inputs = reflex_inputs(hand, fn=[2.0, 2.0, 0.0])
    f, grasp = reflex.forces(state, inputs)
    assert grasp.tolist() == [True, True, False]
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-12)  # no net force on the object
    points = contact_points(hand, inputs)
    moment = sum(cross(points[i] - points.mean(axis=0), f[i]) for i in range(3))
    assert abs(moment) < 1e-12  # nor a moment: the squeeze acts between the contact points
    assert f[0, 0] > 0 and f[1, 0] < 0  # thumb pushes right, forefinger left: a squeeze
    out = reflex.output(0.0, state, inputs)
    expected = np.concatenate([hand.point_jacobian(hand.q0, i, points[i]).T @ f[i] for i in range(3)])
    np.testing.assert_allclose(out["tau_g"], expected, rtol=1e-12, atol=1e-15)


def test_reflex_three_contacts_push_along_the_normals_as_far_as_equilibrium_allows():
    reflex = make_reflex(grasp=["thumb", "fore", "middle"])
    hand = reflex.hand
    inputs = reflex_inputs(hand, fn=[2.0, 2.0, 2.0], normals=((1, 0), (-1, 0), (-1, 0)))
    state = reflex.initial_state()
    state[0] = 1.0
    f, _ = reflex.forces(state, inputs)
    points = contact_points(hand, inputs)
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-12)
    assert abs(sum(cross(points[i], f[i]) for i in range(3))) < 1e-12
    normals = inputs["normal"].reshape(3, 2)
    assert np.all(np.einsum("ij,ij->i", f, normals) > 0)  # every finger pushes into the object


def test_an_approaching_finger_does_not_unbalance_the_squeeze_of_those_touching():
    """A finger still approaching does not touch the object, so the two touching fingers'
    forces must balance each other alone; the third pushes toward them."""
    reflex = make_reflex(grasp=["thumb", "fore", "middle"])
    state = reflex.initial_state()
    state[0] = 2.0
    inputs = reflex_inputs(reflex.hand, fn=[2.0, 2.0, 0.0], normals=((1, 0), (-1, 0), (0, 0)))
    f, grasp = reflex.forces(state, inputs)
    assert grasp.tolist() == [True, True, True]
    np.testing.assert_allclose(f[0] + f[1], 0.0, atol=1e-12)
    assert np.linalg.norm(f[2]) == pytest.approx(reflex.approach_force)
    tips = inputs["tip"].reshape(3, 3)[:, :2]
    assert np.dot(f[2], tips[:2].mean(axis=0) - tips[2]) > 0


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


def three_touching(hand, **ports):
    return dict(reflex_inputs(hand, fn=[2.0, 2.0, 2.0], normals=((1, 0), (-1, 0), (-1, 0))), **ports)


def test_the_reflex_holds_two_fingers_whole_and_a_third_as_far_as_the_suppresser_spares_it():
    reflex = make_reflex(grasp=["thumb", "fore", "middle"], release_share=0.5, hold_share=0.9)
    state = reflex.initial_state()
    state[0] = 2.0
    for share, hold in (([1.0, 1.0, 1.0], 1.0), ([0.97, 0.95, 0.96], 1.0), ([0.9, 0.7, 0.95], 0.5),
                        ([1.0, 0.2, 1.0], 0.0)):
        new = reflex.update(0.0, state, three_touching(reflex.hand, share=np.array(share)))
        np.testing.assert_allclose(new[4:7], [1.0, hold, 1.0], rtol=1e-12)
    # the two the suppresser spares most are held whole, whichever they are
    new = reflex.update(0.0, state, three_touching(reflex.hand, share=np.array([0.6, 0.9, 0.8])))
    np.testing.assert_allclose(new[4:7], [0.25, 1.0, 1.0], rtol=1e-12)
    # the paper's reflex knows nothing of the suppresser
    paper = make_reflex(grasp=["thumb", "fore", "middle"], follow_suppression=False)
    new = paper.update(0.0, paper.initial_state(), three_touching(paper.hand, share=np.array([1.0, 0.0, 1.0])))
    assert new[4:7].tolist() == [1.0, 1.0, 1.0]


def test_a_finger_held_in_part_shares_the_squeeze_in_part():
    """With the forefinger's hold h, the squeeze is h times that of all three plus (1 - h)
    times that of thumb and middle finger: at h = 0 the forefinger is squeezed no more."""
    reflex = make_reflex(grasp=["thumb", "fore", "middle"])
    inputs = three_touching(reflex.hand)
    directions = {}
    for hold in (1.0, 0.5, 0.0):
        state = reflex.initial_state()
        state[5] = hold
        directions[hold] = reflex.directions(state, inputs["tip"], inputs["normal"], inputs["fn"])[0]
    np.testing.assert_allclose(directions[0.0][1], 0.0, atol=1e-15)
    assert np.linalg.norm(directions[1.0][1]) > 0.1
    np.testing.assert_allclose(directions[0.5], (directions[1.0] + directions[0.0]) / 2, atol=1e-15)


def test_a_finger_being_handed_over_drives_the_squeeze_only_as_far_as_it_is_held():
    """The forefinger's friction need would raise the scale; as the suppresser takes it
    over its need counts less, and not at all at release_share (the anti-windup)."""
    reflex = make_reflex(ki=50.0, min_force=1.0, release_share=0.5, grasp=["thumb", "fore", "middle"])
    state = reflex.initial_state()
    state[0] = 2.0
    inputs = three_touching(reflex.hand, ft=np.array([0.0, 3.0, 0.0]))
    steps = [reflex.update(0.0, state, dict(inputs, share=np.array([1.0, s, 1.0])))[0] - 2.0
             for s in (0.95, 0.8, 0.6, 0.5)]
    assert steps[0] > steps[1] > steps[2] > 0 > steps[3]


def test_a_finger_that_bounces_off_is_pushed_back_and_one_let_go_of_is_not():
    reflex = make_reflex(grasp=["thumb", "fore", "middle"])
    state = reflex.initial_state()
    # before any contact the grasp fingers approach each other
    f, grasp = reflex.forces(state, reflex_inputs(reflex.hand, fn=[0, 0, 0]))
    assert grasp.tolist() == [True, True, True]
    assert np.linalg.norm(f[0]) == pytest.approx(reflex.approach_force)
    held = reflex.update(0.0, state, three_touching(reflex.hand))
    assert held[1:4].tolist() == [0.0, 0.0, 0.0]  # held whole, all three
    _, grasp = reflex.forces(held, reflex_inputs(reflex.hand, fn=[2, 0, 2], normals=((1, 0), (0, 0), (-1, 0))))
    assert grasp.tolist() == [True, True, True]  # the forefinger bounced off: pushed back
    letting_go = reflex.update(0.0, state, three_touching(reflex.hand, share=np.array([1.0, 0.85, 1.0])))
    assert letting_go[1:4].tolist() == [0.0, 1.0, 0.0]
    _, grasp = reflex.forces(letting_go, reflex_inputs(reflex.hand, fn=[2, 0, 2], normals=((1, 0), (0, 0), (-1, 0))))
    assert grasp.tolist() == [True, False, True]  # it left while the reflex let it go: left alone


def test_a_pinch_keeps_both_fingers_whatever_their_share():
    """Two fingers are the grasp: whatever the suppresser takes from them, the reflex holds
    both whole and makes up with squeeze what it takes."""
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


def pd_inputs(hand, **ports) -> dict:
    return {"q": hand.q0, "qd": np.zeros(9), "fn": np.zeros(3), "normal": np.zeros(6), "obj": hand.object_pose0,
            **ports}


def bound(pd: ManipulationPD) -> ManipulationPD:
    pd.bind(0.01)
    return pd


def test_manipulation_pd_tracks_its_trajectory_with_gravity_feedforward():
    hand = Hand.default()
    tips = hand.tip_poses(hand.q0)
    goal = tips[1] + [0.004, 0.0, -0.1]
    pd = bound(ManipulationPD(hand=hand, kp=1.0, kd=0.0, load_compensation=False, discretization="held",
                              trajectories={"fore": {"waypoints": [[0.0, *tips[1]], [0.1, *goal]]}}))
    start = pd.output(0.0, None, pd_inputs(hand))
    np.testing.assert_allclose(start["tau_m"], 0.0, atol=1e-9)
    np.testing.assert_allclose(start["tau_ff"], hand.bias(hand.q0, np.zeros(9)), rtol=1e-12)
    end = pd.output(0.2, None, pd_inputs(hand))
    q_ref = end["q_ref"]
    np.testing.assert_allclose(hand.tip_poses(q_ref)[1], goal, atol=1e-9)
    np.testing.assert_allclose(end["tau_m"], q_ref - hand.q0, atol=1e-12)  # kp = 1, held as it is


def free_finger_error(plant, pd, hand, offset: float, steps: int) -> list[float]:
    """The largest joint error of a free forefinger started ``offset`` rad off its target at
    every joint, after each 10 ms PD step (100 plant steps each); ends early, with inf, if
    the plant blows up."""
    from blocks import BlockError

    state = plant.initial_state()
    plant.views(state).q[3:6] += offset
    errors = []
    for k in range(steps):
        out = plant.output(0.0, state, {"tau": np.zeros(9), "f_ext": np.zeros(3)})
        tau = pd.output(0.01 * k, None, pd_inputs(hand, q=out["q"], qd=out["qd"]))["tau_m"]
        try:
            state, _ = plant.advance(0.0, state, {"tau": tau, "f_ext": np.zeros(3)}, 100)
        except BlockError:  # non-finite: diverged
            return errors + [float("inf")]
        q = plant.output(0.0, state, {"tau": np.zeros(9), "f_ext": np.zeros(3)})["q"]
        errors.append(float(np.abs(q - hand.q0).max()))
    return errors


@pytest.mark.parametrize("kp_scale, kd_scale", [(0.5, 0.5), (0.5, 2.0), (1.0, 1.0), (2.0, 0.5), (2.0, 2.0)])
def test_matched_gains_keep_a_free_finger_stable_where_held_ones_diverge(kp_scale, kd_scale):
    """A free forefinger under a 10 ms joint PD, over kp and kd x0.5-2 around the shipped
    3 N m/rad, 0.04 N m s/rad: the matched gains settle it at every corner. Applied as they
    are and held for 10 ms, the same gains settle it where the sampled loop on each joint's
    inertia J is clearly stable (a/2 < b < 2, a = kp T^2 / J, b = kd T / J, with a 10 %
    margin for the joints' coupling) and diverge where it is clearly not, the shipped point
    included (b = 4 on the distal joint); kp, kd x0.5 sits on the edge (b = 1.99)."""
    from hierhand.model import HandPlant
    from hierhand.model.handfile import default_hand_dict

    sections = default_hand_dict()
    sections["gravity"] = [0.0, 0.0]
    sections["object"]["pos"] = [0.0, 1.0]  # out of the fingers' way: they move freely
    plant = HandPlant(**sections)
    plant.bind(1e-4)
    hand = Hand.default()
    kp, kd = 3.0 * kp_scale, 0.04 * kd_scale
    matched = bound(ManipulationPD(hand=plant, kp=kp, kd=kd, gravity_compensation=False, load_compensation=False,
                                   contact_compensation=False))
    error = free_finger_error(plant, matched, hand, 0.05, 60)
    assert error[-1] < 1e-3 * 0.05 and max(error) < 2 * 0.05
    inertia = np.diag(plant.hand.mass_matrix(plant.hand.q0))[3:6]
    a, b = kp * 0.01 ** 2 / inertia, kd * 0.01 / inertia
    clearly_stable = bool(np.all((a / 2 < 0.9 * b) & (b < 0.9 * 2)))
    clearly_unstable = bool(np.any((a / 2 > 1.1 * b) | (b > 1.1 * 2)))
    held = bound(ManipulationPD(hand=plant, kp=kp, kd=kd, gravity_compensation=False, load_compensation=False,
                                contact_compensation=False, discretization="held"))
    error = free_finger_error(plant, held, hand, 0.05, 60)
    if clearly_stable:
        assert error[-1] < 1e-3 * 0.05, (a, b, error[-5:])
    if clearly_unstable:
        assert error[-1] > 0.05, (a, b, error[-5:])
    assert clearly_stable or clearly_unstable or (kp_scale, kd_scale) == (0.5, 0.5)


def test_manipulation_pd_shares_the_object_weight_among_touching_fingers():
    hand = Hand.default()
    pd = bound(ManipulationPD(hand=hand, gravity_compensation=False))
    contact = pd_inputs(hand, fn=np.array([2.0, 2.0, 0.0]), normal=np.array([1.0, 0.0, -1.0, 0.0, 0.0, 0.0]))
    out = pd.output(0.0, None, contact)
    points = hand.tip_positions(hand.q0)[:2] + hand.tip_radius[:2, None] * np.array([[1.0, 0.0], [-1.0, 0.0]])
    weight = hand.params.object.mass * hand.gravity
    # the shares: equal normal forces, the object's centre between the contact points in x
    forces = [np.linalg.lstsq(hand.point_jacobian(hand.q0, f, points[f]).T, out["tau_ff"][3 * f:3 * f + 3],
                              rcond=None)[0] for f in (0, 1)]
    np.testing.assert_allclose(forces[0] + forces[1], -weight, rtol=1e-9, atol=1e-12)  # the weight carried
    moment = sum(cross(points[f] - hand.object_pose0[:2], forces[f]) for f in (0, 1))
    assert abs(moment) < 1e-12  # and no moment about the object's centre
    np.testing.assert_allclose(out["tau_ff"][6:], 0.0)



def test_a_finger_that_presses_little_carries_little_of_the_load():
    """Three contacts leave the load's shares free beyond its force and moment: they go in
    proportion to the normal forces, what each contact can carry by friction."""
    hand = Hand.default()
    pd = bound(ManipulationPD(hand=hand, gravity_compensation=False))
    normal = np.array([1.0, 0.0, -1.0, 0.0, -1.0, 0.0])
    q = hand.q0.copy()
    points = hand.tip_positions(q) + hand.tip_radius[:, None] * normal.reshape(3, 2)

    def shares(fn):
        tau_ff = pd.output(0.0, None, pd_inputs(hand, fn=np.array(fn), normal=normal))["tau_ff"]
        return [np.linalg.lstsq(hand.point_jacobian(q, f, points[f]).T, tau_ff[3 * f:3 * f + 3], rcond=None)[0]
                for f in range(3)]

    even, light = shares([4.0, 4.0, 4.0]), shares([4.0, 4.0, 0.1])
    weight = hand.params.object.mass * hand.gravity
    for case in (even, light):
        np.testing.assert_allclose(sum(case), -weight, rtol=1e-9, atol=1e-12)
    assert np.linalg.norm(light[2]) < 0.1 * np.linalg.norm(even[2])


def test_manipulation_pd_carries_only_what_the_support_does_not():
    hand = Hand.default()
    pd = bound(ManipulationPD(hand=hand, gravity_compensation=False))
    weight = hand.params.object.mass * hand.gravity
    inputs = pd_inputs(hand, fn=np.array([2.0, 2.0, 0.0]), normal=np.array([1.0, 0.0, -1.0, 0.0, 0.0, 0.0]))
    carried = pd.output(0.0, None, dict(inputs, support=np.array([-weight[0], -weight[1], 0.0])))
    np.testing.assert_allclose(carried["tau_ff"], 0.0, atol=1e-15)
    half = pd.output(0.0, None, dict(inputs, support=np.array([0.0, -weight[1] / 2, 0.0])))
    full = pd.output(0.0, None, inputs)
    np.testing.assert_allclose(half["tau_ff"], full["tau_ff"] / 2, rtol=1e-12, atol=1e-15)


def test_a_squeezed_finger_is_aimed_as_deep_as_its_normal_force_presses_it():
    hand = Hand.default()
    pd = bound(ManipulationPD(hand=hand))
    normal = np.array([1.0, 0.0, -1.0, 0.0, 0.0, 0.0])
    free = pd.output(0.0, None, pd_inputs(hand, normal=normal))["q_ref"]
    pressed = pd.output(0.0, None, pd_inputs(hand, fn=np.array([3.0, 0.0, 0.0]), normal=normal))["q_ref"]
    moved = hand.tip_poses(pressed)[0] - hand.tip_poses(free)[0]
    np.testing.assert_allclose(moved, [3.0 / hand.params.contact.k_n, 0.0, 0.0], atol=1e-12)
    np.testing.assert_array_equal(pressed[3:], free[3:])
    off = bound(ManipulationPD(hand=hand, contact_compensation=False))
    np.testing.assert_array_equal(off.output(0.0, None, pd_inputs(hand, fn=np.array([3.0, 0.0, 0.0]),
                                                                 normal=normal))["q_ref"], free)


def test_manipulation_pd_rejects_an_unreachable_waypoint_naming_finger_and_time():
    with pytest.raises(ValueError, match=r"finger 'fore': the waypoint at t = 0.5 s .* unreachable"):
        ManipulationPD(hand=Hand.default(),
                       trajectories={"fore": {"waypoints": [[0.0, 0.033, 0.06, 3.0], [0.5, 0.2, 0.2, 0.0]]}})


@pytest.mark.parametrize("mode", ["magnitude", "signed"])
def test_suppresser_modes_and_limits(mode):
    s = Suppresser(S_a=200.0, S_b=0.1, mode=mode)
    tau_g = np.array([0.3, -0.3, 0.3] * 3)
    quiet = s.output(0, None, {"tau_g": tau_g, "tau_m": np.zeros(9)})
    np.testing.assert_allclose(quiet["tau_g_eff"], tau_g / (1 + np.exp(-20.0)), rtol=1e-12)
    against = -0.5 * np.sign(tau_g)  # voluntary motion pulling against the grasp at every joint
    pulled = s.output(0, None, {"tau_g": tau_g, "tau_m": against})
    np.testing.assert_allclose(pulled["tau_g_eff"], 0.0, atol=1e-30)
    np.testing.assert_allclose(pulled["tau"], against, atol=1e-30)
    along = s.output(0, None, {"tau_g": tau_g, "tau_m": -against})["tau_g_eff"]
    if mode == "magnitude":  # any large manipulation torque suppresses
        np.testing.assert_allclose(along, 0.0, atol=1e-30)
    else:  # signed: only one that works against the grasp
        np.testing.assert_allclose(along, tau_g, rtol=1e-12)


def test_a_filtered_suppresser_follows_the_manipulation_torque_with_its_time_constant():
    """time_constant > 0: the sigmoid reads the manipulation torque low-passed (first order,
    at the block's period), so a step in it suppresses progressively, not at once."""
    s = Suppresser(S_a=150.0, S_b=0.02, mode="signed", time_constant=0.02)
    with pytest.raises(ValueError, match="needs an explicit period"):
        s.bind(None)
    s.bind(0.001)
    tau_g, tau_m = np.full(9, 0.1), np.full(9, -0.05)  # against the grasp, above S_b
    state = s.initial_state()
    factors = []
    for k in range(100):
        out = s.output(0.001 * k, state, {"tau_g": tau_g, "tau_m": tau_m})
        factors.append(float(out["tau_g_eff"][0] / 0.1))
        state = s.update(0.001 * k, state, {"tau_g": tau_g, "tau_m": tau_m})
    assert factors[0] == pytest.approx(1 / (1 + np.exp(-3.0)), rel=1e-12)  # nothing read yet
    assert np.all(np.diff(factors) < 0)
    # after k steps the filter has (1 - exp(-k T / tau)) of the step
    g = 0.05 * (1 - np.exp(-20 * 0.001 / 0.02))
    assert factors[20] == pytest.approx(1 / (1 + np.exp(-150.0 * (0.02 - g))), rel=1e-9)
    g = 0.05 * (1 - np.exp(-99 * 0.001 / 0.02))
    assert factors[-1] == pytest.approx(1 / (1 + np.exp(-150.0 * (0.02 - g))), rel=1e-9)
    assert Suppresser(time_constant=0.02).feedthrough["tau_g_eff"] == {"tau_g"}


def test_disabled_suppresser_passes_the_grasp_torque_through():
    s = Suppresser(enabled=False)
    assert isinstance(s, Block)
    out = s.output(0, None, {"tau_g": np.arange(9.0), "tau_m": np.ones(9)})
    np.testing.assert_array_equal(out["tau_g_eff"], np.arange(9.0))
    np.testing.assert_array_equal(out["tau"], np.arange(9.0) + 1)


def test_suppresser_adds_the_feedforward_unsuppressed():
    s = Suppresser(S_a=200.0, S_b=0.1)
    tau_ff = np.linspace(-0.2, 0.2, 9)
    big = np.full(9, -0.5)  # against the grasp torque: suppresses it whole
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
