"""Task measures on hand-made signals with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from blocks import Results
from hierhand.tasks.metrics import grasp_summary, regrasp_summary, rigid_target


def test_rigid_target_recovers_a_known_motion():
    pose0 = np.array([0.01, 0.06, 0.2])
    tips0 = np.array([[-0.03, 0.061], [0.032, 0.058]])
    angle, shift = -0.3, np.array([0.004, -0.002])
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    tips1 = (tips0 - pose0[:2]) @ rot.T + pose0[:2] + shift
    np.testing.assert_allclose(rigid_target(tips0, tips1, pose0), [*(pose0[:2] + shift), 0.2 + angle], atol=1e-12)


def fake_results(t, ratio, contact, obj):
    return Results({"plant.ratio": (t, ratio), "plant.contact": (t, contact), "plant.obj": (t, obj)}, {})


def test_grasp_summary_measures_peak_recovery_and_steady_ratio():
    t = np.arange(0, 1.0001, 0.001)
    ratio = np.full((t.size, 3), 0.5)
    ratio[:, 2] = 0.0
    bump = (t >= 0.5) & (t < 0.56)
    ratio[bump, 1] = 0.8
    contact = np.tile([1.0, 1.0, 0.0], (t.size, 1))
    obj = np.tile([0.0, 0.06, 0.0], (t.size, 1))
    obj[t >= 0.5, 1] = 0.059
    s = grasp_summary(fake_results(t, ratio, contact, obj), 0.5)
    assert s["peak_ratio"] == 0.8
    assert s["recovery_time_s"] == pytest.approx(0.06)
    assert s["steady_ratio_max"] == 0.5
    assert s["object_displacement_m"] == pytest.approx(0.001)
    assert s["object_dropped"] is False


def test_regrasp_summary_times_and_a_drop():
    t = np.arange(0, 1.0001, 0.001)
    contact = np.tile([1.0, 1.0, 0.0], (t.size, 1))
    contact[t >= 0.3, 2] = 1.0
    contact[t >= 0.55, 1] = 0.0
    contact[t >= 0.9, :] = 0.0
    obj = np.tile([0.0, 0.06, 0.0], (t.size, 1))
    s = regrasp_summary(fake_results(t, np.zeros((t.size, 3)), contact, obj))
    assert s == {"middle_contact_time_s": pytest.approx(0.3), "fore_separation_time_s": pytest.approx(0.55),
                 "object_dropped": True}
