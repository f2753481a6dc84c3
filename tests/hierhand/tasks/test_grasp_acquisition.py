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


FIXED = {"ctrl.reflex.squeeze_from_weight": False, "ctrl.reflex.catch_up": 0.0}
"""The reflex's smallest squeeze as given, not raised to the weight's share, and integral
control alone (no catch-up on a shortfall)."""


@pytest.mark.parametrize("min_force", [DEFAULT_MIN_FORCE, 3.0])
def test_the_grasp_closes_without_slipping(min_force):
    run = blocks.simulate(blocks.load_diagram(DIAGRAMS / "grasp.yaml",
                                              overrides={"ctrl.reflex.min_force": min_force, **FIXED}))
    summary = grasp_summary(run, 0.5, handover_time=handover_time(run.info["parameters"], TaskBlocks.of_run(run)))
    # while the support carries the object: inside the friction cone (mu_s 1), above the safety
    # ratio only while a contact's first anchors settle (about 1 ms at the plant's 0.1 ms)
    assert summary["closing_peak_ratio"] < 1.0
    t, ratio = run["plant.ratio"]
    closing = ratio[t < 0.1][:, :2]
    assert (closing > 0.6).any(axis=1).sum() * 1e-4 < 2e-3
    # at or above m g / (2 x 0.6) = 2.45 N the hand-over holds (1 N: see the next test)
    assert summary["object_dropped"] is False or min_force < 2.45
    t, fn = run["plant.fn"]
    before = t < 0.1
    assert fn[before][-1, :2].min() == pytest.approx(min_force, rel=0.05)  # both fingers squeeze at min_force


def test_the_task_squeeze_carries_the_hand_over_within_the_safety_ratio():
    """3 N per finger is m g / (2 x 0.6) = 2.45 N and a margin: the hand-over stays under
    0.6; with 1 N the ratio climbs to the sliding limit and the object slips. The weight's
    share alone (2.6 N at the ratio target, the task diagrams' reflex over a 1 N floor) holds
    the object but takes the ratio over 0.6 at the hand-over: hence the diagrams' 3 N floor."""
    ratios = {}
    for name, overrides in (("1 N", {"ctrl.reflex.min_force": DEFAULT_MIN_FORCE, **FIXED}),
                            ("3 N", {"ctrl.reflex.min_force": 3.0, **FIXED}),
                            ("weight", {"ctrl.reflex.min_force": DEFAULT_MIN_FORCE})):
        run = blocks.simulate(blocks.load_diagram(DIAGRAMS / "grasp.yaml", overrides=overrides))
        t, ratio = run["plant.ratio"]
        ratios[name] = ratio[(t >= 0.1) & (t < 0.5)][:, :2].max()
    assert ratios["3 N"] <= 0.6 < ratios["1 N"]
    assert 0.6 < ratios["weight"] < ratios["1 N"]
