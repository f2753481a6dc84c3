"""Blocks with compiled kernels (blocks/compiled.py, blocks/csrc/runner.c).

A diagram runs the same whether a block goes through its kernel or its Python methods:
the same logged samples to the last bit, the same status when a block fails, the same
end when a Python block ends the run. The test kernels (``kernel_sources/leak.c``) are
compiled with the calling convention's header by the ``library`` fixture (conftest.py);
their Python twins below compute the same arithmetic in numpy.
"""

from __future__ import annotations

import threading

import numpy as np
import pytest

from blocks import Block, BlockError, EndRun, loads_diagram, simulate
from blocks.kernel import Kernel
from blocks.registry import block_types

from .kernel_library import function


CALLS: dict[str, int] = {}
"""How often the Python methods of the test blocks ran, per block type and method."""


def counted(key: str) -> None:
    CALLS[key] = CALLS.get(key, 0) + 1


class Leak(Block):
    """x <- a x + b u, outputs y = x and sum(x); an update past ``limit`` fails."""

    type_name = "TestLeak"
    lib = None

    def __init__(self, a=0.9, b=0.1, width=2, limit=1e9, x0=0.0, compiled=True, parts="output,update,advance"):
        self.params = np.array([a, b, limit, width], dtype=float)
        self.a, self.b, self.limit, self.width, self.x0 = float(a), float(b), float(limit), int(width), float(x0)
        self.compiled, self.parts = compiled, parts.split(",")
        self.inputs = {"u": width}
        self.outputs = {"y": width, "sum": 1}
        self.feedthrough = False

    def initial_state(self):
        return np.full(self.width, self.x0)

    def output(self, t, state, inputs):
        counted("Leak.output")
        total = 0.0
        for x in state:
            total += x
        return {"y": state.copy(), "sum": np.array([total])}

    def step(self, t, state, u):
        new = self.a * state + self.b * u
        bad = np.flatnonzero(np.abs(new) > self.limit)
        if bad.size:
            raise self.error(7, int(bad[0]), t, "update")
        state[:] = new
        return state

    def update(self, t, state, inputs):
        counted("Leak.update")
        return self.step(t, state, inputs["u"])

    def advance(self, t, state, inputs, n):
        counted("Leak.advance")
        dt = float(self.period)
        rows = np.empty((n, self.width + 1))
        for i in range(n):
            try:
                self.step(t + i * dt, state, inputs["u"])
            except BlockError as exc:
                exc.rows = {"y": rows[:i, :-1], "sum": rows[:i, -1:]}
                raise
            out = self.output(0.0, state, inputs)
            rows[i] = np.concatenate((out["y"], out["sum"]))
        return state, {"y": rows[:, :-1], "sum": rows[:, -1:]}

    @staticmethod
    def error(code, which, t, phase):
        return BlockError(f"x[{which}] past the limit in the step at t={t:.6g} s (code {code})", port="y")

    def kernel(self):
        if not self.compiled:
            return None
        names = {"output": "leak_output", "update": "leak_update", "advance": "leak_advance"}
        return Kernel(context=self.params.ctypes.data, owners=(self.params, self.lib), error=self.error,
                      **{part: function(self.lib, names[part]) for part in self.parts})


class Scale(Block):
    """y = k u, feedthrough."""

    type_name = "TestScale"
    lib = None

    def __init__(self, k=2.0, width=2, compiled=True):
        self.k, self.compiled = float(k), compiled
        self.params = np.array([k, width], dtype=float)
        self.inputs = {"u": width}
        self.outputs = {"y": width}

    def output(self, t, state, inputs):
        counted("Scale.output")
        return {"y": self.k * inputs["u"]}

    def kernel(self):
        if not self.compiled:
            return None
        return Kernel(context=self.params.ctypes.data, output=function(self.lib, "scale_output"),
                      owners=(self.params, self.lib))


class Wave(Block):
    """A Python source: sin(t) and cos(t)."""

    type_name = "TestWave"
    time_varying = True

    def __init__(self):
        self.inputs = {}
        self.outputs = {"y": 2}

    def output(self, t, state, inputs):
        return {"y": np.array([np.sin(7 * t), np.cos(3 * t)])}


class Mix(Block):
    """A Python block with state that keeps what it was given (as a delay might)."""

    type_name = "TestMix"

    def __init__(self, stop_at=None):
        self.stop_at = stop_at
        self.inputs = {"a": 2, "b": 2}
        self.outputs = {"y": 2}
        self.feedthrough = {"y": {"a"}}

    def initial_state(self):
        return [np.zeros(2)]

    def output(self, t, state, inputs):
        return {"y": inputs["a"] - 0.5 * state[0]}

    def update(self, t, state, inputs):
        if self.stop_at is not None and t >= self.stop_at:
            raise EndRun("enough", state=[inputs["b"]])
        return [inputs["b"]]  # kept, not copied: the executor hands it a copy of compiled outputs


class Ticker(Block):
    """Counts its updates; the C kernel sends SIGINT when the count reaches ``at``."""

    type_name = "TestTicker"
    lib = None

    def __init__(self, at=1e9, nogil=False):
        self.params = np.array([at], dtype=float)
        self.nogil = nogil
        self.inputs, self.outputs, self.feedthrough = {}, {"y": 1}, False

    def initial_state(self):
        return np.zeros(1)

    def output(self, t, state, inputs):
        return {"y": state.copy()}

    def update(self, t, state, inputs):
        return state + 1.0

    def advance(self, t, state, inputs, n):
        raise AssertionError("runs compiled")

    def kernel(self):
        return Kernel(context=self.params.ctypes.data, output=function(self.lib, "ticker_output"),
                      advance=function(self.lib, "ticker_advance"), owners=(self.params, self.lib),
                      nogil=self.nogil)


@pytest.fixture(autouse=True)
def registered(library, monkeypatch):
    Leak.lib = Scale.lib = Ticker.lib = library
    for cls in (Leak, Scale, Wave, Mix, Ticker):
        monkeypatch.setitem(block_types(), cls.type_name, cls)
    CALLS.clear()


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
    from blocks.simulate import ADVANCE_CHUNK

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
