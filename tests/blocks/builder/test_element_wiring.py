"""Connections that name elements (``c.y[1] -> g.u``, ``q.y[0:3] -> ctrl.q``, by label, and
inputs assembled from several outputs, ``a.y -> g.u[0]``): checked at load time with the
widths, run in both engines, in subsystems, written back as YAML; and on random multirate
diagrams the same samples, to the bit, as the same wiring through Selector and Mux blocks."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

import blocks
from blocks import DiagramBuilder, DiagramError, dump_diagram, loads_diagram, simulate

from ..test_diagram_fuzz import FUZZ_SETTINGS, dump

ENGINES = ("native", "reference")

HEAD = """
name: elements
time: {t_end: 5 ms}
blocks:
  c: {type: Constant, params: {value: [1.0, 2.0, 3.0, 4.0]}}
  m: {type: Mux, params: {widths: [1, 2], labels: [x, pos]}}
  g: {type: Gain, period: 1 ms, params: {k: 2.0}}
  h: {type: Gain, period: 1 ms, params: {k: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}}
connections:
  - c.y[3] -> m.u0
  - c.y[0:2] -> m.u1
"""


def load(text: str) -> blocks.Diagram:
    return loads_diagram(text, filename="el.yaml", trust=True)


def problems(text: str) -> list[str]:
    with pytest.raises(DiagramError) as caught:
        load(text)
    return [str(i) for i in caught.value.issues]


def run_both(d: blocks.Diagram) -> blocks.Results:
    native, reference = (simulate(d, engine=e) for e in ENGINES)
    assert native.complete and reference.complete, (native.status, reference.status)
    for name in native:
        assert np.array_equal(native[name][0], reference[name][0]), name
        assert np.array_equal(native[name][1], reference[name][1]), name
    return native


def test_an_element_a_slice_and_a_label_wire_what_they_name():
    d = load(HEAD + """  - m.y[pos.1] -> g.u
  - m.y[x,pos.0,1] -> h.u
log: [m.y, g.y, h.y]
""")
    r = run_both(d)
    np.testing.assert_array_equal(r["m.y"][1][0], [4.0, 1.0, 2.0])
    np.testing.assert_array_equal(r["g.y"][1][:, 0], 4.0)
    np.testing.assert_array_equal(r["h.y"][1][-1], [4.0, 1.0, 1.0])
    (to_g,) = d.drivers_of("g", "u")
    assert (to_g.src_select, to_g.src_elements, str(to_g)) == ("pos.1", (2,), "m.y[pos.1] -> g.u")


def test_an_input_assembled_from_several_outputs_with_a_delayed_part():
    d = load(HEAD + """  - c.y[1] -> h.u[2]
  - m.y[0] -> h.u[0]
  - {from: "g.y", to: "h.u[1]", delay: 1, initial: -1.0}
  - c.y[2] -> g.u
log: [h.y]
""")
    r = run_both(d)
    t, y = r["h.y"]
    np.testing.assert_array_equal(y[0], [4.0, -1.0, 2.0])  # the delayed part holds its initial value at t = 0
    np.testing.assert_array_equal(y[1:], np.tile([4.0, 6.0, 2.0], (len(t) - 1, 1)))
    assert [c.dst_elements for c in d.drivers_of("h", "u")] == [(2,), (0,), (1,)]


def test_contiguous_selections_read_the_source_in_place_and_others_are_assembled():
    d = load(HEAD + """  - c.y[2] -> g.u
  - c.y[3,0,1] -> h.u
log: [h.y]
""")
    table = blocks.engine.optable.op_table(d, blocks.build_schedule(d, d.t_end))
    feeds = dict(zip(table.names.blocks, table.names.feeds))
    assert feeds["g"] == ("source",) and feeds["h"] == ("assembled",) and feeds["m"] == ("source", "source")
    assert run_both(d)["h.y"][1][-1].tolist() == [4.0, 1.0, 2.0]


def test_selections_infer_the_width_of_what_they_feed():
    d = load("""
name: widths
time: {t_end: 2 ms}
blocks:
  c: {type: Constant, params: {value: [1.0, 2.0, 3.0, 4.0, 5.0]}}
  open: {type: Gain, period: 1 ms, params: {k: 3.0}}
  step: {type: Gain, period: 1 ms, params: {k: 1.0}}
connections:
  - c.y[1:] -> open.u
  - c.y[::2] -> step.u
log: [open.y, step.y]
""")
    assert d.blocks["open"].block.inputs["u"] == 4 and d.blocks["step"].block.inputs["u"] == 3
    r = run_both(d)
    assert r["open.y"][1][-1].tolist() == [6.0, 9.0, 12.0, 15.0] and r["step.y"][1][-1].tolist() == [1.0, 3.0, 5.0]


@pytest.mark.parametrize("wire, message", [
    ("c.y[4] -> g.u", "el.yaml:12: connection 'c.y[4] -> g.u': output c.y has 4 element(s): index 4 is out of range "
                      "(hint: elements by label, by index from 0, or a slice start:stop, e.g. plant.q[fore.1], "
                      "c.y[0:3])"),
    ("m.y[pos.3] -> g.u", "el.yaml:12: connection 'm.y[pos.3] -> g.u': output m.y has no element 'pos.3'; its "
                          "elements: x, pos.0, pos.1 (or an index from 0, or a slice start:stop)"),
    ("c.y[0:3] -> h.u[0:2]", "el.yaml:12: connection 'c.y[0:3] -> h.u[0:2]': width mismatch: c.y[0:3] selects 3, "
                             "h.u[0:2] selects 2"),
    ("c.y -> h.u", "el.yaml:12: connection 'c.y -> h.u': width mismatch: c.y has width 4, h.u has width 3"),
    ("c.y[] -> g.u", "el.yaml:12: connection 'c.y[] -> g.u': 'c.y[]' is not 'block.port'"),
    ("c.y[3:1] -> g.u", "selects no element of its 4"),
])
def test_a_selection_that_does_not_fit_is_one_line_at_its_connection(wire, message):
    found = problems(HEAD + f"  - {wire}\n  - c.y[0:3] -> h.u\n" if "h.u" not in wire else
                     HEAD + f"  - {wire}\n  - c.y[0] -> g.u\n")
    assert any(message in p for p in found), found
    assert all("\n" not in p for p in found)


def test_elements_driven_twice_or_left_open_are_named_with_their_lines():
    found = problems(HEAD + """  - c.y[0] -> g.u
  - c.y[0:2] -> h.u[0:2]
  - c.y[3] -> h.u[1]
""")
    assert found == [
        "el.yaml:14: element 1 of input h.u driven twice: by c.y[3] and by c.y[0:2] (line 13) "
        "(hint: each element of an input takes one connection)",
        "el.yaml:8: input h.u of block 'h' (Gain): element 2 of 3 not connected (the others by "
        "c.y[0:2] -> h.u[0:2] (line 13); c.y[3] -> h.u[1] (line 14)) "
        "(hint: connect them, e.g. '- <block>.<port> -> h.u[2:3]')"]
    whole = problems(HEAD + "  - c.y[0] -> g.u\n  - c.y[0:3] -> h.u\n  - c.y[3] -> h.u[1]\n")
    assert whole == ["el.yaml:14: input h.u is driven twice: by c.y[3] and by c.y[0:3] (line 13) (hint: an input "
                     "takes exactly one connection (or one per element: a.y -> g.u[0]); add a Sum block to "
                     "combine signals)"]
    after = problems(HEAD + "  - c.y[0] -> g.u\n  - c.y[3] -> h.u[1]\n  - c.y[0:3] -> h.u\n")
    assert after == [whole[0].replace("by c.y[3] and by c.y[0:3]", "by c.y[0:3] and by c.y[3]")]


def test_a_subsystem_wires_by_element_inside_and_across_its_ports(tmp_path):
    (tmp_path / "pick.yaml").write_text("""
name: pick
blocks:
  g: {type: Gain, period: 1 ms, params: {k: [[1, 0], [0, 1]]}}
  d: {type: Gain, params: {k: 10.0}}
connections:
  - g.y[1] -> d.u
inputs: {u: g.u}
outputs: {y: g.y, one: d.y}
""")
    (tmp_path / "top.yaml").write_text("""
name: top
time: {t_end: 3 ms}
blocks:
  c: {type: Constant, params: {value: [1.0, 2.0, 3.0]}}
  sub: {diagram: pick.yaml}
  out: {type: Gain, params: {k: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}}
connections:
  - c.y[2,0] -> sub.u
  - sub.y[1] -> out.u[0]
  - sub.one -> out.u[1]
  - sub.y[0] -> out.u[2]
log: [out.y, sub.d.y]
""")
    d = blocks.load_diagram(tmp_path / "top.yaml")
    r = run_both(d)
    assert r["out.y"][1][-1].tolist() == [1.0, 10.0, 3.0] and r["sub.d.y"][1][-1].tolist() == [10.0]
    assert {str(c) for c in d.drivers_of("out", "u")} == {"sub.g.y[1] -> out.u[0]", "sub.d.y -> out.u[1]",
                                                          "sub.g.y[0] -> out.u[2]"}
    (tmp_path / "pick.yaml").write_text((tmp_path / "pick.yaml").read_text().replace("g.y[1] -> d.u", "g.y[2] -> d.u"))
    with pytest.raises(DiagramError) as caught:
        blocks.load_diagram(tmp_path / "top.yaml")
    assert [str(i) for i in caught.value.issues] == [
        f"{tmp_path / 'pick.yaml'}:7: connection 'sub.g.y[2] -> sub.d.u': output sub.g.y has 2 element(s): index 2 "
        "is out of "
        "range (hint: elements by label, by index from 0, or a slice start:stop, e.g. plant.q[fore.1], c.y[0:3])"]


def test_the_builder_and_the_yaml_writer_keep_the_selections(tmp_path):
    b = DiagramBuilder("built", t_end="2 ms")
    b.add("c", "Constant", params={"value": [1.0, 2.0, 3.0]})
    b.add("g", "Gain", period="1 ms", params={"k": [[1, 0], [0, 1]]})
    b.connect("c.y[2]", "g.u[0]")
    b.connect("c.y[0]", "g.u[1]", delay=1, initial=7.0)
    b.log("g.y")
    d = b.build()
    text = dump_diagram(d)
    assert "c.y[2] -> g.u[0]" in text and yaml.safe_load(text)["connections"][1] == {
        "from": "c.y[0]", "to": "g.u[1]", "delay": 1, "initial": [7.0]}
    again = loads_diagram(text, filename="again.yaml")
    first, second = run_both(d), run_both(again)
    assert np.array_equal(first["g.y"][1], second["g.y"][1]) and first["g.y"][1][0].tolist() == [3.0, 7.0]


# -- random multirate diagrams: by element, and through Selector and Mux blocks ----------------

PERIODS = [None, "0.1 ms", "0.2 ms", "0.5 ms", "1 ms"]


@st.composite
def element_wired(draw) -> tuple[dict, dict]:
    """A random multirate diagram of vector blocks whose inputs take elements of outputs (by
    index lists and slices, assembled from up to three outputs, a whole-input wire sometimes
    delayed), and the same diagram with every selection a Selector and every assembled
    input a Mux: the two documents."""
    n = draw(st.integers(min_value=2, max_value=6))
    blocks_by, kinds = {}, {}
    outputs: dict[str, int] = {}
    for i in range(n):
        name = f"b{i}"
        p = draw(st.integers(min_value=1, max_value=4))
        kind = "Constant" if i == 0 else draw(st.sampled_from(["Constant", "Sine", "Gain", "DSS", "UnitDelay"]))
        period = draw(st.sampled_from(PERIODS[1:] if kind in ("Sine", "DSS", "UnitDelay") else PERIODS))
        values = [float(draw(st.integers(min_value=-3, max_value=3))) + 0.25 * j for j in range(p)]
        if kind == "Constant":
            spec, m = {"type": "Constant", "params": {"value": values}}, 0
        elif kind == "Sine":
            spec, m = {"type": "Sine", "params": {"amplitude": values, "frequency": 50.0 + 10 * i}}, 0
        elif kind == "Gain":
            m = draw(st.integers(min_value=1, max_value=4))
            spec = {"type": "Gain", "params": {"k": [[0.5 * (r + 1) - 0.25 * c for c in range(m)] for r in range(p)]}}
        elif kind == "DSS":
            m = draw(st.integers(min_value=1, max_value=3))
            spec = {"type": "DiscreteStateSpace", "params": {
                "A": [[0.9 if r == c else 0.01 for c in range(p)] for r in range(p)],
                "B": [[0.1 * (r + c + 1) for c in range(m)] for r in range(p)],
                "C": [[1.0 if r == c else 0.0 for c in range(p)] for r in range(p)],
                "D": [[0.0] * m for _ in range(p)]}}
        else:
            m = p
            spec = {"type": "UnitDelay", "params": {"initial": values}}
        if period is not None:
            spec["period"] = period
        blocks_by[name], kinds[name] = spec, (kind, m, p)
        outputs[name] = p
    element, through = [], []
    extra: dict[str, dict] = {}
    for i, (name, (kind, m, p)) in enumerate(kinds.items()):
        if m == 0:
            continue
        # sources: earlier blocks, or any block without feedthrough (no algebraic loop)
        pool = [b for j, b in enumerate(kinds) if j < i or kinds[b][0] in ("DSS", "UnitDelay", "Constant", "Sine")]
        parts = draw(st.integers(min_value=1, max_value=min(3, m)))
        cuts = sorted(draw(st.lists(st.integers(min_value=1, max_value=m - 1), min_size=parts - 1,
                                    max_size=parts - 1, unique=True))) if parts > 1 else []
        bounds = list(zip([0] + cuts, cuts + [m]))
        mux_inputs = []
        for k, (lo, hi) in enumerate(bounds):
            src = draw(st.sampled_from(pool))
            width = outputs[src]
            if draw(st.booleans()) and hi - lo <= width:
                start = draw(st.integers(min_value=0, max_value=width - (hi - lo)))
                picked, text = list(range(start, start + hi - lo)), f"{start}:{start + hi - lo}"
            else:
                picked = draw(st.lists(st.integers(min_value=0, max_value=width - 1), min_size=hi - lo,
                                       max_size=hi - lo))
                text = ",".join(str(j) for j in picked)
            whole = picked == list(range(width))
            source = f"{src}.y" if whole else f"{src}.y[{text}]"
            if whole:
                plain = f"{src}.y"
            else:
                sel = f"s{name}_{k}"
                extra[sel] = {"type": "Selector", "params": {"indices": picked}}
                through.append(f"{src}.y -> {sel}.u")
                plain = f"{sel}.y"
            if len(bounds) == 1:
                if draw(st.integers(min_value=0, max_value=3)) == 0:
                    initial = float(draw(st.integers(min_value=-2, max_value=2)))
                    element.append({"from": source, "to": f"{name}.u", "delay": 1, "initial": initial})
                    through.append({"from": plain, "to": f"{name}.u", "delay": 1, "initial": initial})
                else:
                    element.append(f"{source} -> {name}.u")
                    through.append(f"{plain} -> {name}.u")
            else:
                element.append(f"{source} -> {name}.u[{lo}:{hi}]")
                mux_inputs.append(plain)
        if mux_inputs:
            mux = f"m{name}"
            extra[mux] = {"type": "Mux", "params": {"widths": [hi - lo for lo, hi in bounds]}}
            through += [f"{s} -> {mux}.u{k}" for k, s in enumerate(mux_inputs)] + [f"{mux}.y -> {name}.u"]
    log = [{"signal": f"{b}.y", "decimate": draw(st.sampled_from([1, 1, 2]))} for b in kinds]
    head = {"name": "random-elements", "time": {"t_end": "3 ms"}}
    return ({**head, "blocks": blocks_by, "connections": element, "log": log},
            {**head, "blocks": {**blocks_by, **extra}, "connections": through, "log": log})


@settings(max_examples=120, **FUZZ_SETTINGS)
@given(docs=element_wired())
def test_wiring_by_element_gives_the_samples_of_selector_and_mux_blocks(docs):
    by_element, through_blocks = (loads_diagram(dump(doc), filename="random.yaml")
                                  for doc in docs)
    runs = [simulate(by_element, engine=e) for e in ENGINES] + [simulate(through_blocks, engine=e) for e in ENGINES]
    first = runs[0]
    assert first.complete, first.status
    for other in runs[1:]:
        assert other.status == first.status and list(other) == list(first)
        for name in first:
            assert np.array_equal(first[name][0], other[name][0]), name
            assert np.array_equal(first[name][1], other[name][1]), name


def test_validate_and_graph_show_the_elements(tmp_path, capsys):
    from blocks.cli import PROGRAM
    from blocks.cli.program import main
    from blocks.graph.dot import to_dot

    path = tmp_path / "el.yaml"
    path.write_text(HEAD + "  - m.y[pos.1] -> g.u\n  - m.y[0] -> h.u[2]\n  - c.y[3,1] -> h.u[0:2]\nlog: [h.y]\n")
    assert main(PROGRAM, ["validate", str(path)]) == 0
    out = capsys.readouterr().out
    assert "wiring by element:\n  c.y[3] -> m.u0\n  c.y[0:2] -> m.u1\n  m.y[pos.1] -> g.u  (m.y[2] -> g.u)\n" \
           "  m.y[0] -> h.u[2]\n  c.y[3,1] -> h.u[0:2]\n" in out
    d = blocks.load_diagram(path)
    dot = to_dot(d, blocks.build_schedule(d, d.t_end))
    assert '"c":out_y:e -> "h":in_u:w [color="#c2189b", taillabel="[3,1]", headlabel="[0:2]"];' in dot
    from blocks.graph.drawing import draw

    figure = draw(d, blocks.build_schedule(d, d.t_end))
    shown = sorted(t.get_text() for t in figure.axes[0].texts if (t.get_gid() or "").startswith("elements:"))
    assert shown == sorted(["[3]", "[0:2]", "[pos.1]", "[0]", "[2]", "[3,1]", "[0:2]"])
