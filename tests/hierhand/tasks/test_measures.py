"""The hand's sweep measures: declared in pyproject.toml under ``blocks.measures``, parsed and
checked as metrics, and computed on hand-made Results.

The tests register the measures that pyproject.toml declares, as installing the package
does, so that they do not depend on the installed metadata being current; one test
compares that metadata with pyproject.toml once it has the group.
"""

from __future__ import annotations

import importlib
import tomllib
from importlib.metadata import entry_points
from pathlib import Path

import numpy as np
import pytest

from blocks import Results, load_diagram
from blocks.sweep import SweepError, parse_metric, register_measure, unregister_measure
from blocks.sweep.measures import ENTRY_POINT_GROUP

ROOT = Path(__file__).resolve().parents[3]
HAND_MEASURES = ("separation_time", "object_dropped", "peak_ratio", "recovery_time")


def declared() -> dict[str, str]:
    """The ``blocks.measures`` entry points pyproject.toml declares: name -> 'module:attr'."""
    with open(ROOT / "pyproject.toml", "rb") as f:
        project = tomllib.load(f)["project"]
    return project["entry-points"].get(ENTRY_POINT_GROUP, {})


def target(value: str):
    module, _, attr = value.partition(":")
    return getattr(importlib.import_module(module), attr)


@pytest.fixture(autouse=True)
def hand_measures():
    """The declared measures, registered as the install registers them."""
    for name, value in declared().items():
        register_measure(name, target(value))
    yield
    for name in declared():
        unregister_measure(name)


def test_pyproject_declares_the_hand_measures_and_each_imports_as_a_checked_callable():
    assert sorted(declared()) == sorted(HAND_MEASURES)
    for name, value in declared().items():
        measure = target(value)
        assert value.startswith("hierhand.tasks.measures:") and callable(measure), name
        assert callable(measure.check), name


def test_the_installed_metadata_matches_pyproject():
    installed = {ep.name: ep.value for ep in entry_points(group=ENTRY_POINT_GROUP)}
    if not installed:
        pytest.skip("the installed metadata predates the blocks.measures group: reinstall (pip install -e .)")
    assert {k: v for k, v in installed.items() if k in HAND_MEASURES} == declared()


def test_task_measures_parse():
    assert parse_metric("sep=separation_time").kind == "separation_time"
    assert parse_metric("p=peak_ratio(0.5)").args == (0.5,)
    assert parse_metric("r=recovery_time").args == ()


@pytest.mark.parametrize("text, message", [
    ("m=separation_time(1)", "separation_time takes no arguments"),
    ("m=peak_ratio(1, 2)", "peak_ratio takes at most one argument, the disturbance time"),
])
def test_wrong_arguments_are_refused(text, message):
    with pytest.raises(SweepError, match=message):
        parse_metric(text)


def test_object_dropped_on_hand_made_results():
    t = np.array([0.0, 1.0])
    contact = np.array([[1.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    obj = np.array([[0.0, 0.1, 0.0], [0.0, 0.1, 0.0]])
    r = Results({"plant.contact": (t, contact), "plant.obj": (t, obj)},
                {"status": "complete", "block_types": {"plant": "HandPlant"}})
    assert parse_metric("d=object_dropped").evaluate(r, None) == 1.0


def test_a_hand_measure_on_a_diagram_without_the_plant_signals_is_refused():
    with pytest.raises(SweepError, match="--metric m=separation_time: a hand task needs its plant: a HandPlant"):
        parse_metric("m=separation_time").check(load_diagram(ROOT / "diagrams" / "toy.yaml"))
    unlogged = load_diagram(ROOT / "diagrams" / "regrasp.yaml", overrides={})
    unlogged.log = [entry for entry in unlogged.log if entry.signal != "plant.contact"]
    with pytest.raises(SweepError, match="--metric m=separation_time: the signal plant.contact is not logged"):
        parse_metric("m=separation_time").check(unlogged)


def test_peak_ratio_takes_the_disturbance_from_a_push_block_or_needs_it():
    parse_metric("p=peak_ratio").check(load_diagram(ROOT / "diagrams" / "grasp.yaml"))
    regrasp = load_diagram(ROOT / "diagrams" / "regrasp.yaml")
    parse_metric("p=peak_ratio(0.5)").check(regrasp)
    with pytest.raises(SweepError, match=r"needs the disturbance time: write peak_ratio\(T\)"):
        parse_metric("p=peak_ratio").check(regrasp)


def test_a_sweep_of_the_regrasp_task_records_the_separation_time(tmp_path):
    import csv

    from hierhand.cli import main

    out = tmp_path / "sweep"
    assert main(["sweep", str(ROOT / "diagrams" / "regrasp.yaml"), "-o", str(out), "--grid",
                 "ctrl.suppress.S_b=0.01,0.05", "--metric", "sep=separation_time", "--metric", "dropped=object_dropped",
                 "--serial", "-q"]) == 0
    with open(out / "sweep.csv", newline="") as f:
        rows = {r["ctrl.suppress.S_b"]: r for r in csv.DictReader(f)}
    assert all(r["status"] == "ok" and r["dropped"] == "0.0" for r in rows.values())
    assert 0 < float(rows["0.01"]["sep"]) < float(rows["0.05"]["sep"])
