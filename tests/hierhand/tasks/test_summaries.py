"""Task summaries on hand-made signals with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from blocks import Results
from hierhand.tasks.summaries import grasp_summary, regrasp_events, regrasp_succeeded, regrasp_summary, rigid_target


def test_rigid_target_recovers_a_known_motion():
    pose0 = np.array([0.01, 0.06, 0.2])
    tips0 = np.array([[-0.03, 0.061], [0.032, 0.058]])
    angle, shift = -0.3, np.array([0.004, -0.002])
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    tips1 = (tips0 - pose0[:2]) @ rot.T + pose0[:2] + shift
    np.testing.assert_allclose(rigid_target(tips0, tips1, pose0), [*(pose0[:2] + shift), 0.2 + angle], atol=1e-12)


TASK_INFO = {"block_types": {"plant": "HandPlant", "reflex": "GraspReflex", "manip": "ManipulationPD",
                             "suppress": "Suppresser"}}
"""What run.json says of a task diagram's blocks (the summaries find them by type)."""


def fake_results(t, ratio, contact, obj):
    return Results({"plant.ratio": (t, ratio), "plant.contact": (t, contact), "plant.obj": (t, obj)}, TASK_INFO)


def test_grasp_summary_measures_peak_recovery_and_steady_ratio():
    t = np.arange(0, 1.0001, 0.001)
    ratio = np.full((t.size, 3), 0.5)
    ratio[:, 2] = 0.0
    bump = (t >= 0.5) & (t < 0.56)
    ratio[bump, 1] = 0.8
    contact = np.tile([1.0, 1.0, 0.0], (t.size, 1))
    obj = np.tile([0.0, 0.06, 0.0], (t.size, 1))
    obj[t >= 0.5, 1] = 0.059
    s = grasp_summary(fake_results(t, ratio, contact, obj), 0.5, handover_time=0.1)
    assert s["peak_ratio"] == 0.8
    assert s["recovery_time_s"] == pytest.approx(0.06)
    assert s["steady_ratio_max"] == 0.5
    assert s["closing_peak_ratio"] == 0.5
    assert s["object_displacement_m"] == pytest.approx(0.001)
    assert s["object_dropped"] is False


def test_regrasp_events_times_and_a_drop():
    t = np.arange(0, 1.0001, 0.001)
    contact = np.tile([1.0, 1.0, 0.0], (t.size, 1))
    contact[t >= 0.3, 2] = 1.0
    contact[t >= 0.55, 1] = 0.0
    contact[t >= 0.9, :] = 0.0
    obj = np.tile([0.0, 0.06, 0.0], (t.size, 1))
    s = regrasp_events(fake_results(t, np.zeros((t.size, 3)), contact, obj))
    assert s == {"middle_contact_time_s": pytest.approx(0.3), "fore_separation_time_s": pytest.approx(0.55),
                 "fore_stays_off": True, "object_dropped": True}


def regrasp_results(grasp_torque, touch_again=False):
    """A re-grasp whose forefinger lets go at 0.55 s; its MP joint's applied grasp torque is
    ``grasp_torque(t)`` and its manipulation torque -(t - 0.4) during the withdrawal."""
    t = np.arange(0, 1.0001, 0.001)
    contact = np.tile([1.0, 1.0, 0.0], (t.size, 1))
    contact[t >= 0.3, 2] = 1.0
    contact[t >= 0.55, 1] = 0.0
    if touch_again:
        contact[t >= 0.8, 1] = 1.0
    obj = np.tile([0.0, 0.06, 0.0], (t.size, 1))
    tau_g = np.zeros((t.size, 9))
    tau_g[:, 3] = np.where(t < 0.55, grasp_torque(t), 0.0)
    t_m = t[::10]
    tau_m = np.zeros((t_m.size, 9))
    tau_m[:, 3] = -np.clip(t_m - 0.4, 0.0, 0.3)
    reflex = tau_g.copy()
    reflex[:, 0] = 0.1  # the thumb's MP joint: 0.1 N m from the reflex, 0.08 applied after 0.7 s
    tau_g[:, 0] = np.where(t >= 0.7, 0.08, 0.1)
    reflex[:, 1] = 0.001  # too small a torque to judge suppression by
    signals = {"plant.ratio": (t, np.zeros((t.size, 3))), "plant.contact": (t, contact), "plant.obj": (t, obj),
               "suppress.tau_g_eff": (t, tau_g), "manip.tau_m": (t_m, tau_m), "reflex.tau_g": (t, reflex)}
    return Results(signals, TASK_INFO)


def test_regrasp_summary_measures_the_grasp_torque_against_the_manipulation_torque():
    falling = regrasp_summary(regrasp_results(lambda t: 0.2 - 0.5 * np.clip(t - 0.4, 0, None)), (0.4, 0.7))
    assert falling["fore_grasp_torque_at_withdrawal_Nm"] == pytest.approx(0.2)
    assert falling["fore_grasp_torque_peak_Nm"] == pytest.approx(0.2)
    assert falling["fore_grasp_torque_last_Nm"] == pytest.approx(0.2 - 0.5 * 0.144)  # CONTACT_FADE before 0.55 s
    assert falling["grasp_vs_manipulation_correlation"] < -0.99
    assert falling["holding_grasp_torque_kept"] == pytest.approx(0.8)
    assert regrasp_succeeded(falling)
    rising = regrasp_summary(regrasp_results(lambda t: 0.2 + np.clip(t - 0.4, 0, None)), (0.4, 0.7))
    assert rising["grasp_vs_manipulation_correlation"] > 0.99
    assert rising["fore_grasp_torque_peak_Nm"] == pytest.approx(0.344)


def test_a_regrasp_fails_when_the_forefinger_comes_back_or_leaves_outside_its_withdrawal():
    back = regrasp_summary(regrasp_results(lambda t: 0.2 + 0 * t, touch_again=True), (0.4, 0.7))
    assert back["fore_stays_off"] is False and not regrasp_succeeded(back)
    early = regrasp_summary(regrasp_results(lambda t: 0.2 + 0 * t), (0.6, 0.9))
    assert early["grasp_vs_manipulation_correlation"] is None  # no sample between 0.6 s and the separation
    assert not regrasp_succeeded(early)
