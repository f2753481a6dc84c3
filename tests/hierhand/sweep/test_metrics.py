"""Metric parsing, checking against a diagram, and the reducers on hand-made Results."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from blocks import Results, load_diagram
from hierhand.sweep import SweepError
from hierhand.sweep.metrics import parse_metric, parse_metrics

ROOT = Path(__file__).resolve().parents[3]


def results() -> Results:
    t = np.array([0.0, 0.1, 0.2, 0.3])
    y = np.array([[0.0, 5.0], [2.0, 4.0], [3.0, 1.0], [1.0, 0.5]])
    return Results({"plant.y": (t, y), "g.out": (t, y[:, :1])}, {"status": "complete"})


@pytest.mark.parametrize("text, value", [
    ("m=final(plant.y[1])", 0.5),
    ("m=max(plant.y[0])", 3.0),
    ("m=min(plant.y[1])", 0.5),
    ("m=mean(plant.y[0])", 1.5),
    ("m=final(g.out)", 1.0),
    ("m=first_time_above(plant.y[0], 1.5)", 0.1),
    ("m=first_time_below(plant.y[1], 2)", 0.2),
    ("m=first_time_above(plant.y[0], 10)", None),
])
def test_reducers(text, value):
    assert parse_metric(text).evaluate(results(), None) == value


def test_task_measures_parse():
    assert parse_metric("sep=separation_time").kind == "separation_time"
    assert parse_metric("p=peak_ratio(0.5)").disturbance_time == 0.5
    assert parse_metric("r=recovery_time").disturbance_time is None


def test_object_dropped_on_hand_made_results():
    t = np.array([0.0, 1.0])
    contact = np.array([[1.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    obj = np.array([[0.0, 0.1, 0.0], [0.0, 0.1, 0.0]])
    r = Results({"plant.contact": (t, contact), "plant.obj": (t, obj)}, {"status": "complete"})
    assert parse_metric("d=object_dropped").evaluate(r, None) == 1.0


@pytest.mark.parametrize("text, message", [
    ("final(plant.y)", "expected NAME="),
    ("m=median(plant.y)", "unknown reducer or measure 'median'"),
    ("m=final(plant)", "not a signal"),
    ("m=first_time_above(plant.y[0])", "takes 2 argument"),
    ("m=first_time_above(plant.y[0], abc)", "not a number"),
    ("m=separation_time(1)", "takes no arguments"),
    ("m=final(plant.y[-1])", "must be 0 or more"),
])
def test_bad_metrics_are_refused(text, message):
    with pytest.raises(SweepError, match=message):
        parse_metric(text)


def test_duplicate_names_are_refused():
    with pytest.raises(SweepError, match="used twice"):
        parse_metrics(["a=final(plant.y)", "a=max(plant.y)"])


@pytest.mark.parametrize("text, message", [
    ("m=final(nope.y)", "no block named 'nope'"),
    ("m=final(plant.z)", "has no output 'z'"),
    ("m=final(prop.y)", "not logged"),
    ("m=final(plant.y[1])", "out of range"),
    ("m=separation_time", "plant.contact is not logged"),
])
def test_metrics_are_checked_against_the_diagram(text, message):
    diagram = load_diagram(ROOT / "diagrams" / "toy.yaml")
    parse_metric("ok=final(plant.y)").check(diagram)
    with pytest.raises(SweepError, match=message):
        parse_metric(text).check(diagram)


def test_peak_ratio_takes_the_disturbance_from_a_push_block_or_needs_it():
    parse_metric("p=peak_ratio").check(load_diagram(ROOT / "diagrams" / "grasp.yaml"))
    regrasp = load_diagram(ROOT / "diagrams" / "regrasp.yaml")
    parse_metric("p=peak_ratio(0.5)").check(regrasp)
    with pytest.raises(SweepError, match="needs the disturbance time"):
        parse_metric("p=peak_ratio").check(regrasp)
