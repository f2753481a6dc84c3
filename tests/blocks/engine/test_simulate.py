"""Semantics of the multirate executor against hand-written loops and closed forms."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import blocks
from blocks import loads_diagram, simulate

ROOT = Path(__file__).resolve().parents[3]
DEFS = "python:tests.blocks.blockdefs"


def run(text: str, t_end=None, trust: bool = True):
    return simulate(loads_diagram(text, filename="test.yaml", trust=trust), t_end=t_end)


def accumulate_ones(kind: str, period: str, t_end: str, params: str = "{}"):
    """Run a constant 1 into ``acc``, a ``kind`` block of blockdefs, logging ``acc.y``."""
    return run(f"""
time: {{t_end: {t_end}}}
blocks:
  one: {{type: Constant, params: {{value: 1.0}}}}
  acc: {{type: "{DEFS}:{kind}", period: {period}, params: {params}}}
connections: [one.y -> acc.u]
log: [acc.y]
""")


def toy_hand_loop(n_ticks: int) -> np.ndarray:
    """The toy diagram written out: plant every tick, integ every 10, prop every 100 ticks."""
    xp = xi = yprop = u = 0.0
    out = np.empty(n_ticks + 1)
    for k in range(n_ticks + 1):
        out[k] = xp
        if k == n_ticks:
            break
        if k % 10 == 0:
            e = 1.0 - xp
            yi = xi
            if k % 100 == 0:
                yprop = 5.0 * e
            u = yi + yprop
            xi += 0.02 * e
        xp = 0.999 * xp + 1.0e-4 * u
    return out


def test_toy_multirate_equals_hand_written_loop():
    diagram = blocks.load_diagram(ROOT / "diagrams" / "toy.yaml")
    results = simulate(diagram)
    t, y = results["plant.y"]
    ref = toy_hand_loop(10000)
    assert results.complete
    assert y.shape == (10001, 1)
    np.testing.assert_allclose(y[:, 0], ref, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(t, np.arange(10001) / 10000)


def test_toy_logging_an_inherited_signal_changes_nothing():
    """Logging err makes it fire at every plant hit instead of on demand, so every tick is
    an event and the plant is stepped one hit at a time: the same plant.y up to rounding."""
    text = (ROOT / "diagrams" / "toy.yaml").read_text()
    base = simulate(loads_diagram(text))
    logged_diagram = loads_diagram(text.replace("log: [plant.y]", "log: [plant.y, err.y]"))
    assert not blocks.build_schedule(logged_diagram, logged_diagram.t_end).advanced
    logged = simulate(logged_diagram)
    np.testing.assert_allclose(base["plant.y"][1], logged["plant.y"][1], rtol=1e-12, atol=0)
    t_err, err = logged["err.y"]
    assert len(t_err) == 10001
    np.testing.assert_allclose(err[:, 0], 1.0 - logged["plant.y"][1][:, 0], atol=1e-15)


def test_offset_block_fires_at_exact_offsets():
    res = run(f"""
time: {{t_end: 5 ms}}
blocks:
  clk: {{type: "{DEFS}:Clock", period: 1 ms, offset: 0.5 ms}}
  fast: {{type: "{DEFS}:Clock", period: 0.25 ms}}
log: [clk.y, fast.y]
""")
    t, y = res["clk.y"]
    np.testing.assert_array_equal(t, [0.0005, 0.0015, 0.0025, 0.0035, 0.0045])
    np.testing.assert_array_equal(y[:, 0], t)
    tf, _ = res["fast.y"]
    assert len(tf) == 21 and tf[2] == 0.0005 and tf[-1] == 0.005


def test_step_switches_exactly_at_a_decimal_time():
    """0.3 s is not a binary float, but k * tick is computed so the hit at 0.3 s sees t >= 0.3."""
    res = run("""
time: {t_end: 0.5 s}
blocks:
  s: {type: Step, period: 0.1 ms, params: {time: 0.3}}
log: [s.y]
""")
    t, y = res["s.y"]
    first = int(np.argmax(y[:, 0] > 0.5))
    assert first == 3000 and t[first] == 0.3


def test_inherited_block_fires_when_any_source_fires():
    res = run(f"""
time: {{t_end: 6 ms}}
blocks:
  a: {{type: "{DEFS}:Clock", period: 2 ms}}
  b: {{type: "{DEFS}:Clock", period: 3 ms}}
  s: {{type: Sum, params: {{signs: "++"}}}}
connections: [a.y -> s.u0, b.y -> s.u1]
log: [s.y]
""")
    t, y = res["s.y"]
    np.testing.assert_allclose(t, [0, 0.002, 0.003, 0.004, 0.006])
    # held values: a at 0,2,4,6 ms; b at 0,3,6 ms
    np.testing.assert_allclose(y[:, 0], [0, 0.002, 0.005, 0.007, 0.012])


def test_constant_source_feeds_a_fast_block():
    res = run("""
time: {t_end: 2 ms}
blocks:
  c: {type: Constant, params: {value: [1.5, -2.0]}}
  g: {type: Gain, period: 0.1 ms, params: {k: 2.0}}
connections: [c.y -> g.u]
log: [g.y, c.y]
""")
    t, y = res["g.y"]
    assert len(t) == 21
    np.testing.assert_array_equal(y, np.tile([3.0, -4.0], (21, 1)))
    tc, yc = res["c.y"]
    np.testing.assert_array_equal(tc, [0.0])


def test_value_logged_at_t_end_is_the_state_after_the_last_update():
    res = accumulate_ones("Accumulator", "1 ms", "10 ms")
    t, y = res["acc.y"]
    np.testing.assert_array_equal(t, np.arange(11) / 1000)
    np.testing.assert_array_equal(y[:, 0], np.arange(11))


def test_delay_one_sample_of_the_destination_rate():
    res = run(f"""
time: {{t_end: 5 ms}}
blocks:
  clk: {{type: "{DEFS}:Clock", period: 0.5 ms}}
  g: {{type: Gain, period: 1 ms, params: {{k: 1.0}}}}
connections:
  - {{from: clk.y, to: g.u, delay: 1, initial: -1.0}}
log: [g.y]
""")
    t, y = res["g.y"]
    np.testing.assert_allclose(t, np.arange(6) / 1000)
    # at g's hit j it sees clk as sampled at g's hit j-1
    np.testing.assert_allclose(y[:, 0], [-1.0, 0.0, 0.001, 0.002, 0.003, 0.004])


def test_delay_breaks_an_algebraic_loop():
    """y[k] = 0.5 * y[k-1] + 1 through a delayed feedback wire: the closed form 2 - 2^-k."""
    res = run("""
time: {t_end: 10 ms}
blocks:
  one: {type: Constant, params: {value: 1.0}}
  s: {type: Sum, period: 1 ms, params: {signs: "++"}}
  g: {type: Gain, params: {k: 0.5}}
connections:
  - one.y -> s.u0
  - s.y -> g.u
  - {from: g.y, to: s.u1, delay: 1}
log: [s.y]
""")
    t, y = res["s.y"]
    k = np.arange(11)
    expected = np.concatenate(([1.0], 2 - 0.5 ** k[1:] * 1.0))
    expected = 2 - 0.5 ** k
    np.testing.assert_allclose(y[:, 0], expected, atol=1e-15)


def test_zero_order_hold_between_rates_both_ways():
    res = run(f"""
time: {{t_end: 4 ms}}
blocks:
  slow: {{type: "{DEFS}:Clock", period: 1 ms}}
  up: {{type: Gain, period: 0.25 ms, params: {{k: 1.0}}}}
  fast: {{type: "{DEFS}:Clock", period: 0.25 ms}}
  down: {{type: ZeroOrderHold, period: 1 ms}}
connections: [slow.y -> up.u, fast.y -> down.u]
log: [up.y, down.y]
""")
    t, y = res["up.y"]
    np.testing.assert_allclose(y[:, 0], np.floor(t * 1000 + 1e-9) / 1000)
    td, yd = res["down.y"]
    np.testing.assert_allclose(yd[:, 0], td)


def test_fast_advance_gives_the_same_result_as_stepping():
    text = """
time: {{t_end: 20 ms}}
blocks:
  src: {{type: "{defs}:Clock", period: 1 ms}}
  acc: {{type: "{defs}:{kind}", period: 0.1 ms}}
  g: {{type: Gain, params: {{k: -0.01}}}}
  s: {{type: Sum, params: {{signs: "++"}}}}
connections: [src.y -> s.u0, acc.y -> g.u, g.y -> s.u1, s.y -> acc.u]
log: [acc.y, {{signal: src.y, decimate: 3}}]
"""
    slow = loads_diagram(text.format(defs=DEFS, kind="Accumulator"), trust=True)
    fast = loads_diagram(text.format(defs=DEFS, kind="FastAccumulator"), trust=True)
    # acc feeds itself through g and s, so it cannot be advanced; make the loop slow instead
    assert not blocks.build_schedule(fast, fast.t_end).advanced
    text_open = text.replace("acc.y -> g.u, g.y -> s.u1", "src.y -> g.u, g.y -> s.u1")
    slow = loads_diagram(text_open.format(defs=DEFS, kind="Accumulator"), trust=True)
    fast = loads_diagram(text_open.format(defs=DEFS, kind="FastAccumulator"), trust=True)
    assert blocks.build_schedule(fast, fast.t_end).advanced == {"acc"}
    assert not blocks.build_schedule(slow, slow.t_end).advanced
    r_slow, r_fast = simulate(slow), simulate(fast)
    for name in ("acc.y", "src.y"):
        np.testing.assert_array_equal(r_slow[name][0], r_fast[name][0])
        np.testing.assert_allclose(r_slow[name][1], r_fast[name][1], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(r_fast["src.y"][0], np.arange(0, 21, 3) / 1000)


def test_per_port_feedthrough_allows_a_loop_through_the_non_feedthrough_port():
    """held -> gain -> u is no algebraic loop because only 'direct' reads u."""
    res = run(f"""
time: {{t_end: 5 ms}}
blocks:
  b: {{type: "{DEFS}:SplitFeedthrough", period: 1 ms}}
  g: {{type: Gain, params: {{k: 2.0}}}}
connections: [b.held -> g.u, g.y -> b.u]
log: [b.direct, b.held]
""")
    _, direct = res["b.direct"]
    _, held = res["b.held"]
    # held[k] = 2^k (state <- 2 * held), direct[k] = 2 * held[k]
    np.testing.assert_allclose(held[:, 0], 2.0 ** np.arange(6))
    np.testing.assert_allclose(direct[:, 0], 2.0 ** np.arange(1, 7))


def test_failure_keeps_partial_results():
    res = run(f"""
time: {{t_end: 10 ms}}
blocks:
  clk: {{type: "{DEFS}:Clock", period: 1 ms}}
  f: {{type: "{DEFS}:FailAfter", params: {{t_fail: 0.0045}}}}
connections: [clk.y -> f.u]
log: [clk.y, f.y]
""")
    assert not res.complete
    assert res.status.startswith("failed at t=0.005 s") and "'f'" in res.status and "f.y" in res.status
    t, y = res["f.y"]
    np.testing.assert_allclose(t, [0, 0.001, 0.002, 0.003, 0.004])
    assert res["clk.y"][0][-1] == 0.005


def test_a_failing_advance_span_keeps_the_rows_it_completed():
    """Stepped or advanced, the run fails at the same hit and logs the same samples."""
    text = """
time: {{t_end: 10 ms}}
blocks:
  one: {{type: Constant, params: {{value: 1.0}}}}
  acc: {{type: "{defs}:{kind}", period: 0.1 ms, params: {{limit: 23.5}}}}
  clk: {{type: "{defs}:Clock", period: 1 ms}}
connections: [one.y -> acc.u]
log: [acc.y, clk.y]
"""
    stepped = loads_diagram(text.format(defs=DEFS, kind="CappedAccumulator"), trust=True)
    advanced = loads_diagram(text.format(defs=DEFS, kind="FastCappedAccumulator"), trust=True)
    assert blocks.build_schedule(advanced, advanced.t_end).advanced == {"acc"}
    r_step, r_adv = simulate(stepped), simulate(advanced)
    # the state reaches 23 at 2.3 ms; the update there would make it 24 > 23.5
    assert r_step.status.startswith("failed at t=0.0023 s") and "'acc'" in r_step.status
    assert r_adv.status.startswith("failed at t=0.0023 s") and "advance: state passes 23.5" in r_adv.status
    t, y = r_adv["acc.y"]
    np.testing.assert_array_equal(t, r_step["acc.y"][0])
    np.testing.assert_array_equal(y, r_step["acc.y"][1])
    np.testing.assert_allclose(t[-1], 0.0023)
    np.testing.assert_array_equal(y[:, 0], np.arange(24.0))


def test_a_long_program_keeps_its_order_and_failures():
    """A program of 150 steps runs them in order, and a failure at its end names its block."""
    n = 150
    gains = "\n".join(f"  g{i}: {{type: Gain, params: {{k: 2.0}}}}" for i in range(n))
    chain = [f"g{i - 1}.y -> g{i}.u" for i in range(1, n)]
    wires = ", ".join(["clk.y -> g0.u", *chain, f"g{n - 1}.y -> f.u"])
    res = run(f"""
time: {{t_end: 10 ms}}
blocks:
  clk: {{type: "{DEFS}:Clock", period: 1 ms}}
{gains}
  f: {{type: "{DEFS}:FailAfter", params: {{t_fail: 0.0045}}}}
connections: [{wires}]
log: [g{n - 1}.y, f.y]
""")
    assert res.status.startswith("failed at t=0.005 s: block 'f'")
    assert "f.y output: value out of range" in res.status
    t, y = res[f"g{n - 1}.y"]
    np.testing.assert_array_equal(y[:, 0], t * 2.0 ** n)
    np.testing.assert_array_equal(res["f.y"][1][:, 0], y[:5, 0])


def test_failure_can_raise_with_results():
    diagram = loads_diagram(f"""
time: {{t_end: 10 ms}}
blocks:
  clk: {{type: "{DEFS}:Clock", period: 1 ms}}
  f: {{type: "{DEFS}:FailAfter", params: {{t_fail: 0.003}}}}
connections: [clk.y -> f.u]
log: [f.y]
""", trust=True)
    with pytest.raises(blocks.SimulationError) as info:
        simulate(diagram, raise_on_failure=True)
    assert info.value.block == "f" and info.value.port == "y" and info.value.time == 0.003
    assert len(info.value.results["f.y"][0]) == 3


def test_progress_reaches_one():
    calls = []
    simulate(blocks.load_diagram(ROOT / "diagrams" / "toy.yaml"), t_end="0.5 s",
             progress=lambda f, e: calls.append(f))
    assert calls[-1] == 1.0 and all(0 <= f <= 1 for f in calls)
    assert calls == sorted(calls)


def test_simulate_end_time_override_must_fit_the_base_tick():
    diagram = blocks.load_diagram(ROOT / "diagrams" / "toy.yaml")
    with pytest.raises(blocks.DiagramError, match="not a multiple of the base tick"):
        simulate(diagram, t_end="0.00005")
    assert simulate(diagram, t_end="2 ms")["plant.y"][0][-1] == 0.002


def test_a_diagram_object_is_reusable():
    diagram = blocks.load_diagram(ROOT / "diagrams" / "toy.yaml")
    a = simulate(diagram, t_end=0.1)
    b = simulate(diagram, t_end=0.1)
    np.testing.assert_array_equal(a["plant.y"][1], b["plant.y"][1])


def test_chained_fast_blocks_are_not_both_advanced():
    """b reads a's output, which changes at every hit of a: only one of them may be advanced."""
    text = f"""
time: {{t_end: 5 ms}}
blocks:
  src: {{type: "{DEFS}:Clock", period: 1 ms}}
  b: {{type: "{DEFS}:FastAccumulator", period: 0.1 ms}}
  a: {{type: "{DEFS}:FastAccumulator", period: 0.1 ms}}
connections: [src.y -> a.u, a.y -> b.u]
log: [b.y]
"""
    diagram = loads_diagram(text, trust=True)
    assert len(blocks.build_schedule(diagram, diagram.t_end).advanced) <= 1
    reference = loads_diagram(text.replace("FastAccumulator", "Accumulator"), trust=True)
    np.testing.assert_allclose(simulate(diagram)["b.y"][1], simulate(reference)["b.y"][1], rtol=1e-12)


def test_every_advance_chunk_starts_at_its_exact_tick_time():
    """A span of several ADVANCE_CHUNK hits: each chunk gets ``k * base_tick`` of its first
    tick, computed from the integer k (adding up chunks of 4096 periods of 0.1 ms in
    floats gives 1.2288000000000001 s, not 1.2288 s, for the fourth chunk)."""
    from blocks.engine.optable import ADVANCE_CHUNK

    r = accumulate_ones("ChunkStart", "0.1 ms", "1.6384 s")
    t, y = r["acc.y"]
    hits = np.arange(1, len(t))
    first_tick = (hits - 1) // ADVANCE_CHUNK * ADVANCE_CHUNK
    assert len(t) == 4 * ADVANCE_CHUNK + 1
    assert [float(y[i, 0]) for i in hits] == [int(k) / 10000 for k in first_tick]


def test_an_interrupt_inside_one_long_advance_span_records_the_time_reached():
    """No other block fires after t = 0, so the whole run is one advance span, made of
    chunks of ADVANCE_CHUNK hits; Ctrl-C in the third chunk stops it after two."""
    from blocks.engine.optable import ADVANCE_CHUNK

    r = accumulate_ones("InterruptedAccumulator", "1 ms", "1000 s", "{calls: 3}")
    reached = 2 * ADVANCE_CHUNK * 1e-3
    assert r.interrupted and r.status == f"interrupted at t={reached:.9g} s", r.status
    t, y = r["acc.y"]
    assert t[-1] == pytest.approx(reached) and y[-1, 0] == 2 * ADVANCE_CHUNK
    assert r.info["t_stop"] == pytest.approx(reached)


@pytest.mark.parametrize("t_end", ["0", "-1 ms", "soon", "1e20 s"])
def test_an_end_time_is_checked_by_one_rule_wherever_it_is_given(t_end):
    """In the diagram file, to ``simulate`` and as ``--t-end``, a bad end time is refused
    with one message, after the name it was given by."""
    import argparse

    from blocks.cli.options import end_time
    from blocks.cli.program import UsageError
    from blocks.issues import DiagramError

    text = "blocks:\n  c: {type: Constant, period: 1 ms, params: {value: 1.0}}\n"
    with pytest.raises(DiagramError) as in_file:
        loads_diagram(f"time: {{t_end: '{t_end}'}}\n" + text)
    diagram = loads_diagram(text)
    with pytest.raises(DiagramError) as in_python:
        simulate(diagram, t_end=t_end)
    with pytest.raises(UsageError) as in_cli:
        end_time(argparse.Namespace(t_end=t_end), diagram)
    said = [in_file.value.issues[0].message, in_python.value.issues[0].message, str(in_cli.value)]
    names = ["time.t_end", "t_end", "--t-end"]
    assert all(message.startswith(name) for message, name in zip(said, names))
    assert len({message.removeprefix(name) for message, name in zip(said, names)}) == 1


def test_without_an_end_time_a_run_is_refused_the_same_way_from_python_and_the_command_line():
    import argparse

    from blocks.cli.options import end_time
    from blocks.issues import DiagramError

    diagram = loads_diagram("blocks:\n  c: {type: Constant, period: 1 ms, params: {value: 1.0}}\n")
    with pytest.raises(DiagramError) as in_python:
        simulate(diagram)
    with pytest.raises(DiagramError) as in_cli:
        end_time(argparse.Namespace(t_end=None), diagram)
    assert in_python.value.issues[0].message == in_cli.value.issues[0].message == "no end time"
