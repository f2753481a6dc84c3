"""The tick plan: base tick, hyperperiod, firing sets, lazy and advanced blocks, loops."""

from __future__ import annotations

import types
from fractions import Fraction
from pathlib import Path

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import blocks
from blocks import build_schedule, loads_diagram
from blocks.engine.schedule import _Planner

ROOT = Path(__file__).resolve().parents[3]


def toy():
    return blocks.load_diagram(ROOT / "diagrams" / "toy.yaml")


def test_toy_plan():
    s = build_schedule(toy(), Fraction(1))
    assert s.base_tick == Fraction(1, 10000) and s.hyperperiod == 100 and s.n_ticks == 10000
    assert s.lazy == {"err", "u"}
    assert s.advanced == {"plant"}
    np.testing.assert_array_equal(s.event_ticks, np.arange(0, 100, 10))
    outputs = [b for b, _ in s.programs[s.event_programs[0]].evaluate]
    assert outputs.index("err") < outputs.index("u")
    assert "plant" not in outputs  # its output at an event comes from the previous advance


@settings(max_examples=60)
@given(st.lists(st.tuples(st.integers(1, 12), st.integers(0, 11)), min_size=1, max_size=4),
       st.integers(1, 400))
def test_hits_in_closed_form_match_the_firing_masks(rates, n_ticks):
    lines = ["blocks:"]
    for i, (p, o) in enumerate(rates):
        lines.append(f"  b{i}: {{type: Ramp, period: {p} ms, offset: {o % p} ms}}")
    lines.append("  s: {type: Sum, params: {signs: '" + "+" * len(rates) + "'}}")
    lines.append("connections: [" + ", ".join(f"b{i}.y -> s.u{i}" for i in range(len(rates))) + "]")
    d = loads_diagram("\n".join(lines))
    s = build_schedule(d, n_ticks * build_schedule(d, None).base_tick)
    for name in d.blocks:
        hits = s.hits(name, s.n_ticks)
        listed = [k for k in range(s.n_ticks + 1)
                  if s.masks[name][k % s.hyperperiod] or (k == 0 and s.fires_at_zero[name])]
        np.testing.assert_array_equal(hits, listed)
        assert s.hit_count(name, s.n_ticks) == len(listed)
        for every in (2, 3, 7):
            np.testing.assert_array_equal(s.nth_hits(name, np.arange(0, len(listed), every)), listed[::every])
    # an inherited block fires exactly when one of its sources does
    union = np.unique(np.concatenate([s.hits(f"b{i}", s.n_ticks) for i in range(len(rates))]))
    np.testing.assert_array_equal(s.hits("s", s.n_ticks), union)


def test_a_block_fed_by_a_constant_fires_at_zero_then_with_its_offset_source():
    d = loads_diagram("""
blocks:
  c: {type: Constant, params: {value: 1.0}}
  r: {type: Ramp, period: 2 ms, offset: 1 ms}
  s: {type: Sum, params: {signs: "++"}}
connections: [c.y -> s.u0, r.y -> s.u1]
""")
    s = build_schedule(d, Fraction(9, 1000))
    np.testing.assert_array_equal(s.hits("s", s.n_ticks), [0, 1, 3, 5, 7, 9])
    np.testing.assert_array_equal(s.nth_hits("s", [0, 2, 4]), [0, 3, 7])
    np.testing.assert_array_equal(s.hits("c", s.n_ticks), [0])
    np.testing.assert_array_equal(s.hits("r", s.n_ticks), [1, 3, 5, 7, 9])


def test_algebraic_loop_through_inherited_blocks_names_the_chain():
    with pytest.raises(blocks.DiagramError) as info:
        loads_diagram("""
blocks:
  src: {type: Ramp, period: 1 ms}
  a: {type: Sum, params: {signs: "++"}}
  b: {type: Gain, params: {k: 0.5}}
connections:
  - src.y -> a.u0
  - a.y -> b.u
  - b.y -> a.u1
""", filename="loop.yaml")
    (issue,) = info.value.issues
    assert issue.message == "algebraic loop: a.y -> b.u -> b.y -> a.u1 -> a.y"
    assert issue.line in (8, 9)


def test_blocks_that_never_fire_together_form_no_algebraic_loop():
    d = loads_diagram("""
time: {t_end: 4 ms}
blocks:
  src: {type: Ramp, period: 2 ms}
  a: {type: Sum, period: 2 ms, params: {signs: "++"}}
  b: {type: Gain, period: 2 ms, offset: 1 ms, params: {k: 0.5}}
connections: [src.y -> a.u0, a.y -> b.u, b.y -> a.u1]
log: [a.y, b.y]
""")
    r = blocks.simulate(d)
    np.testing.assert_allclose(r["a.y"][1][:, 0], [0.0, 0.002, 0.005])
    np.testing.assert_allclose(r["b.y"][1][:, 0], [0.0, 0.001])


def test_incommensurate_periods_are_refused():
    with pytest.raises(blocks.DiagramError, match="hyperperiod"):
        loads_diagram("""
blocks:
  a: {type: Ramp, period: 0.000997 s}
  b: {type: Ramp, period: 0.001009 s}
  c: {type: Ramp, period: 0.0001013 s}
""")


def test_huge_logs_are_refused_before_the_run():
    with pytest.raises(blocks.DiagramError, match="GiB"):
        blocks.simulate(toy(), t_end="1e6 s")


@settings(max_examples=200)
@given(st.integers(1, 12).flatmap(lambda n: st.tuples(
    st.just(n), st.permutations(range(n)), st.sets(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1))))))
def test_output_order_is_networkx_lexicographic_order(case):
    """The planner's topological order of the outputs is networkx's lexicographical
    topological sort keyed by diagram order, and None exactly when the graph has a cycle."""
    n, rank, pairs = case
    nodes = {f"b{i}" for i in range(n)}
    edges = {(f"b{a}", f"b{b}") for a, b in pairs}
    planner = types.SimpleNamespace(order={f"b{i}": rank[i] for i in range(n)})
    graph = nx.DiGraph()
    graph.add_nodes_from(nodes)
    graph.add_edges_from(edges)
    got = _Planner.topological_order(planner, nodes, edges)
    if nx.is_directed_acyclic_graph(graph):
        assert got == list(nx.lexicographical_topological_sort(graph, key=planner.order.get))
    else:
        assert got is None
