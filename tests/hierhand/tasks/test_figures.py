"""What the paper's figures draw: one line where the suppresser changes nothing, the
object's target as the fingertip plans imply it, the task's phases on the time axes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

import blocks
from hierhand.tasks.figures import _object_target, _phases, _torque_axes
from hierhand.tasks.reproduce import summarize

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def runs():
    return {task: blocks.simulate(blocks.load_diagram(ROOT / "diagrams" / f"{task}.yaml"))
            for task in ("grasp", "manipulate", "regrasp", "regrasp_unsuppressed")}


def test_a_grasp_torque_the_suppresser_leaves_alone_is_one_line_not_two(runs):
    ax = Figure().add_subplot()
    _torque_axes(ax, runs["grasp"], 3, "Fig. 10")
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["grasp torque (reflex; the suppresser changes it by < 0.1 %)", "manipulation torque (PD)"]
    anchor = ax.get_legend().get_bbox_to_anchor().transformed(ax.transAxes.inverted())
    assert anchor.x0 > 1.0  # right of the axes, off the traces


def test_the_object_target_follows_the_fingertip_plans_to_the_summarys_target_pose(runs):
    run = runs["manipulate"]
    trajectories = run.info["parameters"]["ctrl.manip"]["trajectories"]
    t, target = _object_target(run, trajectories)
    np.testing.assert_allclose(target[-1], summarize(runs)["manipulation"]["target_pose"], atol=1e-12)
    first = min(w["waypoints"][0][0] for w in trajectories.values())
    assert np.ptp(target[t <= first], axis=0).max() == 0.0  # held until the plans start
    moving = target[(t > first) & (t < 0.8)]
    assert np.all(np.abs(np.diff(moving[:, 0])) > 0)  # then on the way, not a step at t = 0


def test_the_tasks_phases_are_marked_on_a_figures_axes(runs):
    ax = Figure().add_subplot()
    ax.plot([0, 1], [0, 1])
    _phases([ax], runs["regrasp"])
    words = " | ".join(t.get_text() for t in ax.texts)
    assert "object on its support" in words and "middle finger moving" in words and "forefinger moving" in words
