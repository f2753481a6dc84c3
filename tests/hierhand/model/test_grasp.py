"""A thumb-forefinger pinch under gravity holds iff the squeeze beats m g / (2 mu_s)."""

import numpy as np
import pytest

from hierhand.model import Hand

from .sim import make_plant, pinch_torques, run


def pinch_under_gravity(ratio):
    """Squeeze = ratio * m g / (2 mu_s); the weight is handed over from f_ext gradually.

    For 50 ms f_ext carries the weight while the squeeze builds, then over 100 ms it
    hands the weight to the fingers (whose torques take on their share, m g / 2 each).
    Loading a grasp before its normal force exists would start it sliding, and a sliding
    contact only recovers below mu_d, which is a different test.
    """
    plant = make_plant()
    hand = plant.hand
    m = hand.params.object.mass
    g = -hand.gravity[1]
    squeeze = ratio * m * g / (2 * hand.params.contact.mu_s)
    share = lambda t: float(np.clip((t - 0.05) / 0.1, 0.0, 1.0))  # noqa: E731
    state, logs, t = run(
        plant, plant.initial_state(), 0.4,
        lambda t: pinch_torques(hand, squeeze, share(t) * m * g / 2),
        f_ext=lambda t: [0.0, (1.0 - share(t)) * m * g, 0.0],
        kp=0.3, kd=0.003,
    )
    return plant, logs, t


@pytest.mark.parametrize("ratio", [1.1, 1.5])
def test_pinch_holds_when_the_squeeze_exceeds_the_friction_limit(ratio):
    plant, logs, t = pinch_under_gravity(ratio)
    y = logs["obj"][:, 1]
    loaded = t >= 0.15
    assert y[loaded].max() - y[loaded].min() < 0.5e-3
    assert abs(logs["obj_vel"][-1, 1]) < 2e-3
    assert abs(logs["obj"][-1, 2]) < 0.05
    assert logs["contact"][-1].tolist() == [1.0, 1.0, 0.0]
    # the fingers carry the weight with a friction ratio near 1 / ratio, inside the cone
    assert np.all(logs["ratio"][loaded][:, :2] < plant.hand.params.contact.mu_s)
    assert logs["ratio"][-1, :2] == pytest.approx(1.0 / ratio, rel=0.1)


@pytest.mark.parametrize("ratio", [0.5, 0.7])
def test_pinch_drops_the_object_when_the_squeeze_is_clearly_too_weak(ratio):
    _, logs, t = pinch_under_gravity(ratio)
    y = logs["obj"][:, 1]
    start = Hand.default().object_pose0[1]
    assert y[t <= 0.05].min() > start - 0.5e-3  # held up by f_ext at first
    assert y[-1] < start - 20e-3


def test_contact_normals_point_from_each_tip_into_the_face_it_presses():
    """Thumb presses the left face (+x), forefinger the right face (-x); the middle finger
    touches nothing, so its normal is zero."""
    _, logs, _ = pinch_under_gravity(1.5)
    normal = logs["normal"][-1].reshape(3, 2)
    np.testing.assert_allclose(normal[0], [1.0, 0.0], atol=0.05)
    np.testing.assert_allclose(normal[1], [-1.0, 0.0], atol=0.05)
    np.testing.assert_array_equal(normal[2], [0.0, 0.0])
    np.testing.assert_allclose(np.linalg.norm(normal[:2], axis=1), 1.0, rtol=1e-12)
