"""Metric expressions: parsing, checking against a diagram, and the reducers on hand-made Results
(measures have their own tests, in test_measures)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from blocks import Results, load_diagram
from blocks.sweep import SweepError
from blocks.sweep.metrics import parse_metric, parse_metrics

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
    ("m=final(plant.y[-1])", 0.5),  # from the end, as a plot's selection and a connection read it
])
def test_reducers(text, value):
    assert parse_metric(text).evaluate(results(), None) == value


@pytest.mark.parametrize("text, message", [
    ("final(plant.y)", "expected NAME="),
    ("m=median(plant.y)", "unknown reducer or measure 'median'"),
    ("m=final(plant)", "not a signal"),
    ("m=first_time_above(plant.y[0])", "takes 2 argument"),
    ("m=first_time_above(plant.y[0], abc)", "not a number"),
    ("m=final(plant.y[])", "not a signal"),
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
])
def test_metrics_are_checked_against_the_diagram(text, message):
    diagram = load_diagram(ROOT / "diagrams" / "toy.yaml")
    parse_metric("ok=final(plant.y)").check(diagram)
    with pytest.raises(SweepError, match=message):
        parse_metric(text).check(diagram)


def test_a_metric_knows_its_unit_where_the_diagram_or_the_measure_says():
    from blocks import loads_diagram
    from blocks.sweep.measures import register_measure, unregister_measure

    d = loads_diagram("""
time: {t_end: 2 ms}
blocks:
  src: {type: "python:tests.blocks.blockdefs:Labelled", period: 1 ms, params: {labels: [x, y, theta], units: [m, m, rad]}}
  k: {type: Constant, params: {value: 1.0}}
log: [src.y, k.y]
""", trust=True)

    def spread(results, diagram):
        return 0.0

    spread.unit = "mm"
    register_measure("spread_for_test", spread)
    try:
        units = {m.name: m.unit(d) for m in parse_metrics(["a=max(src.y[2])", "b=final(src.y[0])",
                                                           "c=first_time_above(src.y[1], 0.5)", "d=final(k.y)",
                                                           "e=spread_for_test"])}
    finally:
        unregister_measure("spread_for_test")
    assert units == {"a": "rad", "b": "m", "c": "s", "d": None, "e": "mm"}


@pytest.fixture(scope="module")
def first_order_fmu(tmp_path_factory):
    """The FMI 2 first-order test FMU: z[1] = scale x, z[2] = its time."""
    from tests.blocks.fmu.build import build_error, compile_library, fmi2_files, zip_files

    why = build_error()
    if why:
        pytest.skip(why)
    folder = tmp_path_factory.mktemp("metric_fmu")
    library = compile_library(folder / "fo.so", "first_order_fmi2.c", "fmi2_unsupported.c")
    return zip_files(folder / "fo.fmu", fmi2_files(library))


def test_an_fmu_element_is_one_element_in_a_metric_a_plot_and_a_connection(first_order_fmu):
    from blocks import loads_diagram, simulate
    from blocks.plot.select import select

    diagram = loads_diagram(f"""
time: {{t_end: 0.5 s}}
blocks:
  plant: {{type: FMU, period: 0.1 s, params: {{path: '{first_order_fmu}', start_values: {{x0: 1.0, scale: 3}}}}}}
  g: {{type: Gain, params: {{k: 1.0}}}}
connections: ["plant.z[1] -> g.u"]
log: [plant.z, g.y]
""")
    result = simulate(diagram)
    # z[1] = scale x, x = a^k x0 (a = 0.5); z[2] = t
    for label, want in (("1", 3 * 0.5**5), ("2", 0.5)):
        metric = parse_metric(f"m=final(plant.z[{label}])")
        metric.check(diagram)
        (trace,) = select(result, f"plant.z[{label}]")
        assert metric.evaluate(result, diagram) == result["plant.z"][1][-1, trace.columns[0]] == want
    assert parse_metric("m=final(plant.z[1])").evaluate(result, diagram) == result["g.y"][1][-1, 0]
    with pytest.raises(SweepError, match="has no element 'x'"):
        parse_metric("m=final(plant.z[x])").check(diagram)
    for number in ("0", "3", "-1"):  # on a numbered port a number is a label, never an index: none of these
        with pytest.raises(SweepError, match="numbers its elements 1 to 2"):
            parse_metric(f"m=final(plant.z[{number}])").check(diagram)
        with pytest.raises(ValueError):
            select(result, f"plant.z[{number}]")
    with pytest.raises(SweepError, match="2 elements; a metric reduces one"):
        parse_metric("m=final(plant.z[0:2])").check(diagram)
