"""Blocks with compiled kernels (blocks/engine/compiled.py), run by the C core (blocks/csrc/core.c).

A diagram runs the same whether a block goes through its kernel or its Python methods:
the same logged samples to the last bit, the same status when a block fails, the same
end when a Python block ends the run. The test blocks (``compiled_blocks.py``) have
kernels (``kernel_sources/leak.c``, compiled by the ``library`` fixture, conftest.py) and
Python twins that compute the same arithmetic in numpy.
"""

from __future__ import annotations

import threading

import numpy as np
import pytest

from blocks import loads_diagram, simulate

from ..compiled_blocks import CALLS, Leak, Scale, register


@pytest.fixture(autouse=True)
def registered(library, monkeypatch):
    register(library, monkeypatch)


MIXED = """
time: {t_end: %(t_end)s}
blocks:
  wave:  {type: TestWave, period: 1 ms}
  lift:  {type: TestScale, period: 1 ms, params: {k: -1.5, compiled: %(compiled)s}}
  fast:  {type: TestLeak, period: 0.1 ms, params: {compiled: %(compiled)s, limit: %(limit)s}}
  slow:  {type: TestLeak, period: 1 ms, params: {a: 0.5, b: 2.0, compiled: %(compiled)s}}
  mix:   {type: TestMix, period: 10 ms, params: {stop_at: %(stop_at)s}}
  back:  {type: TestScale, period: 1 ms, params: {k: 3.0, compiled: %(compiled)s}}
  slow2: {type: TestLeak, period: 2 ms, params: {a: 0.7, b: 0.3, compiled: %(compiled)s}}
connections:
  - wave.y -> lift.u                       # Python -> compiled
  - lift.y -> fast.u                       # compiled -> compiled
  - fast.y -> slow.u
  - slow.y -> mix.a                        # compiled -> Python
  - {from: fast.y, to: mix.b, delay: 1}    # compiled -> Python, delayed
  - {from: mix.y, to: back.u, delay: 1}    # Python -> compiled, delayed
  - back.y -> slow2.u
log:
  - {signal: fast.y, decimate: 3}
  - fast.sum
  - slow.y
  - lift.y
  - mix.y
  - back.y
  - {signal: slow2.sum, decimate: 2}
"""


def run_mixed(compiled: bool, t_end="95.3 ms", limit=1e9, stop_at=None):
    text = MIXED % {"compiled": str(compiled).lower(), "t_end": t_end, "limit": limit,
                    "stop_at": "null" if stop_at is None else stop_at}
    return simulate(loads_diagram(text, filename="mixed.yaml"))


def assert_same(a, b):
    assert a.status == b.status
    assert set(a) == set(b)
    for name in a:
        (ta, va), (tb, vb) = a[name], b[name]
        assert np.array_equal(ta, tb), name
        assert np.array_equal(va, vb), name


@pytest.mark.parametrize("t_end", ["95.3 ms", "100 ms", "0.4 ms"])
def test_compiled_and_python_blocks_give_the_same_samples(t_end):
    compiled = run_mixed(True, t_end)
    assert CALLS == {}, "the compiled blocks' Python methods ran"
    python = run_mixed(False, t_end)
    assert CALLS["Leak.advance"] > 0
    assert compiled.complete
    assert_same(compiled, python)
    if t_end != "0.4 ms":
        assert all(np.any(compiled[s][1] != 0) for s in compiled)


def test_a_kernel_without_a_needed_function_leaves_its_block_in_python():
    text = MIXED % {"compiled": "true", "t_end": "20 ms", "limit": 1e9, "stop_at": "null"}
    text = text.replace("limit: 1000000000.0}", "limit: 1000000000.0, parts: 'output,update'}")
    assert "parts:" in text
    partial = simulate(loads_diagram(text, filename="partial.yaml"))
    assert CALLS.get("Leak.advance", 0) > 0 and "Leak.update" not in CALLS  # fast in Python, slow compiled
    CALLS.clear()
    assert_same(partial, run_mixed(False, "20 ms"))


def test_a_kernel_failure_is_the_blocks_own_error_with_the_rows_before_it():
    compiled = run_mixed(True, limit=0.04)
    python = run_mixed(False, limit=0.04)
    assert compiled.status.startswith("failed at t=")
    assert "block 'fast' (TestLeak), signal fast.y advance: x[" in compiled.status
    assert "past the limit" in compiled.status
    assert_same(compiled, python)


def test_a_python_block_ending_the_run_ends_the_compiled_ones_there():
    compiled = run_mixed(True, t_end="100 ms", stop_at=0.05)
    python = run_mixed(False, t_end="100 ms", stop_at=0.05)
    assert compiled.complete and compiled.ended_by["block"] == "mix"
    assert compiled["fast.sum"][0][-1] == pytest.approx(0.06)
    assert_same(compiled, python)


@pytest.mark.parametrize("limit", [1e9, 0.8])
def test_all_compiled_events_fuse_and_keep_every_sample(limit):
    text = """
time: {t_end: 0.2 s}
blocks:
  a: {type: TestLeak, period: 1 ms, params: {a: 0.99, b: 0.5, width: 3, x0: 1.0}}
  k: {type: TestScale, period: 5 ms, params: {k: -0.5, width: 3}}
  z: {type: TestLeak, period: 0.25 ms, params: {a: 0.9, b: 1.0, width: 3, limit: %s}}
connections:
  - {from: a.y, to: k.u}
  - {from: k.y, to: a.u, delay: 1}
  - {from: a.y, to: z.u}
log: [a.y, k.y, {signal: z.sum, decimate: 7}]
"""
    d = loads_diagram(text % limit, filename="fused.yaml")
    compiled = simulate(d)
    assert CALLS == {}
    d.blocks["a"].block.compiled = d.blocks["k"].block.compiled = d.blocks["z"].block.compiled = False
    python = simulate(d)
    assert_same(compiled, python)
    if limit > 1:
        assert compiled.complete and len(compiled["z.sum"][0]) == -(-801 // 7)
    else:
        assert "block 'z' (TestLeak), signal z.y advance: x[0] past the limit" in compiled.status


@pytest.mark.parametrize("nogil", [False, True])
def test_ctrl_c_in_a_long_compiled_advance_stops_after_the_chunk_it_came_in(nogil):
    """No block fires after t = 0, so the run is one advance in C, in chunks of
    ADVANCE_CHUNK hits; SIGINT in the third chunk stops the run at its end, everything up
    to there logged. The same with the GIL released around the chunks (a nogil kernel,
    while another thread waits): the check between chunks takes it back."""
    from blocks.engine.optable import ADVANCE_CHUNK

    text = f"""
time: {{t_end: 1000 s}}
blocks:
  tick: {{type: TestTicker, period: 1 ms, params: {{at: {2 * ADVANCE_CHUNK + 5}, nogil: {nogil}}}}}
log: [tick.y]
"""
    done = threading.Event()
    waiting = threading.Thread(target=done.wait)
    waiting.start()
    try:
        r = simulate(loads_diagram(text, filename="ticker.yaml"))
    finally:
        done.set()
        waiting.join()
    reached = 3 * ADVANCE_CHUNK
    assert r.interrupted and r.status == f"interrupted at t={reached * 1e-3:.9g} s", r.status
    t, y = r["tick.y"]
    assert len(t) == reached + 1 and y[-1, 0] == reached and t[-1] == pytest.approx(reached * 1e-3)


def test_a_kernel_that_cannot_be_made_fails_the_run_naming_its_block(monkeypatch):
    def broken(self):
        raise RuntimeError("no such function in the library")

    monkeypatch.setattr(Scale, "kernel", broken)
    r = run_mixed(True, "10 ms")
    assert r.status == ("failed at t=0 s: block 'lift' (TestScale) kernel: no such function in the library"), \
        r.status


def test_an_input_default_of_another_width_keeps_its_block_in_python(monkeypatch):
    """A kernel reads as many values as the port is wide, so it never sees a default of
    another width: the block runs in Python, which meets it as it always has."""
    monkeypatch.setattr(Scale, "input_defaults", {"u": np.ones(1)})
    text = """
time: {t_end: 3 ms}
blocks:
  g: {type: TestScale, period: 1 ms, params: {k: 2.0}}
log: [g.y]
"""
    r = simulate(loads_diagram(text, filename="default.yaml"))
    assert CALLS.get("Scale.output", 0) == 1  # through Python, which finds the width wrong
    assert "output 'y' must be a float64 array of shape (2,), got shape (1,)" in r.status


def test_a_default_input_holds_until_its_compiled_source_first_fires(monkeypatch):
    """A connected input with a default holds the default until its source's first hit
    (here an offset one): the same whether the blocks run compiled or in Python."""
    monkeypatch.setattr(Leak, "input_defaults", {"u": np.array([3.0, -1.0])})
    text = """
time: {t_end: 10 ms}
blocks:
  src:  {type: TestLeak, period: 5 ms, offset: 4 ms, params: {x0: 2.0, compiled: %s}}
  leak: {type: TestLeak, period: 1 ms, params: {compiled: %s}}
connections: [src.y -> leak.u]
log: [leak.y, src.y]
"""
    compiled = simulate(loads_diagram(text % ("true", "true"), filename="offset.yaml"))
    python = simulate(loads_diagram(text % ("false", "false"), filename="offset.yaml"))
    assert_same(compiled, python)
    assert compiled["leak.y"][1][1, 0] == pytest.approx(0.1 * 3.0)  # the default, before src fires at 4 ms
