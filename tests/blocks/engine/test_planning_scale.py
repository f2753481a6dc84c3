"""Planning stays near-linear in the number of blocks, and nothing recurses per block.

No timing is asserted (machines are noisy; ``benchmarks/scheduler.py`` prints the times).
Instead the work is counted: loading and planning a chain twice as long makes at most
about twice as many function calls (Python's and builtins', as ``sys.setprofile`` sees
them), so any quadratic step of loading, width inference, firing sets, ordering or program
building, as they were before issue 12, fails the bound whatever the machine's speed. The
chain is written bottom-up (last block and last connection first), the order in which
sweep-until-nothing-changes loops need a pass per block, and is longer than Python's
recursion limit, so a step that recurses per block fails too.
"""

from __future__ import annotations

import sys

import numpy as np

import blocks
from blocks.builder.references import build_order

CHAIN = 3_000
"""Blocks in the longer chain; the shorter has half, still more than Python's recursion limit (1000)."""

GROWTH = 2.25
"""The most that doubling the chain may multiply the calls by: linear work doubles them
(n log n work multiplies them by 2.19 at this size), a pass per block quadruples them."""

GAIN = 1.00001


def chain_text(n: int) -> str:
    """``src: Ramp -> g0 -> ... -> g{n-1}``, blocks and connections listed last first."""
    lines = ["time: {t_end: 2 ms}", "blocks:"]
    lines += [f"  g{i}: {{type: Gain, params: {{k: {GAIN}}}}}" for i in reversed(range(n))]
    lines.append("  src: {type: Ramp, period: 1 ms, params: {slope: 3.0}}")
    lines.append("connections:")
    lines += [f"  - g{i - 1}.y -> g{i}.u" for i in reversed(range(1, n))]
    lines.append("  - src.y -> g0.u")
    lines.append(f"log: [g{n // 2}.y, g{n - 1}.y]")
    return "\n".join(lines) + "\n"


def planned_with_calls(n: int) -> tuple[blocks.Diagram, blocks.Schedule, int]:
    """The chain of ``n`` blocks loaded and planned, and the function calls that took."""
    text = chain_text(n)
    calls = 0

    def count(frame, event, arg) -> None:
        nonlocal calls
        calls += event in ("call", "c_call")

    sys.setprofile(count)
    try:
        diagram = blocks.loads_diagram(text)
        plan = blocks.build_schedule(diagram, diagram.t_end)
    finally:
        sys.setprofile(None)
    return diagram, plan, calls


def test_a_long_chain_written_bottom_up_plans_in_linear_work_in_order_and_runs_to_the_closed_form():
    planned_with_calls(3)  # the lazy imports, once
    _, _, half = planned_with_calls(CHAIN // 2)
    diagram, plan, calls = planned_with_calls(CHAIN)
    assert calls <= GROWTH * half, (half, calls)
    chain = ["src"] + [f"g{i}" for i in range(CHAIN)]
    assert plan.n_ticks == 2 and plan.hyperperiod == 1
    assert plan.lazy == frozenset(chain[1:]) - {f"g{CHAIN // 2}", f"g{CHAIN - 1}"}
    for program in (plan.initial, *plan.programs, plan.final):
        assert [b for b, ports in program.evaluate] == chain
        assert all(ports is None for _, ports in program.evaluate)
    results = blocks.simulate(diagram)
    assert results.status == "complete"
    for i in (CHAIN // 2, CHAIN - 1):
        t, y = results[f"g{i}.y"]
        np.testing.assert_array_equal(t, [0.0, 0.001, 0.002])
        np.testing.assert_allclose(y[:, 0], 3.0 * t * GAIN ** (i + 1), rtol=1e-9)


def test_a_deep_chain_of_block_references_is_ordered_without_recursion():
    n = 100_000
    references = {f"b{i}": {"source": f"b{i + 1}"} for i in range(n - 1)} | {f"b{n - 1}": {}}
    order, cycles = build_order(references)
    assert order == [f"b{i}" for i in reversed(range(n))] and cycles == []
    references[f"b{n - 1}"] = {"source": "b0"}
    order, cycles = build_order(references)
    assert len(order) == n and len(cycles) == 1
    assert [str(r) for r in cycles[0][:2]] == ["b0.source -> b1", "b1.source -> b2"]
    assert str(cycles[0][-1]) == f"b{n - 1}.source -> b0"


def test_an_inherited_block_fires_at_zero_only_if_a_source_does_whatever_the_file_order():
    """Sums and gains fed, also through each other, by a source with an offset never fire
    at t = 0 (the sweep that found this used to stop early in some block orders)."""
    definitions = {
        "b0": "{type: Gain, params: {k: 2.0}}",
        "b1": "{type: Gain, params: {k: 3.0}}",
        "b2": "{type: Ramp, period: 2 ms, offset: 1 ms}",
        "b3": "{type: Sum, params: {signs: '++'}}",
        "b4": "{type: Sum, params: {signs: '+++'}}",
    }
    wires = "[b2.y -> b0.u, b0.y -> b3.u0, b2.y -> b3.u1, b3.y -> b1.u, b0.y -> b4.u0, " \
            "b1.y -> b4.u1, b2.y -> b4.u2]"
    for order in (["b3", "b0", "b2", "b4", "b1"], ["b2", "b0", "b3", "b1", "b4"]):
        text = "\n".join(["time: {t_end: 4 ms}", "blocks:"] + [f"  {b}: {definitions[b]}" for b in order]
                         + [f"connections: {wires}", "log: [b3.y, b4.y]"])
        diagram = blocks.loads_diagram(text)
        plan = blocks.build_schedule(diagram, diagram.t_end)
        assert not any(plan.fires_at_zero.values()), order
        results = blocks.simulate(diagram)
        for signal in ("b3.y", "b4.y"):
            np.testing.assert_array_equal(results[signal][0], [0.001, 0.003])
