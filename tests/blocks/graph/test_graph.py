"""The wiring drawing (``blocks.graph``): record-like blocks with their ports, every
connection once from output port to input port, layers along the feedthrough, colours
by rate with a legend, and the DOT text for Graphviz."""

from __future__ import annotations

import re
from itertools import combinations
from pathlib import Path

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from blocks import build_schedule, load_diagram, loads_diagram
from blocks.graph import (crossings, draw, effective_rate, geometry, is_feedthrough, layered, picture, rate_colors,
                          render, to_dot)

ROOT = Path(__file__).resolve().parents[3]
TOY = ROOT / "diagrams" / "toy.yaml"

DELAYED_LOOP = """
name: loop through a delay
blocks:
  ref:  {type: Step, period: 1 ms, params: {time: 0.0}}
  sum:  {type: Sum, params: {signs: "+-"}}
  gain: {type: Gain, period: 1 ms, params: {k: 0.5}}
  slow: {type: Gain, period: 4 ms, params: {k: 2.0}}
connections:
  - ref.y -> sum.u0
  - {from: gain.y, to: sum.u1, delay: 1}
  - sum.y -> gain.u
  - gain.y -> slow.u
"""


def toy():
    d = load_diagram(TOY)
    return d, build_schedule(d, None)


def wires(fig) -> list[str]:
    return [p.get_gid()[len("wire:"):] for p in fig.axes[0].patches if (p.get_gid() or "").startswith("wire:")]


def test_every_connection_is_one_port_to_port_edge_in_the_dot_text():
    d, s = toy()
    dot = to_dot(d, s)
    assert dot.count("->") == len(d.connections)
    for c in d.connections:
        edge = f'"{c.src_block}":out_{c.src_port}:e -> "{c.dst_block}":in_{c.dst_port}:w'
        assert dot.count(edge) == 1, edge


def test_dot_blocks_are_records_with_their_ports_and_rate_colours():
    d, s = toy()
    dot = to_dot(d, s)
    assert "shape=record" in dot and "rankdir=LR" in dot
    label = re.search(r'"err" \[label="([^"]*)", color="(#[0-9a-f]{6})"', dot)
    assert label.group(1).startswith("{{<in_u0> u0|<in_u1> u1}|err\\nSum\\n")
    assert label.group(1).endswith("|{<out_y> y}}")
    colours = dict(re.findall(r'^  "(\w+)" \[label=.*?color="(#[0-9a-f]{6})"', dot, re.M))
    # err inherits the plant's 100 us, u the integrator's 1 ms
    assert colours["err"] == colours["plant"]
    assert colours["u"] == colours["integ"]
    assert len({colours["plant"], colours["integ"], colours["prop"], colours["ref"]}) == 4


def test_delayed_and_feedback_wires_in_the_dot_text():
    d = loads_diagram(DELAYED_LOOP)
    dot = to_dot(d, build_schedule(d, None))
    delayed = [line for line in dot.splitlines() if '"gain":out_y:e -> "sum":in_u1:w' in line]
    assert len(delayed) == 1 and "style=dashed" in delayed[0] and "z\u207b\u00b9" in delayed[0]
    assert "constraint=false" in delayed[0]


def test_the_figure_draws_every_connection_once():
    d, s = toy()
    fig = draw(d, s)
    assert sorted(wires(fig)) == sorted(str(c) for c in d.connections)
    blocks = [p.get_gid() for p in fig.axes[0].patches if (p.get_gid() or "").startswith("block:")]
    assert sorted(blocks) == sorted(f"block:{n}" for n in d.blocks)
    texts = {t.get_text() for t in fig.axes[0].texts}
    for c in d.connections:     # every port name is written in its block
        assert c.src_port in texts and c.dst_port in texts


def test_layers_follow_the_feedthrough_and_the_loop_runs_back_through_the_plant():
    d, s = toy()
    pic = picture(d, s)
    lay = layered(pic)
    assert [str(c) for c in lay.feedback] == ["u.y -> plant.u"]
    for c in d.connections:
        if c not in lay.feedback:
            assert lay.layer[c.src_block] < lay.layer[c.dst_block], c
    for c in d.connections:
        if is_feedthrough(pic, c):
            assert c not in lay.feedback, c
    assert lay.layer["ref"] == lay.layer["plant"] == 0
    assert lay.layer["err"] == 1 and lay.layer["integ"] == lay.layer["prop"] == 2 and lay.layer["u"] == 3


def test_a_loop_through_a_delay_is_broken_at_the_delay_and_drawn_dashed_with_its_mark():
    d = loads_diagram(DELAYED_LOOP)
    s = build_schedule(d, None)
    lay = layered(picture(d, s))
    assert [str(c) for c in lay.feedback] == ["gain.y -> sum.u1 (delay 1)"]
    fig = draw(d, s)
    assert len(wires(fig)) == len(d.connections)
    delayed = [p for p in fig.axes[0].patches if p.get_gid() == "wire:gain.y -> sum.u1 (delay 1)"]
    assert delayed[0].get_linestyle() != "-"
    assert "z\u207b\u00b9" in [t.get_text() for t in fig.axes[0].texts]
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert legend == ["1 ms", "4 ms", "delayed one sample (z\u207b\u00b9)"]


def test_a_self_loop_through_a_delay_draws():
    d = loads_diagram("""
blocks:
  acc: {type: Sum, period: 1 ms, params: {signs: "++"}}
  one: {type: Constant, params: {value: 1.0}}
connections:
  - one.y -> acc.u0
  - {from: acc.y, to: acc.u1, delay: 1}
""")
    fig = draw(d, build_schedule(d, None))
    assert len(wires(fig)) == 2


def test_one_legend_entry_and_colour_per_distinct_rate():
    d, s = toy()
    rates = rate_colors(d, s)
    assert [label for label, _ in rates.legend] == ["100 us", "1 ms", "10 ms", "constant (t = 0 only)"]
    assert len({colour for _, colour in rates.legend}) == 4
    fig = draw(d, s)
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == [label for label, _ in rates.legend]


def test_inherited_rates_resolve_from_the_schedule():
    d = loads_diagram("""
blocks:
  a: {type: Step, period: 2 ms, params: {time: 0.0}}
  b: {type: Step, period: 3 ms, params: {time: 0.0}}
  mixed: {type: Sum, params: {signs: "++"}}
  c: {type: Step, period: 5 ms, params: {time: 0.0}}
  follows: {type: Gain, params: {k: 1.0}}
connections: [a.y -> mixed.u0, b.y -> mixed.u1, c.y -> follows.u]
""")
    s = build_schedule(d, None)
    assert effective_rate(s, "mixed").kind == "mixed"
    assert effective_rate(s, "follows") == effective_rate(s, "c")
    labels = [label for label, _ in rate_colors(d, s).legend]
    assert labels == ["2 ms", "3 ms", "5 ms", "inherited, mixed rates"]


def test_an_inherited_only_rate_is_labelled_inherited():
    d = loads_diagram("""
blocks:
  a: {type: Step, period: 2 ms, params: {time: 0.0}}
  b: {type: Step, period: 2 ms, params: {time: 0.0}}
  s: {type: Sum, params: {signs: "++"}}
  g: {type: Gain, params: {k: 1.0}, period: 4 ms}
connections: [a.y -> s.u0, b.y -> s.u1, s.y -> g.u]
""")
    s = build_schedule(d, None)
    assert [label for label, _ in rate_colors(d, s).legend] == ["2 ms", "4 ms"]
    d = loads_diagram("""
blocks:
  c: {type: Constant, params: {value: 1.0}}
  z: {type: ZeroOrderHold, period: 1 ms}
  g: {type: Gain, params: {k: 1.0}}
connections: [c.y -> z.u, z.y -> g.u]
""")
    s = build_schedule(d, None)
    labels = [label for label, _ in rate_colors(d, s).legend]
    assert labels[0] == "1 ms" and "constant (t = 0 only)" in labels


def test_barycenter_ordering_removes_avoidable_crossings():
    d = loads_diagram("""
blocks:
  a: {type: Step, period: 1 ms, params: {time: 0.0}}
  b: {type: Step, period: 1 ms, params: {time: 0.0}}
  fed_by_b: {type: Gain, params: {k: 1.0}}
  fed_by_a: {type: Gain, params: {k: 1.0}}
  last_b: {type: Gain, params: {k: 1.0}}
  last_a: {type: Gain, params: {k: 1.0}}
connections: [b.y -> fed_by_b.u, a.y -> fed_by_a.u, fed_by_b.y -> last_b.u, fed_by_a.y -> last_a.u]
""")
    pic = picture(d, build_schedule(d, None))
    lay = layered(pic)
    assert crossings(pic, lay) == 0
    assert lay.columns[1] == ["fed_by_a", "fed_by_b"] and lay.columns[2] == ["last_a", "last_b"]


def test_boxes_do_not_overlap_and_the_figure_grows_with_the_diagram():
    d, s = toy()
    pic = picture(d, s)
    geo = geometry(pic, layered(pic))
    for (a, p), (b, q) in combinations(geo.boxes.items(), 2):
        apart = p.x + p.w <= q.x or q.x + q.w <= p.x or p.y + p.h <= q.y or q.y + q.h <= p.y
        assert apart, (a, b)
    small = loads_diagram("blocks:\n  a: {type: Step, period: 1 ms, params: {time: 0.0}}\n"
                          "  g: {type: Gain, params: {k: 1.0}}\nconnections: [a.y -> g.u]\n")
    w_small, h_small = draw(small, build_schedule(small, None)).get_size_inches()
    w_toy, h_toy = draw(d, s).get_size_inches()
    assert w_toy > w_small and h_toy > h_small


def test_port_names_fit_inside_their_boxes():
    d, s = toy()
    fig = draw(d, s)
    renderer = FigureCanvasAgg(fig).get_renderer()
    ax = fig.axes[0]
    boxes = {p.get_gid(): p.get_window_extent(renderer) for p in ax.patches if (p.get_gid() or "").startswith("block:")}
    for t in ax.texts:
        box = t.get_window_extent(renderer)
        inside = [b for b in boxes.values() if b.x0 - 1 <= box.x0 and box.x1 <= b.x1 + 1
                  and b.y0 - 1 <= box.y0 and box.y1 <= b.y1 + 1]
        overlaps = [b for b in boxes.values() if b.overlaps(box)]
        assert not overlaps or inside, t.get_text()


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_render_writes_the_file(tmp_path, suffix):
    d = loads_diagram(DELAYED_LOOP)
    out = render(d, build_schedule(d, None), tmp_path / "sub" / f"wiring{suffix}")
    data = out.read_bytes()
    if suffix == ".png":
        assert data.startswith(b"\x89PNG\r\n\x1a\n")
    else:
        assert b"<svg" in data and b"wire:gain.y -&gt; sum.u1 (delay 1)" in data


def shipped_picture(name: str, expand: bool = False):
    d = load_diagram(ROOT / "diagrams" / f"{name}.yaml")
    return d, picture(d, build_schedule(d, None), expand)


def test_a_disabled_block_shows_on_the_subsystem_box_and_the_two_regrasp_graphs_differ():
    _, on = shipped_picture("regrasp")
    _, off = shipped_picture("regrasp_unsuppressed")
    assert off.nodes["ctrl"].notes[0] == "suppress disabled"
    assert "suppress.S_b = 0.02" in off.nodes["ctrl"].notes
    assert not any("disabled" in n for n in on.nodes["ctrl"].notes)
    assert "support" in on.nodes and on.nodes["support"].notes == ["hand = plant", "until = 0.1"]


def test_expanded_a_disabled_block_is_drawn_as_such_in_the_figure_and_the_dot_text():
    d, pic = shipped_picture("regrasp_unsuppressed", expand=True)
    node = pic.nodes["ctrl.suppress"]
    assert node.disabled and node.notes[0] == "disabled" and "enabled = false" not in node.notes
    assert not pic.nodes["ctrl.reflex"].disabled
    fig = draw(d, build_schedule(d, None), expand=True)
    (box,) = [p for p in fig.axes[0].patches if p.get_gid() == "block:ctrl.suppress"]
    assert box.get_linestyle() != "-"
    notes = [t.get_text() for t in fig.axes[0].texts if t.get_gid() == "note:ctrl.suppress"]
    assert notes[0] == "disabled"
    dot = to_dot(d, build_schedule(d, None), expand=True)
    (line,) = [ln for ln in dot.splitlines() if ln.strip().startswith('"ctrl.suppress" [')]
    assert "disabled" in line and 'style="filled,dashed"' in line


def test_long_and_many_parameters_are_cut_short():
    from blocks.graph.view import parameter_notes

    assert parameter_notes({"k": 5.0, "signs": "+-", "on": True}) == ["k = 5.0", "signs = +-", "on = true"]
    assert parameter_notes({"A": [[0.999]]}) == ["A = [[0.999]]"]
    assert parameter_notes({"trajectories": {"fore": {"waypoints": [[0.1] * 4] * 3}}}) == ["trajectories = ..."]
    assert parameter_notes({f"p{i}": i for i in range(6)}) == ["p0 = 0", "p1 = 1", "p2 = 2", "(+3 more parameters)"]
