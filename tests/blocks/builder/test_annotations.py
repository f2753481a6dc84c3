"""Units and element names a diagram gives ports of blocks that have none: kept in run.json,
the CSV columns, plots, validate and connections by label; checked against the port's
width and the block's own; and connections whose ends declare different units refused."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest

import blocks
from blocks import DiagramBuilder, DiagramError, dump_diagram, loads_diagram, simulate
from blocks.units import same_unit

POSE = """
name: pose
time: {t_end: 2 ms}
blocks:
  c: {type: Constant, params: {value: [1.0, 2.0, 0.5]}, units: {y: [m, m, rad]}, elements: {y: [x, y, theta]}}
  g: {type: Gain, period: 1 ms, params: {k: 2.0}}
  h: {type: Gain, period: 1 ms, params: {k: 1.0}}
connections:
  - c.y[theta] -> g.u
  - c.y[x,y] -> h.u
units: {g.u: radian, g.y: rad, h.u: m}
elements: {h.y: [a, b]}
log: [c.y, g.y, h.y]
"""


def load(text: str) -> blocks.Diagram:
    return loads_diagram(text, filename="pose.yaml")


def problems(text: str) -> list[str]:
    with pytest.raises(DiagramError) as caught:
        load(text)
    return [str(i) for i in caught.value.issues]


def test_given_units_and_names_reach_run_json_csv_and_wiring_by_label(tmp_path):
    d = load(POSE)
    assert d.port_units("c", "y") == ["m", "m", "rad"] and d.element_labels("c", "y") == ["x", "y", "theta"]
    assert [c.src_elements for c in d.connections] == [(2,), (0, 1)]
    r = simulate(d)
    r.save(tmp_path / "run", csv=True)
    info = json.loads((tmp_path / "run" / "run.json").read_text())
    assert info["units"] == {"c.y": ["m", "m", "rad"], "g.y": "rad"}
    assert info["element_labels"] == {"c.y": ["x", "y", "theta"], "h.y": ["a", "b"]}
    header = (tmp_path / "run" / "signals.csv").read_text().splitlines()[0]
    assert header == "time,c.y[x],c.y[y],c.y[theta],g.y,h.y[a],h.y[b]"
    again = blocks.Results.load(tmp_path / "run")
    assert again.units("c.y") == ["m", "m", "rad"] and again.unit("g.y") == "rad"


def test_the_builder_and_the_writer_keep_them():
    b = DiagramBuilder("built", t_end="1 ms")
    b.add("c", "Constant", params={"value": [1.0, 2.0]}, units={"y": "N"}, elements={"y": ["left", "right"]})
    b.add("g", "Gain", params={"k": 1.0})
    b.connect("c.y[right]", "g.u")
    b.annotate("g.y", units="N")
    b.log("g.y")
    d = b.build()
    assert d.port_units("g", "y") == "N" and d.drivers_of("g", "u")[0].src_elements == (1,)
    text = dump_diagram(d)
    again = loads_diagram(text, filename="again.yaml")
    assert again.blocks["c"].units == {"y": "N"} and again.blocks["c"].labels == {"y": ("left", "right")}
    assert again.blocks["g"].units == {"y": "N"}


@pytest.mark.parametrize("change, message", [
    ("units: {g.u: radian, g.y: rad, h.u: m}", None),
    ("h.u: m}", "pose.yaml:10: connection 'c.y[x,y] -> h.u': units differ: c.y[0] is in 'm', h.u[0] in 'mm' (hint: a "
                "connection converts nothing: insert a Gain of the factor between them, or give both ends one unit)"),
    ("g.u: radian", "pose.yaml:9: connection 'c.y[theta] -> g.u': units differ: c.y[2] is in 'rad', g.u in 'deg'"),
])
def test_connected_ports_of_different_units_are_refused(change, message):
    if message is None:
        load(POSE)  # radian and rad are one unit
        return
    text = POSE.replace(change, change.replace(" m}", " mm}") if "h.u" in change else "g.u: deg")
    found = problems(text)
    assert len(found) == 1 and found[0].startswith(message), found


@pytest.mark.parametrize("edit, message, replacement", [
    ("elements: {h.y: [a, b]}", "pose.yaml:12: elements of h.y: 3 names for the 2 elements of 'y' (hint: one name "
                                "per element)", "elements: {h.y: [a, b, c]}"),
    ("elements: {h.y: [a, b]}", "pose.yaml:12: elements of h.y: must be a list of distinct names, got ['a', 'a']",
     "elements: {h.y: [a, a]}"),
    ("units: {g.u: radian, g.y: rad, h.u: m}", "pose.yaml:11: units of h.u: 3 units for the 2 elements of 'u'",
     "units: {g.u: radian, g.y: rad, h.u: [m, m, m]}"),
    ("units: {g.u: radian, g.y: rad, h.u: m}", "pose.yaml:11: units of 'nope.y': no block named 'nope'",
     "units: {g.u: radian, g.y: rad, h.u: m, nope.y: m}"),
    ("units: {g.u: radian, g.y: rad, h.u: m}", "pose.yaml:11: block 'g' (Gain) has no port 'z' (hint: its ports: "
                                               "u, y)", "units: {g.u: radian, g.y: rad, h.u: m, g.z: m}"),
])
def test_what_does_not_fit_the_port_is_one_line_at_its_line(edit, message, replacement):
    found = problems(POSE.replace(edit, replacement))
    assert any(p.startswith(message) for p in found), found


def test_a_blocks_own_units_and_names_stand(tmp_path):
    text = """
name: own
time: {t_end: 1 ms}
blocks:
  lab: {type: "python:tests.blocks.blockdefs:Labelled", params: {labels: [a, b, c], units: rad}}
  g: {type: Gain, params: {k: 1.0}}
connections: [lab.y -> g.u]
units: {lab.y: deg}
elements: {lab.y: [a, b, c]}
"""
    with pytest.raises(DiagramError) as caught:
        loads_diagram(text, filename="own.yaml", trust=True)
    (issue,) = caught.value.issues
    assert str(issue).startswith("own.yaml:8: units of lab.y: block 'lab' (Labelled) gives it 'rad', the diagram "
                                 "'deg' (hint: a block's own units stand")


def test_one_unit_however_written_and_pint_only_when_the_texts_differ():
    assert same_unit("N m", "m*N") and same_unit("N·m", "N m")
    assert same_unit("N", "kg m/s^2") and same_unit("rad/s", "radian / second")
    assert not same_unit("mm", "m") and not same_unit("rad", "deg") and not same_unit("m", "s")
    assert not same_unit("widgets", "gadgets") and same_unit("widgets", "widgets")
    assert "pint" in sys.modules  # loaded by the comparisons above, not before them


def test_validate_shows_them(tmp_path, capsys):
    from blocks.cli import PROGRAM
    from blocks.cli.program import main

    path = tmp_path / "pose.yaml"
    path.write_text(POSE)
    assert main(PROGRAM, ["validate", str(path)]) == 0
    out = capsys.readouterr().out
    assert "out: y[3] (m, m, rad) {x, y, theta}" in out and "in: u[1] (radian)  out: y[1] (rad)" in out
    assert "in: u[2] (m)  out: y[2] {a, b}" in out
    np.testing.assert_array_equal(simulate(blocks.load_diagram(path))["h.y"][1][-1], [1.0, 2.0])
