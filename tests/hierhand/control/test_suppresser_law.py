"""The suppresser's law: stable sigmoid, signed and magnitude modes, limits, shares, the
low-pass filter; the compiled law against its numpy oracle."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from hierhand.control import finger_shares, sigmoid, suppress
from hierhand.control.suppresser import Suppresser

from . import oracles

finite = st.floats(-1e6, 1e6)


def test_sigmoid_is_stable_far_out():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
            assert sigmoid(1000.0) == 1.0
            assert sigmoid(-1000.0) == 0.0
            assert sigmoid(-745.0) > 0.0
            np.testing.assert_array_equal(sigmoid(np.array([-1e308, 0.0, 1e308])), [0.0, 0.5, 1.0])


@given(st.floats(-30, 30))
def test_sigmoid_matches_the_logistic_formula(x):
    assert sigmoid(x) == pytest.approx(1.0 / (1.0 + math.exp(-x)), rel=1e-14)


@given(finite)
def test_sigmoid_is_symmetric(x):
    assert sigmoid(-x) == pytest.approx(1.0 - sigmoid(x), abs=1e-15)


def test_sigmoid_keeps_shape_and_returns_floats_for_scalars():
    assert isinstance(sigmoid(0.3), float)
    assert sigmoid(np.zeros((2, 3))).shape == (2, 3)


@given(st.floats(-5, 5), st.floats(0, 50), st.floats(-1, 1))
def test_magnitude_mode_at_zero_manipulation_torque(tau_g, s_a, s_b):
    expected = tau_g / (1.0 + math.exp(-s_a * s_b))
    assert suppress(tau_g, 0.0, s_a, s_b, "magnitude") == pytest.approx(expected, rel=1e-13, abs=1e-300)


@pytest.mark.parametrize("tau_m", [-10.0, 10.0, -1e6, 1e6])
def test_magnitude_mode_suppresses_large_torques_of_either_sign(tau_m):
    out = suppress(np.array([0.3, -0.2, 1.0]), np.full(3, tau_m), 50.0, 0.05, "magnitude")
    np.testing.assert_allclose(out, 0.0, atol=1e-9)


def test_signed_mode_suppresses_only_manipulation_torque_against_the_grasp():
    """The paper's literal formula, with tau_m signed positive against the joint's grasping
    torque: a large torque along the grasp passes it, one against it switches it off."""
    tau_g = np.array([0.3, -0.2, 1.0])
    along, against = 10.0 * np.sign(tau_g), -10.0 * np.sign(tau_g)
    np.testing.assert_allclose(suppress(tau_g, along, 50.0, 0.05, mode="signed"), tau_g, rtol=1e-12)
    np.testing.assert_allclose(suppress(tau_g, against, 50.0, 0.05, mode="signed"), 0.0, atol=1e-9)


@given(st.floats(-5, 5), st.floats(0, 1e3), st.floats(0, 50), st.floats(-1, 1))
def test_modes_agree_for_manipulation_torque_against_the_grasp(tau_g, size, s_a, s_b):
    against = -size if tau_g >= 0 else size
    assert suppress(tau_g, against, s_a, s_b, "signed") == suppress(tau_g, against, s_a, s_b, "magnitude")


@given(st.floats(0.01, 5), st.floats(0, 10), st.floats(0, 10), st.floats(0.1, 50), st.floats(-1, 1))
def test_magnitude_mode_never_grows_with_the_torque_size(tau_g, a, b, s_a, s_b):
    small, large = sorted([a, b])
    assert suppress(tau_g, -large, s_a, s_b, "magnitude") <= suppress(tau_g, small, s_a, s_b, "magnitude")


@pytest.mark.parametrize("s_a", [0.0, 1e-12])
@pytest.mark.parametrize("mode", ["magnitude", "signed"])
def test_vanishing_gain_halves_the_grasp_torque(s_a, mode):
    tau_g = np.array([0.4, -0.1, 2.0])
    out = suppress(tau_g, np.array([5.0, -3.0, 0.0]), s_a, 0.05, mode=mode)
    np.testing.assert_allclose(out, tau_g / 2, rtol=1e-9)


def test_per_joint_parameters_broadcast():
    tau_g = np.array([1.0, 1.0, 1.0])
    tau_m = np.array([0.0, 0.1, -0.1])
    s_a = np.array([10.0, 20.0, 30.0])
    s_b = np.array([0.05, 0.1, 0.0])
    expected = tau_g / (1 + np.exp(-s_a * (s_b - np.abs(tau_m))))
    np.testing.assert_allclose(suppress(tau_g, tau_m, s_a, s_b, "magnitude"), expected, rtol=1e-14)
    assert isinstance(suppress(1.0, 0.0, 1.0, 0.0), float)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"mode": "absolute"}, "mode"),
        ({"S_a": -1.0}, "S_a"),
        ({"S_a": np.array([1.0, -0.1])}, "S_a"),
        ({"S_a": float("nan")}, "S_a"),
    ],
)
def test_bad_parameters_are_rejected(kwargs, message):
    args = {"tau_g": np.ones(2), "tau_m": np.zeros(2), "S_a": 1.0, "S_b": 0.0}
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        suppress(**args)


def test_suppress_matches_the_oracle_to_round_off():
    """numpy's exp and libm's may differ in the last bit; nothing more."""
    rng = np.random.default_rng(41)
    for mode in ("magnitude", "signed"):
        for scale in (1e-3, 0.1, 1.0, 1e3):
            tau_g, tau_m = rng.normal(0.0, scale, (2, 500, 9))
            s_a, s_b = rng.uniform(0.0, 500.0, 9), rng.uniform(-0.2, 0.3, 9)
            np.testing.assert_allclose(suppress(tau_g, tau_m, s_a, s_b, mode),
                                       oracles.suppress(tau_g, tau_m, s_a, s_b, mode), rtol=1e-15, atol=1e-300)
    x = rng.normal(0.0, 50.0, 10000)
    np.testing.assert_allclose(sigmoid(x), oracles.sigmoid(x), rtol=5e-16, atol=1e-300)


def test_finger_shares_project_the_kept_torque_on_the_grasp_torque():
    tau_g = np.array([1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0])
    kept = np.array([0.5, 3.0, 0.0, 0.0, -1.0, 0.0, 1.0, 1.0, 1.0])  # the part across tau_g does not count
    np.testing.assert_array_equal(finger_shares(tau_g, kept), [0.5, -0.5, 1.0])
    rng = np.random.default_rng(43)
    for _ in range(200):
        tau_g, tau_g_eff = rng.normal(size=(2, 9))
        np.testing.assert_allclose(finger_shares(tau_g, tau_g_eff), oracles.finger_shares(tau_g, tau_g_eff),
                                   rtol=1e-14)


@pytest.mark.parametrize("mode", ["magnitude", "signed"])
@pytest.mark.parametrize("enabled", [True, False])
def test_the_block_matches_the_oracle(mode, enabled):
    s = Suppresser(S_a=[200.0, 0.0, 50.0] * 3, S_b=[0.1, 0.2, 0.0] * 3, mode=mode, enabled=enabled)
    rng = np.random.default_rng(5)
    for scale in (1e-3, 0.1, 1.0, 1e3):
        for _ in range(200):
            inputs = {"tau_g": rng.normal(0.0, scale, 9), "tau_m": rng.normal(0.0, scale, 9),
                      "tau_ff": rng.normal(0.0, scale, 9)}
            out, expected = s.output(0.0, None, inputs), oracles.suppresser_output(s, inputs)
            for port in expected:
                assert out[port].shape == expected[port].shape and out[port].dtype == np.float64
                np.testing.assert_allclose(out[port], expected[port], rtol=1e-13, atol=1e-300)


def test_the_block_at_edge_values_and_with_unusual_inputs():
    s = Suppresser(S_a=200.0, S_b=0.1)
    tau_g = np.array([1.0, -2.0, 3.0, np.nan, 1.0, 1.0, 1e308, 0.0, 1.0])
    tau_m = np.array([0.1, 1e300, -1e300, 0.0, np.inf, np.nan, 0.0, 5.0, -0.1])
    out = s.output(0.0, None, {"tau_g": tau_g, "tau_m": tau_m})
    with np.errstate(all="ignore"):
        expected = oracles.suppresser_output(s, {"tau_g": tau_g, "tau_m": tau_m})
    for port in expected:
        np.testing.assert_allclose(out[port], expected[port], rtol=1e-14)
    listed = s.output(0.0, None, {"tau_g": [0.3] * 9, "tau_m": np.zeros(9, dtype=np.float32)})
    np.testing.assert_allclose(listed["tau_g_eff"], 0.3 / (1 + math.exp(-20.0)), rtol=1e-14)
    with pytest.raises(ValueError, match="^tau_m must hold 9 values, got 8$"):
        s.output(0.0, None, {"tau_g": np.zeros(9), "tau_m": np.zeros(8)})


@pytest.mark.parametrize("mode", ["magnitude", "signed"])
def test_the_filtered_block_matches_the_oracle(mode):
    s = Suppresser(S_a=[150.0, 0.0, 50.0] * 3, S_b=[0.02, 0.2, 0.0] * 3, mode=mode, time_constant=0.02)
    s.bind(0.001)
    rng = np.random.default_rng(9)
    state, expected_state = s.initial_state(), np.zeros(9)
    for k in range(300):
        inputs = {"tau_g": rng.normal(0.0, 0.1, 9), "tau_m": rng.normal(0.0, 0.05, 9),
                  "tau_ff": rng.normal(0.0, 0.1, 9)}
        out, expected = s.output(0.0, state, inputs), oracles.suppresser_output(s, inputs, expected_state)
        for port in expected:
            np.testing.assert_allclose(out[port], expected[port], rtol=1e-13, atol=1e-15)
        state = s.update(0.0, state, inputs)
        expected_state = oracles.suppresser_update(s, expected_state, inputs, 0.001)
        np.testing.assert_allclose(state, expected_state, rtol=1e-13, atol=1e-16)
