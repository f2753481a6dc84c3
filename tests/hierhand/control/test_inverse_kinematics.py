"""Finger and hand inverse kinematics against forward kinematics written out here."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hierhand.control import UnreachableError, finger_fk, finger_ik, finger_ik_near, hand_ik, wrap_angle
from hierhand.model import Hand

from . import oracles

angle = st.floats(-math.pi, math.pi, allow_nan=False)
length = st.floats(0.005, 0.06)
bent = st.floats(0.05, math.pi - 0.05)


def walk_finger(base, base_angle, lengths, q):
    """Tip centre and link-3 angle, by walking the links one at a time."""
    x, y = float(base[0]), float(base[1])
    heading = base_angle
    for qi, li in zip(q, lengths):
        heading += qi
        x += li * math.cos(heading)
        y += li * math.sin(heading)
    return x, y, heading


def angle_error(a, b):
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    return np.abs(np.arctan2(np.sin(d), np.cos(d)))


@pytest.fixture(scope="module")
def hand() -> Hand:
    return Hand.default()


# -- wrap ---------------------------------------------------------------------------


@given(st.floats(-50, 50))
def test_wrap_angle_lands_in_the_half_open_interval_and_keeps_the_direction(a):
    w = float(wrap_angle(a))
    assert -math.pi < w <= math.pi
    assert angle_error(w, a) < 1e-12


def test_wrap_angle_maps_both_ends_to_pi():
    assert wrap_angle(math.pi) == math.pi
    assert wrap_angle(-math.pi) == math.pi
    assert wrap_angle(3 * math.pi) == pytest.approx(math.pi)


def test_wrap_angle_just_above_pi_does_not_round_to_minus_pi():
    w = wrap_angle(3.1415926535897936)
    assert -math.pi < w <= math.pi
    assert angle_error(w, 3.1415926535897936) < 1e-15
    assert isinstance(w, float)
    assert wrap_angle(np.array([0.0, 2 * math.pi])).shape == (2,)


# -- finger IK / FK -----------------------------------------------------------------


@settings(max_examples=300)
@given(
    st.tuples(st.floats(-0.1, 0.1), st.floats(-0.1, 0.1)),
    angle,
    st.tuples(length, length, length),
    angle,
    bent,
    angle,
    st.sampled_from([1, -1]),
)
def test_ik_round_trips_through_forward_kinematics(base, base_angle, lengths, q1, q2_size, q3, elbow):
    q = np.array([q1, elbow * q2_size, q3])
    target = walk_finger(base, base_angle, lengths, q)
    sol = finger_ik(base, base_angle, lengths, *target, elbow=elbow)
    assert np.all(angle_error(sol, q) < 1e-7)
    assert np.all((sol > -math.pi) & (sol <= math.pi))
    x, y, phi = walk_finger(base, base_angle, lengths, sol)
    assert x == pytest.approx(target[0], abs=1e-12)
    assert y == pytest.approx(target[1], abs=1e-12)
    assert angle_error(phi, target[2]) < 1e-12

    other = finger_ik(base, base_angle, lengths, *target, elbow=-elbow)
    assert -elbow * other[1] > 0
    x, y, phi = walk_finger(base, base_angle, lengths, other)
    assert (x, y) == pytest.approx(target[:2], abs=1e-12)
    assert angle_error(phi, target[2]) < 1e-12


@pytest.mark.parametrize("q2", [0.0, math.pi])
def test_fully_stretched_and_folded_fingers_still_solve(q2):
    base, base_angle, lengths = (0.01, -0.02), 0.4, (0.04, 0.025, 0.012)
    q = np.array([0.3, q2, -0.7])
    target = walk_finger(base, base_angle, lengths, q)
    for elbow in (1, -1):
        sol = finger_ik(base, base_angle, lengths, *target, elbow=elbow)
        assert np.all(angle_error(sol, q) < 1e-6)


@settings(max_examples=100)
@given(st.tuples(st.floats(-0.1, 0.1), st.floats(-0.1, 0.1)), angle, st.tuples(length, length, length), st.tuples(angle, angle, angle))
def test_finger_fk_matches_the_link_walk(base, base_angle, lengths, q):
    x, y, phi = finger_fk(base, base_angle, lengths, q)
    ex, ey, ephi = walk_finger(base, base_angle, lengths, q)
    assert (x, y) == pytest.approx((ex, ey), abs=1e-14)
    assert phi == pytest.approx(ephi, abs=1e-14)


@pytest.mark.parametrize(
    "target, distance",
    [
        ((0.2, 0.0, 0.0), 0.2 - 0.01),  # far: wrist 0.19 m out, reach 0.07
        ((0.01, 0.005, 0.0), 0.005),  # too close: inside the inner radius 0.02
    ],
)
def test_unreachable_targets_name_the_distance_and_range(target, distance):
    lengths = (0.045, 0.025, 0.01)
    with pytest.raises(UnreachableError) as info:
        finger_ik((0.0, 0.0), 0.0, lengths, *target)
    err = info.value
    assert isinstance(err, ValueError)
    assert err.distance == pytest.approx(distance, rel=1e-12)
    assert (err.r_min, err.r_max) == pytest.approx((0.02, 0.07), rel=1e-12)
    message = str(err)
    assert f"{distance:.6g}" in message
    assert "0.02" in message and "0.07" in message


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"elbow": 0}, "elbow"),
        ({"lengths": (0.04, 0.0, 0.01)}, "lengths"),
        ({"lengths": (0.04, 0.02)}, "lengths"),
    ],
)
def test_finger_ik_rejects_bad_arguments(kwargs, message):
    args = {"base": (0.0, 0.0), "base_angle": 0.0, "lengths": (0.04, 0.03, 0.01), "x": 0.05, "y": 0.02, "phi": 0.0}
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        finger_ik(**args)


# -- hand IK ------------------------------------------------------------------------


hand_q = st.lists(st.floats(-1.3, 1.3), min_size=9, max_size=9).map(np.array)


@settings(max_examples=100)
@given(hand_q, st.lists(st.floats(-0.02, 0.02), min_size=9, max_size=9))
def test_hand_ik_reproduces_the_models_tip_positions(hand, q, noise):
    q[1::3] = np.where(np.abs(q[1::3]) < 0.1, 0.1, q[1::3])
    targets = hand.tip_poses(q)
    sol = hand_ik(hand, targets, q + np.array(noise))
    np.testing.assert_allclose(hand.tip_positions(sol), hand.tip_positions(q), atol=1e-12)
    np.testing.assert_allclose(sol, q, atol=1e-7)


@settings(max_examples=50)
@given(hand_q)
def test_hand_ik_picks_the_branch_nearest_the_reference(hand, q):
    q[1::3] = np.where(np.abs(q[1::3]) < 0.1, 0.1, q[1::3])
    targets = hand.tip_poses(q)
    flipped = np.concatenate(
        [
            finger_ik(f.base, f.base_angle, [link.length for link in f.links], *targets[i], elbow=-int(np.sign(q[3 * i + 1])))
            for i, f in enumerate(hand.params.fingers)
        ]
    )
    sol = hand_ik(hand, targets, flipped)
    np.testing.assert_allclose(sol, flipped, atol=1e-7)
    assert np.all(np.sign(sol[1::3]) == -np.sign(q[1::3]))
    np.testing.assert_allclose(hand.tip_positions(sol), hand.tip_positions(q), atol=1e-12)


def test_hand_ik_returns_angles_next_to_the_reference(hand):
    q = hand.q0.copy()
    shifted = q + 2 * math.pi * np.array([1, 0, -1, 0, 2, 0, -1, 1, 0])
    sol = hand_ik(hand, hand.tip_poses(q), shifted)
    np.testing.assert_allclose(sol, shifted, atol=1e-7)


def test_hand_ik_on_the_default_start_pose(hand):
    sol = hand_ik(hand, hand.tip_poses(hand.q0), hand.q0)
    np.testing.assert_allclose(sol, hand.q0, atol=1e-9)


def test_hand_ik_names_the_finger_that_cannot_reach(hand):
    targets = hand.tip_poses(hand.q0)
    targets[1, :2] = [0.5, 0.5]
    with pytest.raises(UnreachableError, match=r"^fore: .*reachable range") as info:
        hand_ik(hand, targets, hand.q0)
    assert info.value.finger == "fore"
    fore = hand.params.fingers[1]
    assert info.value.r_max == pytest.approx(fore.links[0].length + fore.links[1].length)


@pytest.mark.parametrize("targets, q_ref, message", [(np.zeros((3, 2)), np.zeros(9), "targets"), (np.zeros((3, 3)), np.zeros(8), "q_ref")])
def test_hand_ik_checks_shapes(hand, targets, q_ref, message):
    with pytest.raises(ValueError, match=message):
        hand_ik(hand, targets, q_ref)


# -- against the oracle ------------------------------------------------------------------


def test_wrap_angle_matches_the_oracle_to_the_bit():
    a = np.concatenate([np.random.default_rng(1).uniform(-50, 50, 10000), [math.pi, -math.pi, -1e-300, 0.0, -0.0]])
    np.testing.assert_array_equal(wrap_angle(a), oracles.wrap_angle(a))


def test_finger_kinematics_match_the_oracle():
    """Round-off apart: the oracle sums the links with numpy, walks the wrist distance with
    math.hypot (not libm's) and the angles with numpy's cumulative sum."""
    rng = np.random.default_rng(2)
    for _ in range(3000):
        base, base_angle = rng.uniform(-0.1, 0.1, 2), rng.uniform(-math.pi, math.pi)
        lengths, q = rng.uniform(0.005, 0.06, 3), rng.uniform(-math.pi, math.pi, 3)
        target = finger_fk(base, base_angle, lengths, q)
        np.testing.assert_allclose(target, oracles.finger_fk(base, base_angle, lengths, q), rtol=0, atol=1e-14)
        for elbow in (1, -1):
            np.testing.assert_allclose(finger_ik(base, base_angle, lengths, *target, elbow=elbow),
                                       oracles.finger_ik(base, base_angle, lengths, *target, elbow=elbow),
                                       rtol=0, atol=1e-9)


def test_finger_ik_near_matches_the_oracle(hand):
    rng = np.random.default_rng(3)
    for _ in range(3000):
        f = int(rng.integers(3))
        q = hand.q0[3 * f:3 * f + 3] + rng.normal(0.0, 0.8, 3)
        ref_q = hand.q0[3 * f:3 * f + 3] + rng.normal(0.0, 1.5, 3)
        target = hand.tip_poses(np.tile(q, 3))[f]
        np.testing.assert_allclose(finger_ik_near(hand, f, target, ref_q), oracles.finger_ik_near(hand, f, target, ref_q),
                                   rtol=0, atol=1e-9)


def test_finger_ik_near_names_the_finger_and_the_distance(hand):
    with pytest.raises(UnreachableError, match="^middle: ") as info:
        finger_ik_near(hand, 2, (1.0, 1.0, 0.0), hand.q0[6:])
    assert info.value.distance > info.value.r_max
