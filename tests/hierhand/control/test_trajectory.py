"""Waypoint trajectories: waypoints hit, holds outside, minimum-jerk velocity."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from hierhand.control import Trajectory

from . import oracles

WAYPOINTS = [
    (0.1, 0.03, 0.06, 3.0),
    (0.4, 0.035, 0.07, 2.8),
    (0.5, 0.02, 0.075, 3.1),
    (1.0, 0.025, 0.05, 3.3),
]


@st.composite
def trajectories(draw):
    n = draw(st.integers(2, 5))
    gaps = draw(st.lists(st.floats(0.01, 1.0), min_size=n - 1, max_size=n - 1))
    t = draw(st.floats(-1.0, 1.0)) + np.concatenate([[0.0], np.cumsum(gaps)])
    poses = draw(st.lists(st.tuples(*[st.floats(-0.1, 0.1)] * 2, st.floats(-4, 4)), min_size=n, max_size=n))
    mode = draw(st.sampled_from(["linear", "minjerk"]))
    return Trajectory([(ti, *p) for ti, p in zip(t, poses)], mode)


@pytest.mark.parametrize("mode", ["linear", "minjerk"])
def test_hits_every_waypoint_and_holds_outside(mode):
    traj = Trajectory(WAYPOINTS, mode)
    for t, *pose in WAYPOINTS:
        np.testing.assert_allclose(traj.sample(t), pose, atol=1e-15)
    np.testing.assert_array_equal(traj.sample(-5.0), WAYPOINTS[0][1:])
    np.testing.assert_array_equal(traj.sample(0.0999), WAYPOINTS[0][1:])
    np.testing.assert_array_equal(traj.sample(1.0001), WAYPOINTS[-1][1:])
    np.testing.assert_array_equal(traj.sample(1e6), WAYPOINTS[-1][1:])
    for t in (-5.0, 0.0999, 1.0, 1.0001, 1e6):
        np.testing.assert_array_equal(traj.velocity(t), np.zeros(3))


def test_times_and_duration():
    traj = Trajectory(WAYPOINTS)
    np.testing.assert_array_equal(traj.times, [0.1, 0.4, 0.5, 1.0])
    assert traj.duration == pytest.approx(0.9)
    np.testing.assert_array_equal(traj.points, np.array(WAYPOINTS)[:, 1:])
    assert traj.interpolation == "minjerk"


def test_minjerk_profile_and_its_rate():
    """On the unit segment from 0 to 1 the trajectory is the blend s(tau) itself."""
    unit = Trajectory([(0.0, 0.0, 0.0, 0.0), (1.0, 1.0, 1.0, 1.0)])
    for tau in np.linspace(0, 1, 11):
        np.testing.assert_allclose(unit.sample(tau), 10 * tau**3 - 15 * tau**4 + 6 * tau**5, atol=1e-15)
        np.testing.assert_allclose(unit.velocity(tau), 30 * tau**2 * (1 - tau) ** 2 if tau < 1 else 0.0, atol=1e-14)
    assert unit.sample(0.5).tolist() == [0.5] * 3
    assert unit.velocity(0.5) == pytest.approx([1.875] * 3)


def test_minjerk_is_at_rest_at_every_waypoint():
    traj = Trajectory(WAYPOINTS, "minjerk")
    for t, *_ in WAYPOINTS:
        np.testing.assert_allclose(traj.velocity(t), 0.0, atol=1e-15)
        np.testing.assert_allclose(traj.velocity(t - 1e-9), 0.0, atol=1e-9)
        np.testing.assert_allclose(traj.velocity(t + 1e-9), 0.0, atol=1e-9)


def test_minjerk_segment_follows_the_closed_form():
    traj = Trajectory([(0.0, 0.0, 0.0, 0.0), (2.0, 1.0, -2.0, 0.5)])
    tau = 0.3
    s = 10 * tau**3 - 15 * tau**4 + 6 * tau**5
    np.testing.assert_allclose(traj.sample(0.6), s * np.array([1.0, -2.0, 0.5]), atol=1e-15)
    ds = 30 * tau**2 * (1 - tau) ** 2 / 2.0
    np.testing.assert_allclose(traj.velocity(0.6), ds * np.array([1.0, -2.0, 0.5]), atol=1e-15)


def test_linear_segments_move_at_constant_speed():
    traj = Trajectory(WAYPOINTS, "linear")
    v = (np.array(WAYPOINTS[1][1:]) - np.array(WAYPOINTS[0][1:])) / 0.3
    for t in (0.1, 0.2, 0.35, 0.3999):
        np.testing.assert_allclose(traj.velocity(t), v, rtol=1e-12)
    np.testing.assert_allclose(traj.sample(0.25), np.mean([WAYPOINTS[0][1:], WAYPOINTS[1][1:]], axis=0), atol=1e-15)


@settings(max_examples=200)
@given(trajectories(), st.floats(0.0, 1.0))
def test_velocity_matches_finite_differences(traj, frac):
    t = traj.times[0] + frac * traj.duration
    h = 1e-7
    gaps = np.abs(traj.times - t)
    assume(np.min(gaps) > 10 * h)
    numeric = (traj.sample(t + h) - traj.sample(t - h)) / (2 * h)
    scale = 1.0 + np.max(np.abs(traj.points))
    np.testing.assert_allclose(traj.velocity(t), numeric, atol=1e-5 * scale / np.min(np.diff(traj.times)))


@settings(max_examples=100)
@given(trajectories(), st.floats(0.0, 1.0))
def test_samples_stay_between_neighbouring_waypoints(traj, frac):
    t = traj.times[0] + frac * traj.duration
    i = min(int(np.searchsorted(traj.times, t, side="right")) - 1, len(traj.times) - 2)
    lo = np.minimum(traj.points[i], traj.points[i + 1])
    hi = np.maximum(traj.points[i], traj.points[i + 1])
    p = traj.sample(t)
    assert np.all(p >= lo - 1e-12) and np.all(p <= hi + 1e-12)


def test_a_single_waypoint_is_held_forever():
    traj = Trajectory([(0.2, 1.0, 2.0, 3.0)])
    assert traj.duration == 0.0
    for t in (-1.0, 0.2, 5.0):
        np.testing.assert_array_equal(traj.sample(t), [1.0, 2.0, 3.0])
        np.testing.assert_array_equal(traj.velocity(t), np.zeros(3))


def test_samples_are_copies():
    traj = Trajectory(WAYPOINTS)
    traj.sample(0.0)[0] = 99.0
    traj.times[0] = 99.0
    np.testing.assert_array_equal(traj.sample(0.0), WAYPOINTS[0][1:])


@pytest.mark.parametrize(
    "waypoints, message",
    [
        ([(0.0, 0, 0, 0), (0.5, 0, 0, 0), (0.5, 1, 1, 1)], r"waypoint 2: t = 0.5 is not after waypoint 1"),
        ([(0.0, 0, 0, 0), (1.0, 0, 0, 0), (0.9, 1, 1, 1)], r"waypoint 2"),
        ([(1.0, 0, 0, 0), (0.0, 0, 0, 0)], r"waypoint 1"),
        ([], r"non-empty"),
        ([(0.0, 0.0, 0.0)], r"\(t, x, y, phi\)"),
        ([(0.0, 0, 0, 0), (1.0, 0, float("nan"), 0)], r"waypoint 1 is not finite"),
    ],
)
def test_bad_waypoints_are_rejected_naming_the_index(waypoints, message):
    with pytest.raises(ValueError, match=message):
        Trajectory(waypoints)


def test_unknown_interpolation_is_rejected():
    with pytest.raises(ValueError, match="cubic"):
        Trajectory(WAYPOINTS, "cubic")


def test_from_config():
    a = Trajectory.from_config({"waypoints": WAYPOINTS, "interpolation": "linear"})
    assert a.interpolation == "linear"
    np.testing.assert_array_equal(a.times, Trajectory(WAYPOINTS).times)
    b = Trajectory.from_config([list(w) for w in WAYPOINTS])
    assert b.interpolation == "minjerk"
    with pytest.raises(ValueError, match="speed"):
        Trajectory.from_config({"waypoints": WAYPOINTS, "speed": 2})
    with pytest.raises(ValueError, match="needs waypoints"):
        Trajectory.from_config({"interpolation": "linear"})


@pytest.mark.parametrize("mode", ["linear", "minjerk"])
def test_samples_and_velocities_match_the_oracle(mode):
    """To the bit, but for the minimum-jerk rate's (1 - tau)^2, which the oracle takes
    with pow and the compiled law as a product."""
    rng = np.random.default_rng(8)
    for _ in range(200):
        n = int(rng.integers(1, 6))
        t = rng.uniform(-1.0, 1.0) + np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 1.0, n - 1))])
        waypoints = np.column_stack([t, rng.uniform(-0.1, 0.1, (n, 2)), rng.uniform(-4.0, 4.0, n)])
        traj = Trajectory(waypoints, mode)
        for when in np.concatenate([rng.uniform(t[0] - 0.5, t[-1] + 0.5, 40), t, np.nextafter(t, -np.inf)]):
            np.testing.assert_array_equal(traj.sample(when), oracles.trajectory_sample(waypoints, mode, when))
            np.testing.assert_allclose(traj.velocity(when), oracles.trajectory_velocity(waypoints, mode, when),
                                       rtol=1e-15, atol=0)


@pytest.mark.parametrize("waypoints", [WAYPOINTS, WAYPOINTS[:1]])
def test_a_nan_time_gives_nan(waypoints):
    traj = Trajectory(waypoints)
    assert np.all(np.isnan(traj.sample(float("nan")))) and np.all(np.isnan(traj.velocity(float("nan"))))
