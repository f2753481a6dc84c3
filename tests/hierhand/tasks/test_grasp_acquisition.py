"""The fingers close on the object from the shipped start within the safety ratio, with the
task's 3 N minimum squeeze and with the reflex's default 1 N; only the 3 N carry the
hand-over."""

from __future__ import annotations

from pathlib import Path

import pytest

import blocks
from hierhand.control.grasp_reflex import GraspReflex
from hierhand.tasks.summaries import TaskBlocks, grasp_summary, handover_time

DIAGRAMS = Path(__file__).resolve().parents[3] / "diagrams"
DEFAULT_MIN_FORCE = GraspReflex.parameters()["min_force"].default


@pytest.mark.parametrize("min_force", [DEFAULT_MIN_FORCE, 3.0])
def test_the_grasp_closes_without_slipping(min_force):
    run = blocks.simulate(blocks.load_diagram(DIAGRAMS / "grasp.yaml", overrides={"ctrl.reflex.min_force": min_force}))
    summary = grasp_summary(run, 0.5, handover_time=handover_time(run.info["parameters"], TaskBlocks.of_run(run)))
    assert summary["closing_peak_ratio"] <= 0.6  # while the support carries the object
    assert summary["object_dropped"] == (min_force < 2.45)  # m g / (2 x 0.6): 1 N lets the hand-over slip
    t, fn = run["plant.fn"]
    before = t < 0.1
    assert fn[before][-1, :2].min() == pytest.approx(min_force, rel=0.05)  # both fingers squeeze at min_force


def test_the_task_squeeze_carries_the_hand_over_within_the_safety_ratio():
    """3 N per finger is m g / (2 x 0.6) = 2.45 N and a margin: the hand-over stays under
    0.6; with 1 N the ratio climbs to the sliding limit and the object slips out."""
    ratios = {}
    for min_force in (DEFAULT_MIN_FORCE, 3.0):
        run = blocks.simulate(blocks.load_diagram(DIAGRAMS / "grasp.yaml", overrides={"ctrl.reflex.min_force": min_force}))
        t, ratio = run["plant.ratio"]
        ratios[min_force] = ratio[(t >= 0.1) & (t < 0.5)][:, :2].max()
    assert ratios[3.0] <= 0.6 < ratios[DEFAULT_MIN_FORCE]
