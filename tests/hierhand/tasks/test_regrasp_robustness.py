"""The re-grasp holds over the corners of the audited parameter ranges, not only at the
shipped values (the full 300-point experiment is benchmarks/robustness.py)."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

import blocks
from hierhand.tasks.summaries import regrasp_events, regrasp_succeeded, regrasp_summary
from hierhand.tasks.reproduce import withdrawal

DIAGRAMS = Path(__file__).resolve().parents[3] / "diagrams"
CORNERS = list(itertools.product((0.24, 0.36), (0.8, 1.2), (0.8, 1.2), (0.9, 1.1)))
"""Object mass (kg) and factors on the PD's kp, the suppresser's S_b and the friction."""


def corner_overrides(mass: float, kp: float, s_b: float, friction: float) -> dict:
    return {"plant.object.mass": mass, "plant.contact.mu_s": 1.0 * friction, "plant.contact.mu_d": 0.9 * friction,
            "manip.kp": 1.0 * kp, "suppress.S_b": 0.1 * s_b}


@pytest.mark.parametrize("mass, kp, s_b, friction", CORNERS)
def test_regrasp_succeeds_with_the_suppresser_and_not_without(mass, kp, s_b, friction):
    overrides = corner_overrides(mass, kp, s_b, friction)
    run = blocks.simulate(blocks.load_diagram(DIAGRAMS / "regrasp.yaml", overrides=overrides))
    summary = regrasp_summary(run, withdrawal(run.info["parameters"]))
    assert regrasp_succeeded(summary), summary
    assert summary["grasp_vs_manipulation_correlation"] < 0  # Fig. 14: the grasp torque falls as tau_m grows
    without = regrasp_events(blocks.simulate(blocks.load_diagram(DIAGRAMS / "regrasp_unsuppressed.yaml",
                                                                 overrides=overrides)))
    assert without["fore_separation_time_s"] is None and not without["object_dropped"]
