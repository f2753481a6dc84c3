"""Named measures: registered from Python or through the ``blocks.measures`` entry points,
their arguments checked against their signatures, their own checks run before a sweep, and
their values computed in a sweep (also on Dask workers)."""

from __future__ import annotations

import csv
from importlib.metadata import EntryPoint
from pathlib import Path

import numpy as np
import pytest

from blocks import Results, load_diagram, plugins
from blocks.sweep import SweepError, grid_points, parse_metric, register_measure, registered_measures, \
    run_sweep, unregister_measure
from blocks.sweep import measures as registry
from blocks.sweep.measures import checked_by, require_logged

ROOT = Path(__file__).resolve().parents[3]
TOY = ROOT / "diagrams" / "toy.yaml"


def _needs_plant_y(diagram, level: float = 0.0) -> None:
    require_logged(diagram, ["plant.y"])


@checked_by(_needs_plant_y)
def time_above(results, diagram, level: float = 0.0) -> float | None:
    """When plant.y first exceeds ``level`` (None: never)."""
    t, y = results["plant.y"]
    hits = np.flatnonzero(y[:, 0] > level)
    return float(t[hits[0]]) if hits.size else None


def peak_gain(results, diagram) -> float:
    """The largest plant.y times the diagram's ``prop.k``: a measure that reads a parameter."""
    return float(results["plant.y"][1].max()) * float(diagram.blocks["prop"].params["k"])


def band(results, diagram, low: float, high: float) -> bool:
    """Whether the final plant.y lies in [low, high]: two required arguments, a bool value."""
    return low <= results["plant.y"][1][-1, 0] <= high


@pytest.fixture
def test_measures():
    """time_above, peak_gain and band registered for one test."""
    for name, measure in (("time_above", time_above), ("peak_gain", peak_gain), ("band", band)):
        register_measure(name, measure)
    yield
    for name in ("time_above", "peak_gain", "band"):
        unregister_measure(name)


def toy_results() -> Results:
    t = np.array([0.0, 0.1, 0.2])
    return Results({"plant.y": (t, np.array([[0.0], [0.5], [0.8]]))}, {"status": "complete"})


def test_a_registered_measure_is_parsed_with_its_arguments(test_measures):
    metric = parse_metric("t=time_above(0.4)")
    assert metric.kind == "time_above" and metric.measure is time_above and metric.args == (0.4,)
    assert metric.evaluate(toy_results(), None) == 0.1
    assert parse_metric("t=time_above(2)").evaluate(toy_results(), None) is None
    assert parse_metric("t=time_above").evaluate(toy_results(), None) == 0.1
    assert parse_metric("b=band(0.7, 0.9)").evaluate(toy_results(), None) == 1.0
    assert "time_above" in registered_measures()


@pytest.mark.parametrize("text, message", [
    ("m=peak_gain(1)", "peak_gain takes no arguments"),
    ("m=time_above(1, 2)", "time_above takes at most one argument, the level"),
    ("m=band(1)", "band takes two arguments, the low and high"),
    ("m=band", "band takes two arguments, the low and high"),
    ("m=time_above(x)", "'x' is not a number"),
    ("m=time_abov", "unknown reducer or measure 'time_abov'; known: final, max, min, mean, first_time_above, "
                    "first_time_below, band,"),
])
def test_wrong_arguments_and_unknown_names_are_refused(test_measures, text, message):
    with pytest.raises(SweepError, match=message.replace("(", r"\(")):
        parse_metric(text)


def test_the_measures_own_check_runs_against_the_diagram(test_measures, tmp_path):
    parse_metric("t=time_above").check(load_diagram(TOY))
    unlogged = tmp_path / "toy.yaml"
    unlogged.write_text(TOY.read_text().replace("log: [plant.y]", "log: [u.y]"), encoding="utf-8")
    with pytest.raises(SweepError, match=r"^--metric t=time_above: the signal plant.y is not logged"):
        parse_metric("t=time_above").check(load_diagram(unlogged))
    parse_metric("p=peak_gain").check(load_diagram(unlogged))  # no check: nothing to refuse


def test_a_registered_measure_overrides_an_entry_point_and_unregistering_restores_it(monkeypatch):
    monkeypatch.setattr(registry, "_installed", {"time_above": peak_gain})
    assert registry.find_measure("time_above") is peak_gain
    register_measure("time_above", time_above)
    try:
        assert registry.find_measure("time_above") is time_above
    finally:
        unregister_measure("time_above")
    assert registry.find_measure("time_above") is peak_gain


def test_entry_points_of_the_group_are_loaded_and_a_broken_one_is_named(monkeypatch):
    here = __name__
    points = [EntryPoint("peak_gain", f"{here}:peak_gain", registry.ENTRY_POINT_GROUP),
              EntryPoint("missing", f"{here}:no_such_measure", registry.ENTRY_POINT_GROUP),
              EntryPoint("not_callable", f"{here}:ROOT", registry.ENTRY_POINT_GROUP)]
    asked = []

    def fake_entry_points(group):
        asked.append(group)
        return points

    monkeypatch.setattr(plugins, "entry_points", fake_entry_points)
    monkeypatch.setattr(registry, "_installed", None)
    monkeypatch.setattr(registry, "_load_errors", {})
    assert registry.find_measure("peak_gain") is peak_gain
    assert asked == ["blocks.measures"]
    with pytest.raises(SweepError, match="measure 'missing' is registered but failed to load"):
        parse_metric("m=missing")
    with pytest.raises(SweepError, match="is not callable"):
        parse_metric("m=not_callable")


def test_register_measure_refuses_what_cannot_be_called():
    with pytest.raises(TypeError, match="not callable"):
        register_measure("x", 3.0)


def _rows(out: Path) -> list[dict]:
    with open(out / "sweep.csv", newline="") as f:
        return list(csv.DictReader(f))


@pytest.mark.parametrize("mode", [{"serial": True}, {"workers": 2}], ids=["serial", "local-cluster"])
def test_run_sweep_computes_registered_measures(test_measures, tmp_path, mode):
    summary = run_sweep(TOY, grid_points({"prop.k": [1, 4]}), ["g=peak_gain", "t=time_above(0.0005)",
                                                               "y=max(plant.y)"],
                        tmp_path / "s", t_end="50 ms", progress=False, **mode)
    assert (summary.points, summary.failed, summary.skipped) == (2, 0, 0)
    rows = {r["prop.k"]: r for r in _rows(tmp_path / "s")}
    for k in ("1", "4"):
        assert rows[k]["status"] == "ok"
        assert float(rows[k]["g"]) == pytest.approx(float(rows[k]["y"]) * float(k))
    assert float(rows["4"]["t"]) < float(rows["1"]["t"])


def test_a_callable_without_results_and_diagram_is_refused_when_parsed():
    register_measure("bare", lambda results: 1.0)
    try:
        with pytest.raises(SweepError, match=r"bare is not a measure\(results, diagram, ...\)"):
            parse_metric("m=bare")
    finally:
        unregister_measure("bare")
