"""The compiled output of ManipulationPD against its numpy oracle, and how the blocks'
native calls take their arguments."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from hierhand import _native
from hierhand.control import UnreachableError, manipulation_pd, reflex_law, suppresser
from hierhand.control.grasp_reflex import GraspReflex
from hierhand.control.manipulation_law import manipulation_output, pack_trajectories
from hierhand.control.manipulation_pd import ManipulationPD
from hierhand.control.suppresser import Suppresser
from hierhand.control.trajectory import INTERPOLATIONS, Trajectory
from hierhand.layouts import MANIP_META as M, MANIP_OUT, MANIP_STATUS as STATUS
from hierhand.model import Hand, HandPlant

from . import oracles

REGRASP = {
    "middle": {"waypoints": [[0.15, 0.04798, 0.07000, 2.6], [0.35, 0.0328, 0.040, 3.0]]},
    "fore": {"waypoints": [[0.38, 0.03310, 0.06017, 3.0], [0.68, 0.04810, 0.06017, 2.6]]},
}
MANIPULATE = {
    "thumb": {"waypoints": [[0.3, -0.03412, 0.06017, -0.0306], [0.8, -0.02857, 0.07109, -0.2051]]},
    "fore": {"waypoints": [[0.3, 0.03310, 0.06017, 3.0000], [0.8, 0.03762, 0.05942, 2.8255]],
             "interpolation": "linear"},
}
THREE_SEGMENTS = {
    "fore": {"waypoints": [[0.1, 0.03310, 0.06017, 3.0], [0.3, 0.0381, 0.06017, 2.8],
                           [0.32, 0.0381, 0.0612, 2.8], [0.5, 0.0351, 0.0590, 2.9]]},
    "thumb": {"waypoints": [[0.2, -0.03412, 0.06017, -0.0306], [0.4, -0.0300, 0.0650, -0.1],
                            [0.6, -0.02857, 0.07109, -0.2051]], "interpolation": "linear"},
}


def bound_pd(**params) -> ManipulationPD:
    """A ManipulationPD with the 10 ms period a diagram gives it (its gains are matched to it)."""
    pd = ManipulationPD(**params)
    pd.bind(Fraction(1, 100))
    return pd


def pd_inputs(hand, **ports) -> dict:
    """The PD's inputs: ``ports`` over the hand at rest, no contact normals, the object where it starts."""
    return {"q": hand.q0, "qd": np.zeros(9), "fn": np.zeros(3), "normal": np.zeros(6), "obj": hand.object_pose0,
            **ports}


def _times(trajectories):
    """A grid plus every waypoint time and its neighbours a derivative step away."""
    ts = list(np.linspace(-0.05, 1.0, 211))
    for spec in trajectories.values():
        for w in spec["waypoints"]:
            ts += [w[0], w[0] - 1e-3, w[0] + 1e-3, np.nextafter(w[0], -1.0), np.nextafter(w[0], 2.0)]
    return ts


@pytest.mark.parametrize("trajectories", [REGRASP, MANIPULATE, THREE_SEGMENTS, {}])
@pytest.mark.parametrize("flags", [(True, True, True, "matched"), (False, True, False, "held"),
                                   (True, False, True, "held"), (False, False, False, "matched")])
def test_compiled_output_matches_the_oracle(trajectories, flags):
    hand = Hand.default()
    pd = bound_pd(hand=hand, kp=[1.0, 2.0, 0.5] * 3, kd=0.015, trajectories=trajectories,
                  gravity_compensation=flags[0], load_compensation=flags[1], contact_compensation=flags[2],
                  discretization=flags[3])
    rng = np.random.default_rng(7)
    for t in _times(trajectories):
        angles = rng.uniform(-np.pi, np.pi, 3)
        inputs = {"q": hand.q0 + rng.normal(0.0, 0.1, 9), "qd": rng.normal(0.0, 1.0, 9),
                  "fn": rng.choice([0.0, 0.04, 0.06, 2.0], 3), "support": rng.normal(0.0, 1.0, 3),
                  "normal": np.column_stack([np.cos(angles), np.sin(angles)]).ravel(),
                  "obj": hand.object_pose0 + rng.normal(0.0, 0.003, 3)}
        fast = pd.output(float(t), None, inputs)
        expected = oracles.manipulation_output(pd, float(t), inputs)
        assert set(fast) == set(expected) == set(pd.outputs)
        for port in expected:
            assert fast[port].shape == (9,) and fast[port].dtype == np.float64
            # round-off of the grasp-matrix solves: relative to the port's largest value
            np.testing.assert_allclose(fast[port], expected[port], rtol=1e-11,
                                       atol=1e-12 * max(1.0, float(np.abs(expected[port]).max())),
                                       err_msg=f"{port} at t={t}")


def test_outputs_are_fresh_arrays():
    hand = Hand.default()
    pd = bound_pd(hand=hand, trajectories=REGRASP)
    inputs = pd_inputs(hand, fn=np.ones(3))
    a = pd.output(0.2, None, inputs)
    kept = {k: v.copy() for k, v in a.items()}
    pd.output(0.5, None, inputs)
    for k in a:
        np.testing.assert_array_equal(a[k], kept[k])
        assert not np.shares_memory(a[k], pd._params)


def test_unusual_inputs_are_converted():
    hand = Hand.default()
    pd = bound_pd(hand=hand, trajectories=REGRASP)
    ref = pd.output(0.25, None, pd_inputs(hand))
    listed = pd.output(0.25, None, pd_inputs(hand, q=list(hand.q0), qd=[0] * 9, fn=np.zeros(3, dtype=np.float32),
                                             obj=list(hand.object_pose0)))
    for k in ref:
        np.testing.assert_array_equal(listed[k], ref[k])
    integer_time = pd.output(0, None, pd_inputs(hand))
    np.testing.assert_array_equal(integer_time["q_ref"], pd.output(0.0, None, pd_inputs(hand))["q_ref"])
    with pytest.raises(ValueError, match="^qd must hold 9 values, got 8$"):
        pd.output(0.25, None, pd_inputs(hand, qd=np.zeros(8)))
    with pytest.raises(ValueError, match="^normal must hold 6 values, got 4$"):
        pd.output(0.25, None, pd_inputs(hand, normal=np.zeros(4)))


def test_matched_gains_need_the_period():
    hand = Hand.default()
    unbound = ManipulationPD(hand=hand)
    with pytest.raises(ValueError, match="matched to its period, and it has none yet"):
        unbound.output(0.0, None, pd_inputs(hand))
    with pytest.raises(ValueError, match="needs an explicit period"):
        unbound.bind(None)
    held = ManipulationPD(hand=hand, discretization="held")
    held.bind(None)
    assert np.all(np.isfinite(held.output(0.0, None, pd_inputs(hand))["tau_m"]))


def test_a_target_unreachable_between_waypoints_raises_naming_the_finger():
    # fore finger: wrist points 50 mm above and below the base (reachable), whose
    # straight-line interpolation passes the base itself (inside the inner radius)
    hand = Hand.default()
    pd = bound_pd(hand=hand, trajectories={"fore": {"waypoints": [[0.0, 0.035, 0.062, math.pi / 2],
                                                                        [1.0, 0.035, -0.038, math.pi / 2]]}})
    inputs = pd_inputs(hand)
    pd.output(0.1, None, inputs)
    with pytest.raises(UnreachableError, match="fore: unreachable fingertip target"):
        pd.output(0.5, None, inputs)


def test_unbound_plant_is_rejected_by_every_entry_point():
    plant = HandPlant()
    state = plant.initial_state()
    inputs = {"tau": np.zeros(9)}
    for call in (lambda: plant.output(0.0, state, inputs), lambda: plant.update(0.0, state, inputs),
                 lambda: plant.advance(0.0, state, inputs, 3)):
        with pytest.raises(Exception, match="not bound to a period"):
            call()


def test_float64_arrays_with_a_distinct_dtype_object_take_the_native_path(monkeypatch):
    """Any C-contiguous float64 array goes straight to the native call, also one whose
    dtype object is equal but not identical to numpy's float64 (as arrays from other
    libraries carry); nothing is converted."""
    dtype = np.dtype(np.float64).newbyteorder("=")
    assert dtype == np.float64 and dtype is not np.dtype(np.float64)
    hand = Hand.default()

    def refuse(*args, **kwargs):
        raise AssertionError("conversion taken")

    for module in (manipulation_pd, suppresser, reflex_law):
        monkeypatch.setattr(module, "flat_float64", refuse)
    pd = bound_pd(hand=hand, trajectories=REGRASP)
    s = Suppresser()
    reflex = GraspReflex(hand=hand)
    reflex.bind(0.001)
    pd.output(0.2, None, {"q": hand.q0.astype(dtype), "qd": np.zeros(9, dtype), "fn": np.zeros(3, dtype),
                          "normal": np.zeros(6, dtype), "obj": hand.object_pose0.astype(dtype)})
    s.output(0.0, None, {"tau_g": np.ones(9, dtype), "tau_m": np.zeros(9, dtype)})
    reflex_inputs = {"q": hand.q0.astype(dtype), "tip": hand.tip_poses(hand.q0).ravel().astype(dtype),
                     "normal": np.zeros(6, dtype), "fn": np.array([1.0, 1.0, 0.0], dtype),
                     "ft": np.zeros(3, dtype)}
    reflex.output(0.0, reflex.initial_state().astype(dtype), reflex_inputs)
    reflex.update(0.0, reflex.initial_state().astype(dtype), reflex_inputs)
    plant = HandPlant()
    plant.bind(1e-4)
    state = plant.initial_state().astype(dtype)
    monkeypatch.setattr(plant, "_check_state", refuse)
    monkeypatch.setattr(plant, "_arguments", refuse)
    plant.advance(0.0, state, {"tau": np.zeros(9, dtype), "f_ext": np.zeros(3, dtype)}, 2)


def test_other_arrays_are_converted():
    """Strided views, other dtypes and lists give what their float64 copies give."""
    hand = Hand.default()
    pd = bound_pd(hand=hand, trajectories=REGRASP)
    s = Suppresser(S_a=50.0, S_b=0.2)
    reflex = GraspReflex(hand=hand)
    reflex.bind(0.001)
    rng = np.random.default_rng(11)
    wide = rng.normal(size=(9, 2))
    q = hand.q0 + 0.05 * wide[:, 0]
    manip = pd_inputs(hand, q=q, qd=wide[:, 1].copy(), fn=np.array([0.0, 2.0, 2.0]),
                      normal=np.array([1.0, 0.0, -1.0, 0.0, -1.0, 0.0]))
    strided = pd_inputs(hand, q=np.column_stack([q, q])[:, 0], qd=wide[:, 1], fn=np.array([0, 2, 2]),
                        normal=[1, 0, -1, 0, -1, 0])
    assert not strided["q"].flags.c_contiguous
    for port, value in pd.output(0.2, None, strided).items():
        np.testing.assert_array_equal(value, pd.output(0.2, None, manip)[port])
    torques = {"tau_g": wide[:, 0], "tau_m": wide[:, 1].astype(np.float32)}
    expected = s.output(0.0, None, {k: np.array(v, dtype=float) for k, v in torques.items()})
    for port, value in s.output(0.0, None, torques).items():
        np.testing.assert_array_equal(value, expected[port])
    tip = hand.tip_poses(q)
    normal = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0]])
    exact = {"q": q, "tip": tip.ravel(), "normal": normal.ravel(), "fn": np.array([1.0, 1.0, 0.0]),
             "ft": np.array([0.1, 0.2, 0.0])}
    loose = {"q": list(q), "tip": tip, "normal": normal.T.copy().T, "fn": np.array([1, 1, 0]),
             "ft": np.array([0.1, 0.2, 0.0], dtype=np.float32)}
    state = np.array([2.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0])
    for port, value in reflex.output(0.0, state, loose).items():
        np.testing.assert_array_equal(value, reflex.output(0.0, state, exact)[port])
    np.testing.assert_allclose(reflex.update(0.0, list(state), loose), reflex.update(0.0, state, exact), rtol=1e-7)


def test_native_output_reports_the_unreachable_finger():
    """The status names the finger (UNREACHABLE + f) whose target, or a neighbour a
    derivative step away, is out of reach; ``output`` then raises naming it."""
    hand = Hand.default()
    pd = bound_pd(hand=hand, trajectories={"fore": {"waypoints": [[0.0, 0.035, 0.062, math.pi / 2],
                                                                        [1.0, 0.035, -0.038, math.pi / 2]]}})
    inputs = (hand.q0, np.zeros(9), np.zeros(3), np.zeros(3), np.zeros(6), hand.object_pose0)
    out = np.empty((3, 9))
    assert manipulation_output(hand.native, pd._params, pd._waypoints, pd._meta, 0.1, *inputs, out) == STATUS.OK
    status = manipulation_output(hand.native, pd._params, pd._waypoints, pd._meta, 0.5, *inputs, out)
    assert status == STATUS.UNREACHABLE + 1
    with pytest.raises(ValueError, match="out must hold 27 values"):
        manipulation_output(hand.native, pd._params, pd._waypoints, pd._meta, 0.1, *inputs,
                            np.empty(MANIP_OUT.size - 1))
    with pytest.raises(UnreachableError, match="^fore: unreachable"):
        pd.output(0.5, None, dict(zip(("q", "qd", "fn", "support", "normal", "obj"), inputs)))


def test_a_target_out_of_reach_only_a_derivative_step_ahead_is_named():
    """The velocity target needs the poses a derivative step either side: one out of reach
    there is the finger's error too, with the wrist's distance inside the inner radius."""
    hand = Hand.default()
    through_base = [[0.0, 0.035, 0.062, math.pi / 2], [1.0, 0.035, -0.038, math.pi / 2]]
    pd = bound_pd(hand=hand, trajectories={"fore": {"waypoints": through_base}})
    waypoints = np.array(through_base)

    def reachable(t: float) -> bool:
        target = oracles.trajectory_sample(waypoints, "minjerk", t)
        return oracles.finger_ik_near(hand, 1, target, hand.q0[3:6]) is not None

    lo, hi = 0.1, 0.5  # reachable, not: bisect to where the path leaves the annulus
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if reachable(mid) else (lo, mid)
    t = lo - 0.4e-3  # its own target reachable, the one a derivative step (1 ms) ahead not
    assert reachable(t) and not reachable(t + 1e-3)
    inputs = pd_inputs(hand)
    with pytest.raises(UnreachableError, match="^fore: unreachable") as info:
        pd.output(t, None, inputs)
    assert info.value.finger == "fore" and info.value.distance < info.value.r_min


def test_trajectory_arrays_are_checked():
    hand = Hand.default()
    pd = bound_pd(hand=hand)
    waypoints, meta = pack_trajectories([None, Trajectory([[0.0, 0.03, 0.06, 3.0], [1.0, 0.031, 0.06, 3.0]]), None])
    assert meta.dtype == np.float64 and meta[1, M.COUNT] == 2 and meta[1, M.INTERP] == INTERPOLATIONS["minjerk"]
    inputs = (hand.q0, np.zeros(9), np.zeros(3), np.zeros(3), np.zeros(6), hand.object_pose0, np.empty((3, 9)))
    assert manipulation_output(hand.native, pd._params, waypoints, meta, 0.5, *inputs) == STATUS.OK
    for bad in (2.5, 3.0, -1.0, np.nan):
        wrong = meta.copy()
        wrong[1, M.COUNT] = bad
        with pytest.raises(ValueError, match="waypoint count"):
            manipulation_output(hand.native, pd._params, waypoints, wrong, 0.5, *inputs)
    wrong = meta.copy()
    wrong[1, M.INTERP] = 7
    with pytest.raises(ValueError, match="interpolation"):
        manipulation_output(hand.native, pd._params, waypoints, wrong, 0.5, *inputs)
    with pytest.raises(ValueError, match="3 x n x 4"):
        manipulation_output(hand.native, pd._params, waypoints.ravel()[:-1].copy(), meta, 0.5, *inputs)
    with pytest.raises(TypeError, match="float64"):
        manipulation_output(hand.native, pd._params, waypoints, meta.astype(np.int64), 0.5, *inputs)
    pose = np.empty(3)
    with pytest.raises(ValueError, match="n x 4"):
        _native.trajectory_sample(np.zeros(6), INTERPOLATIONS["linear"], 0.5, pose)
    with pytest.raises(ValueError, match="interpolation"):
        _native.trajectory_sample(np.zeros(4), 7, 0.5, pose)
