"""The native (C) fast paths of ManipulationPD and Suppresser against their numpy references."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hierhand.control.inverse_kinematics import (
    UnreachableError,
    finger_fk,
    finger_ik_near,
)
from hierhand.control import reflex_kernel
from hierhand.control.grasp_reflex import GraspReflex
from hierhand.control.manipulation_kernel import (
    INTERP_LINEAR,
    M_COUNT,
    M_INTERP,
    N_OUT,
    OK,
    UNREACHABLE,
    ik_near,
    manipulation_output,
    moving,
    pack_trajectories,
    sample,
)
from hierhand.control.manipulation_pd import ManipulationPD
from hierhand.control.suppresser import Suppresser
from hierhand.control.suppression import suppress
from hierhand.control.trajectory import Trajectory
from hierhand.model import Hand, HandPlant

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


def _times(trajectories):
    """A grid plus every waypoint time and its neighbours a derivative step away."""
    ts = list(np.linspace(-0.05, 1.0, 211))
    for spec in trajectories.values():
        for w in spec["waypoints"]:
            ts += [w[0], w[0] - 1e-3, w[0] + 1e-3, np.nextafter(w[0], -1.0), np.nextafter(w[0], 2.0)]
    return ts


@pytest.mark.parametrize("trajectories", [REGRASP, MANIPULATE, THREE_SEGMENTS, {}])
@pytest.mark.parametrize("flags", [(True, True), (False, True), (True, False), (False, False)])
def test_compiled_output_matches_the_numpy_reference(trajectories, flags):
    hand = Hand.default()
    pd = ManipulationPD(hand=hand, kp=[1.0, 2.0, 0.5] * 3, kd=0.015, trajectories=trajectories,
                        gravity_compensation=flags[0], load_compensation=flags[1])
    rng = np.random.default_rng(7)
    for t in _times(trajectories):
        inputs = {"q": hand.q0 + rng.normal(0.0, 0.1, 9), "qd": rng.normal(0.0, 1.0, 9),
                  "fn": rng.choice([0.0, 0.04, 0.06, 2.0], 3)}
        fast = pd.output(float(t), None, inputs)
        ref = pd.output_reference(float(t), None, inputs)
        assert set(fast) == set(ref) == set(pd.outputs)
        for port in ref:
            assert fast[port].shape == (9,) and fast[port].dtype == np.float64
            np.testing.assert_allclose(fast[port], ref[port], rtol=1e-11, atol=1e-13, err_msg=f"{port} at t={t}")


def test_outputs_are_fresh_arrays():
    hand = Hand.default()
    pd = ManipulationPD(hand=hand, trajectories=REGRASP)
    inputs = {"q": hand.q0, "qd": np.zeros(9), "fn": np.ones(3)}
    a = pd.output(0.2, None, inputs)
    kept = {k: v.copy() for k, v in a.items()}
    pd.output(0.5, None, inputs)
    for k in a:
        np.testing.assert_array_equal(a[k], kept[k])
        assert not np.shares_memory(a[k], pd._params)


def test_unusual_inputs_take_the_reference_path():
    hand = Hand.default()
    pd = ManipulationPD(hand=hand, trajectories=REGRASP)
    ref = pd.output(0.25, None, {"q": hand.q0, "qd": np.zeros(9), "fn": np.zeros(3)})
    listed = pd.output(0.25, None, {"q": list(hand.q0), "qd": [0] * 9, "fn": np.zeros(3, dtype=np.float32)})
    for k in ref:
        np.testing.assert_allclose(listed[k], ref[k], rtol=1e-12, atol=1e-15)
    integer_time = pd.output(0, None, {"q": hand.q0, "qd": np.zeros(9), "fn": np.zeros(3)})
    np.testing.assert_array_equal(integer_time["q_ref"], pd.output(0.0, None, {"q": hand.q0, "qd": np.zeros(9),
                                                                             "fn": np.zeros(3)})["q_ref"])


def test_a_target_unreachable_between_waypoints_raises_naming_the_finger():
    # fore finger: wrist points 50 mm above and below the base (reachable), whose
    # straight-line interpolation passes the base itself (inside the inner radius)
    hand = Hand.default()
    pd = ManipulationPD(hand=hand, trajectories={"fore": {"waypoints": [[0.0, 0.035, 0.062, math.pi / 2],
                                                                        [1.0, 0.035, -0.038, math.pi / 2]]}})
    inputs = {"q": hand.q0, "qd": np.zeros(9), "fn": np.zeros(3)}
    pd.output(0.1, None, inputs)
    with pytest.raises(UnreachableError, match="fore: unreachable fingertip target"):
        pd.output(0.5, None, inputs)


def test_ik_near_matches_finger_ik_near():
    hand = Hand.default()
    rng = np.random.default_rng(3)
    for _ in range(3000):
        f = int(rng.integers(3))
        q = hand.q0[3 * f:3 * f + 3] + rng.normal(0.0, 0.8, 3)
        ref_q = hand.q0[3 * f:3 * f + 3] + rng.normal(0.0, 1.5, 3)
        p = hand.params.fingers[f]
        target = finger_fk(p.base, p.base_angle, [link.length for link in p.links], q)
        ok, *got = ik_near(hand.native, f, *target, *ref_q)
        assert ok
        np.testing.assert_allclose(got, finger_ik_near(hand, f, target, ref_q), rtol=1e-12, atol=1e-12)
    ok, *_ = ik_near(hand.native, 1, 1.0, 1.0, 0.0, *hand.q0[3:6])
    assert not ok


@pytest.mark.parametrize("interpolation", ["minjerk", "linear"])
def test_trajectory_sampling_matches_trajectory(interpolation):
    wp = [[0.1, 0.0, 1.0, 2.0], [0.3, 0.5, 1.0, 2.5], [0.35, 0.5, 1.0, 2.5], [0.9, -0.5, 2.0, 3.0]]
    traj = Trajectory(wp, interpolation)
    waypoints, meta = pack_trajectories([None, traj, Trajectory([[0.2, 1.0, 2.0, 3.0]])])
    ts = list(np.linspace(0.0, 1.0, 1001)) + [w[0] for w in wp] + [np.nextafter(w[0], 0.0) for w in wp]
    for t in ts:
        assert sample(waypoints, meta, 1, t) == tuple(traj.sample(t)), t
        assert moving(waypoints, meta, 1, t) == bool(np.any(traj.velocity(t))), t
        assert sample(waypoints, meta, 2, t) == (1.0, 2.0, 3.0)
        assert not moving(waypoints, meta, 2, t)


@pytest.mark.parametrize("mode", ["magnitude", "signed"])
@pytest.mark.parametrize("enabled", [True, False])
def test_suppresser_kernel_matches_suppress(mode, enabled):
    s = Suppresser(S_a=[200.0, 0.0, 50.0] * 3, S_b=[0.1, 0.2, 0.0] * 3, mode=mode, enabled=enabled)
    rng = np.random.default_rng(5)
    for scale in (1e-3, 0.1, 1.0, 1e3):
        for _ in range(200):
            inputs = {"tau_g": rng.normal(0.0, scale, 9), "tau_m": rng.normal(0.0, scale, 9)}
            fast = s.output(0.0, None, inputs)
            ref = s.output_reference(0.0, None, inputs)
            if enabled:
                np.testing.assert_allclose(ref["tau_g_eff"], suppress(inputs["tau_g"], inputs["tau_m"], s.S_a, s.S_b, mode))
            for port in ("tau", "tau_g_eff"):
                assert fast[port].shape == (9,) and fast[port].dtype == np.float64
                np.testing.assert_allclose(fast[port], ref[port], rtol=1e-14, atol=1e-300)


def test_suppresser_edge_values_and_unusual_inputs():
    s = Suppresser(S_a=200.0, S_b=0.1)
    tau_g = np.array([1.0, -2.0, 3.0, np.nan, 1.0, 1.0, 1e308, 0.0, 1.0])
    tau_m = np.array([0.1, 1e300, -1e300, 0.0, np.inf, np.nan, 0.0, 5.0, -0.1])
    fast = s.output(0.0, None, {"tau_g": tau_g, "tau_m": tau_m})
    with np.errstate(all="ignore"):
        ref = s.output_reference(0.0, None, {"tau_g": tau_g, "tau_m": tau_m})
    for port in ref:
        np.testing.assert_allclose(fast[port], ref[port], rtol=1e-14)
    listed = s.output(0.0, None, {"tau_g": [0.3] * 9, "tau_m": np.zeros(9, dtype=np.float32)})
    np.testing.assert_allclose(listed["tau_g_eff"], 0.3 / (1 + math.exp(-20.0)), rtol=1e-14)


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
    libraries carry); nothing is converted and no reference path is taken."""
    dtype = np.dtype(np.float64).newbyteorder("=")
    assert dtype == np.float64 and dtype is not np.dtype(np.float64)
    hand = Hand.default()

    def refuse(*args, **kwargs):
        raise AssertionError("conversion or reference path taken")

    pd = ManipulationPD(hand=hand, trajectories=REGRASP)
    s = Suppresser()
    reflex = GraspReflex(hand=hand)
    reflex.bind(0.001)
    monkeypatch.setattr(pd, "output_reference", refuse)
    monkeypatch.setattr(s, "output_reference", refuse)
    monkeypatch.setattr(reflex_kernel, "_f64", refuse)
    pd.output(0.2, None, {"q": hand.q0.astype(dtype), "qd": np.zeros(9, dtype), "fn": np.zeros(3, dtype)})
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


def test_other_arrays_are_converted_or_take_the_reference_path():
    """Strided views, other dtypes and lists give what their float64 copies give."""
    hand = Hand.default()
    pd = ManipulationPD(hand=hand, trajectories=REGRASP)
    s = Suppresser(S_a=50.0, S_b=0.2)
    reflex = GraspReflex(hand=hand)
    reflex.bind(0.001)
    rng = np.random.default_rng(11)
    wide = rng.normal(size=(9, 2))
    q = hand.q0 + 0.05 * wide[:, 0]
    manip = {"q": q, "qd": wide[:, 1].copy(), "fn": np.array([0.0, 2.0, 2.0])}
    strided = {"q": np.column_stack([q, q])[:, 0], "qd": wide[:, 1], "fn": np.array([0, 2, 2])}
    assert not strided["q"].flags.c_contiguous
    for port, value in pd.output(0.2, None, strided).items():
        np.testing.assert_allclose(value, pd.output(0.2, None, manip)[port], rtol=1e-12, atol=1e-15)
    torques = {"tau_g": wide[:, 0], "tau_m": wide[:, 1].astype(np.float32)}
    expected = s.output(0.0, None, {k: np.array(v, dtype=float) for k, v in torques.items()})
    for port, value in s.output(0.0, None, torques).items():
        np.testing.assert_allclose(value, expected[port], rtol=1e-14)
    tip = hand.tip_poses(q)
    normal = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0]])
    exact = {"q": q, "tip": tip.ravel(), "normal": normal.ravel(), "fn": np.array([1.0, 1.0, 0.0]),
             "ft": np.array([0.1, 0.2, 0.0])}
    loose = {"q": list(q), "tip": tip, "normal": normal.T.copy().T, "fn": np.array([1, 1, 0]),
             "ft": np.array([0.1, 0.2, 0.0], dtype=np.float32)}
    state = np.array([2.0, 1.0, 1.0, 0.0])
    for port, value in reflex.output(0.0, state, loose).items():
        np.testing.assert_array_equal(value, reflex.output(0.0, state, exact)[port])
    np.testing.assert_allclose(reflex.update(0.0, list(state), loose), reflex.update(0.0, state, exact), rtol=1e-7)


def test_native_output_reports_the_unreachable_finger():
    """The status names the finger (UNREACHABLE + f) whose target, or a neighbour a
    derivative step away, is out of reach; ``output`` then raises from the reference."""
    hand = Hand.default()
    pd = ManipulationPD(hand=hand, trajectories={"fore": {"waypoints": [[0.0, 0.035, 0.062, math.pi / 2],
                                                                        [1.0, 0.035, -0.038, math.pi / 2]]}})
    inputs = (hand.q0, np.zeros(9), np.zeros(3), np.zeros(3))
    out = np.empty((3, 9))
    assert manipulation_output(hand.native, pd._params, pd._waypoints, pd._meta, 0.1, *inputs, out) == OK
    assert manipulation_output(hand.native, pd._params, pd._waypoints, pd._meta, 0.5, *inputs, out) == UNREACHABLE + 1
    with pytest.raises(ValueError, match="out must hold 27 values"):
        manipulation_output(hand.native, pd._params, pd._waypoints, pd._meta, 0.1, *inputs, np.empty(N_OUT - 1))


def test_trajectory_arrays_are_checked():
    waypoints, meta = pack_trajectories([None, Trajectory([[0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 0.0, 0.0]]), None])
    assert meta.dtype == np.float64 and meta[1, M_COUNT] == 2 and meta[1, M_INTERP] != INTERP_LINEAR
    with pytest.raises(ValueError, match="finger 0 has no trajectory"):
        sample(waypoints, meta, 0, 0.5)
    with pytest.raises(ValueError, match="finger must be 0, 1 or 2"):
        moving(waypoints, meta, 3, 0.5)
    for bad in (2.5, 3.0, -1.0, np.nan):
        wrong = meta.copy()
        wrong[1, M_COUNT] = bad
        with pytest.raises(ValueError, match="waypoint count"):
            sample(waypoints, wrong, 1, 0.5)
    wrong = meta.copy()
    wrong[1, M_INTERP] = 7
    with pytest.raises(ValueError, match="interpolation"):
        moving(waypoints, wrong, 1, 0.5)
    with pytest.raises(ValueError, match="3 x n x 4"):
        sample(waypoints.ravel()[:-1].copy(), meta, 1, 0.5)
    with pytest.raises(TypeError, match="float64"):
        sample(waypoints, meta.astype(np.int64), 1, 0.5)
