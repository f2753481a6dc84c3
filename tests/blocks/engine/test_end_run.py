"""A block ends a run early by raising EndRun from its update: the run goes on to the
block's next hit, ends there as at a normal end time, and is complete."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import blocks
from blocks import EndRun, Results, loads_diagram, simulate

REPO = Path(__file__).resolve().parents[3]
DEFS = "python:tests.blocks.blockdefs"

THREE_RATES = f"""
name: three-rates
time: {{t_end: 20 ms}}
blocks:
  count: {{type: "{DEFS}:Counter", period: 2 ms, params: {{stop: 4}}}}
  fast: {{type: "{DEFS}:Clock", period: 1 ms}}
  slow: {{type: "{DEFS}:Clock", period: 5 ms}}
log: [count.y, fast.y, slow.y]
"""


def run(text: str, t_end=None):
    return simulate(loads_diagram(text, filename="test.yaml", trust=True), t_end=t_end)


def test_the_run_ends_complete_at_the_blocks_next_hit():
    """count updates at 0, 2, 4 and 6 ms to 1, 2, 3 and 4; at 6 ms it asks to end, so the
    run ends at its next hit, 8 ms, with the outputs there logged as at a normal end."""
    r = run(THREE_RATES)
    assert r.complete and r.status == "complete"
    assert r.ended_by == {"block": "count", "type": "Counter", "time": 0.008, "tick_time": 0.006,
                          "reason": "the count reached 4"}
    assert r.info["t_stop"] == r.stop_time == 0.008
    t, y = r["count.y"]
    np.testing.assert_allclose(t, [0, 0.002, 0.004, 0.006, 0.008])
    np.testing.assert_array_equal(y[:, 0], [0, 1, 2, 3, 4])  # the last output is the state EndRun gave
    t_fast, y_fast = r["fast.y"]
    np.testing.assert_allclose(t_fast, np.arange(9) / 1000)   # the faster block ran up to the end
    np.testing.assert_allclose(y_fast[:, 0], t_fast)
    np.testing.assert_allclose(r["slow.y"][0], [0, 0.005])    # the slower block's next hit is past it
    assert r.end_note == ("ended at t=0.008 s by block 'count' (Counter): "
                          "the count reached 4 (asked in its update at t=0.006 s)")
    assert r.info["real_time_factor"] == pytest.approx(0.008 / r.info["wall_time_s"])


def test_without_a_state_the_block_keeps_the_state_it_had():
    r = run(THREE_RATES.replace("stop: 4", "stop: 4, give_state: false"))
    assert r.ended_by["time"] == 0.008
    np.testing.assert_array_equal(r["count.y"][1][:, 0], [0, 1, 2, 3, 3])


def test_an_earlier_t_end_wins():
    """Asked at 6 ms, the end would be 8 ms; t_end = 7 ms comes first and the run is an
    ordinary one to t_end."""
    r = run(THREE_RATES, t_end="7 ms")
    assert r.complete and r.ended_by is None and r.stop_time is None and r.info["t_stop"] is None
    assert r["fast.y"][0][-1] == 0.007
    assert r["count.y"][0][-1] == 0.006


def test_a_run_that_ends_normally_has_no_ended_by():
    r = run(THREE_RATES.replace("stop: 4", "stop: 100"))
    assert r.complete and r.ended_by is None and r.end_note is None and r.stop_time is None
    assert r["fast.y"][0][-1] == 0.020


def test_an_inherited_block_ends_at_its_next_firing():
    """count inherits clk's 3 ms rate: it asks at 6 ms and the run ends at 9 ms."""
    r = run(f"""
time: {{t_end: 20 ms}}
blocks:
  clk: {{type: "{DEFS}:Clock", period: 3 ms}}
  fast: {{type: "{DEFS}:Clock", period: 1 ms}}
  count: {{type: "{DEFS}:Counter", params: {{stop: 3}}}}
connections: [clk.y -> count.u]
log: [count.y, fast.y]
""")
    assert (r.ended_by["tick_time"], r.ended_by["time"]) == (0.006, 0.009)
    np.testing.assert_allclose(r["count.y"][0], [0, 0.003, 0.006, 0.009])
    np.testing.assert_array_equal(r["count.y"][1][:, 0], [0, 1, 2, 3])
    assert r["fast.y"][0][-1] == 0.009


def test_when_two_blocks_ask_in_one_tick_the_first_is_reported_and_the_earliest_end_taken():
    """At 4 ms both ask: a (every 4 ms) would end at 8 ms, b (every 2 ms) at 6 ms."""
    r = run(f"""
time: {{t_end: 20 ms}}
blocks:
  a: {{type: "{DEFS}:Counter", period: 4 ms, params: {{stop: 2}}}}
  b: {{type: "{DEFS}:Counter", period: 2 ms, params: {{stop: 3}}}}
log: [a.y, b.y]
""")
    assert (r.ended_by["block"], r.ended_by["tick_time"], r.ended_by["time"]) == ("a", 0.004, 0.006)
    assert r["b.y"][0][-1] == 0.006 and r["b.y"][1][-1, 0] == 3
    assert r["a.y"][0][-1] == 0.004


ADVANCED = f"""
time: {{t_end: 10 ms}}
blocks:
  one: {{type: Constant, params: {{value: 1.0}}}}
  acc: {{type: "{DEFS}:KIND", period: 0.1 ms}}
  count: {{type: "{DEFS}:Counter", period: 1 ms, params: {{stop: 3}}}}
connections: [one.y -> acc.u]
log: [acc.y, count.y]
"""


def test_an_advanced_block_stops_at_the_new_end():
    """acc is stepped over the spans between count's hits; count asks at 2 ms, so the
    last span ends at 3 ms, as it does when acc is stepped hit by hit."""
    advanced = loads_diagram(ADVANCED.replace("KIND", "FastAccumulator"), trust=True)
    stepped = loads_diagram(ADVANCED.replace("KIND", "Accumulator"), trust=True)
    assert blocks.build_schedule(advanced, advanced.t_end).advanced == {"acc"}
    assert not blocks.build_schedule(stepped, stepped.t_end).advanced
    r_adv, r_step = simulate(advanced), simulate(stepped)
    for r in (r_adv, r_step):
        assert r.complete and r.ended_by["time"] == 0.003
        t, y = r["acc.y"]
        np.testing.assert_allclose(t, np.arange(31) / 10000)
        np.testing.assert_array_equal(y[:, 0], np.arange(31.0))
        np.testing.assert_allclose(r["count.y"][0], [0, 0.001, 0.002, 0.003])


def test_end_run_from_output_fails_the_run():
    r = run(f"""
time: {{t_end: 10 ms}}
blocks:
  e: {{type: "{DEFS}:EndInOutput", period: 1 ms, params: {{t_end: 0.002}}}}
log: [e.y]
""")
    assert not r.complete and r.ended_by is None
    assert r.status == ("failed at t=0.002 s: block 'e' (EndInOutput) output: "
                        "EndRun must be raised from update, not output (done)")
    np.testing.assert_allclose(r["e.y"][0], [0, 0.001])


def test_end_run_from_advance_fails_the_run():
    diagram = loads_diagram(ADVANCED.replace("KIND", "EndInAdvance"), trust=True)
    assert blocks.build_schedule(diagram, diagram.t_end).advanced == {"acc"}
    r = simulate(diagram)
    assert r.status == ("failed at t=0 s: block 'acc' (EndInAdvance) advance: "
                        "EndRun must be raised from update, not advance (done)")


def test_end_run_keeps_its_reason_and_state():
    assert not EndRun("why").has_state
    end = EndRun("why", state=None)
    assert end.has_state and end.state is None and end.reason == "why" and str(end) == "why"


def test_ended_by_is_saved_and_loaded(tmp_path):
    r = run(THREE_RATES)
    r.save(tmp_path / "out")
    assert json.loads((tmp_path / "out" / "run.json").read_text())["ended_by"] == r.ended_by
    again = Results.load(tmp_path / "out")
    assert again.complete and again.ended_by == r.ended_by
    assert again.stop_time == 0.008 and again.end_note == r.end_note


def test_plots_of_an_ended_run_stop_at_its_end():
    from blocks.plot.curves import time_span

    assert time_span(run(THREE_RATES)) == (0.008, None)


def test_cli_run_reports_the_end_and_exits_0(tmp_path):
    diagram = tmp_path / "ends.yaml"
    diagram.write_text(THREE_RATES, encoding="utf-8")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO), env.get("PYTHONPATH", "")) if p)
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "hierhand", "run", str(diagram), "-o", str(out), "--trust",
                           "--csv", "--plot"], capture_output=True, text=True, cwd=tmp_path, env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert ("three-rates: ended at t=0.008 s by block 'count' (Counter): "
            "the count reached 4 (asked in its update at t=0.006 s)") in proc.stdout
    assert "three-rates: 0.008 s simulated in" in proc.stdout
    info = json.loads((out / "run.json").read_text(encoding="utf-8"))
    assert info["status"] == "complete" and info["ended_by"]["block"] == "count" and info["t_stop"] == 0.008
    last = (out / "signals.csv").read_text().splitlines()[-1]
    assert float(last.split(",")[0]) == 0.008
    assert (out / "plots" / "signals.png").is_file()


def test_a_sweep_point_ended_by_a_block_is_ok(tmp_path):
    from blocks.sweep.runner import SweepJob, run_point
    from blocks.sweep.store import OK

    diagram = tmp_path / "ends.yaml"
    diagram.write_text(THREE_RATES, encoding="utf-8")
    outcome = run_point(SweepJob(diagram=str(diagram), trust=True), {"count.stop": 3})
    assert outcome.status == OK, outcome.error
