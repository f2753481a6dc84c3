"""The suppresser decides the re-grasp, over a sample of the spread and not only at the
shipped point (the 300-point experiment is benchmarks/robustness.py): with it the
forefinger separates during its withdrawal and stays off while thumb and middle finger
keep the object; with only the sigmoid switched off, it never separates."""

from __future__ import annotations

from pathlib import Path

import pytest

import blocks
from hierhand.tasks.robustness import by_name, regrasp_outcome, unsuppressed_outcome
from hierhand.tasks.summaries import TaskBlocks
from hierhand.tasks.variations import carry, sample

DIAGRAMS = Path(__file__).resolve().parents[3] / "diagrams"
REGRASP = DIAGRAMS / "regrasp.yaml"
POINTS = [v for v in sample(60, 24) if v.sees_slip][:12]
"""Points of the spread where the reflex can see slip (its safety ratio below mu_d)."""
SIGMOID_OFF = {"S_b so large that the factor is 1": {"suppress.S_b": 100.0},
               "enabled: false": {"suppress.enabled": False}}


ROLES = TaskBlocks.of_diagram(blocks.load_diagram(REGRASP))


@pytest.fixture(scope="module")
def carried():
    parameters = blocks.load_diagram(REGRASP).parameters()
    return [carry(parameters, v, False, ROLES) for v in POINTS]


@pytest.mark.parametrize("point", range(len(POINTS)))
def test_with_the_suppresser_the_forefinger_lets_go_and_the_others_keep_the_object(carried, point):
    run = blocks.simulate(blocks.load_diagram(REGRASP, overrides=carried[point]))
    assert regrasp_outcome(run) == "", POINTS[point]


@pytest.mark.parametrize("off", SIGMOID_OFF)
@pytest.mark.parametrize("point", range(len(POINTS)))
def test_with_only_the_sigmoid_switched_off_the_forefinger_never_lets_go(carried, point, off):
    run = blocks.simulate(blocks.load_diagram(REGRASP, overrides={**carried[point], **by_name(ROLES, SIGMOID_OFF[off])}))
    assert unsuppressed_outcome(run) == "", POINTS[point]


def test_the_unsuppressed_diagram_differs_from_the_suppressed_in_the_suppresser_alone():
    with_it, without = (blocks.load_diagram(DIAGRAMS / name) for name in ("regrasp.yaml", "regrasp_unsuppressed.yaml"))
    assert [str(c) for c in with_it.connections] == [str(c) for c in without.connections]
    assert [e.signal for e in with_it.log] == [e.signal for e in without.log]
    a, b = with_it.parameters(), without.parameters()
    suppresser = ROLES.block("suppress")
    assert b.pop(suppresser) == {**a.pop(suppresser), "enabled": False}
    assert a == b
