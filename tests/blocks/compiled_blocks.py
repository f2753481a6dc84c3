"""Test blocks with compiled kernels (``kernel_sources/leak.c``) and their Python twins.

Each block computes the same arithmetic in its Python methods (numpy, elementwise) as its
kernel in C, so a diagram gives the same samples to the last bit whichever way its blocks
run; ``compiled=False`` keeps a block's kernel from being offered. ``register`` makes the
types known to diagrams (``TestLeak``, ...) for one test.
"""

from __future__ import annotations

import numpy as np

from blocks import Block, BlockError, EndRun
from blocks.engine.kernel import END_RUN, Kernel
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


class Stopper(Block):
    """y = [count, t]; each update adds one, and the one that brings the count to ``stop``
    asks to end the run (EndRun from Python, BLK_END_RUN from the kernel)."""

    type_name = "TestStopper"
    lib = None

    def __init__(self, stop=3, compiled=True):
        self.params = np.array([stop], dtype=float)
        self.stop, self.compiled = float(stop), compiled
        self.inputs, self.outputs, self.feedthrough = {"u": 2}, {"y": 2}, False
        self.input_defaults = {"u": np.zeros(2)}

    def initial_state(self):
        return np.zeros(1)

    def output(self, t, state, inputs):
        return {"y": np.array([state[0], t])}

    def update(self, t, state, inputs):
        new = state + 1.0
        if new[0] == self.stop:
            raise EndRun(f"the count reached {self.stop:g}", state=new)
        return new

    def error(self, code, which, t, phase):
        if code == END_RUN:
            return EndRun(f"the count reached {self.stop:g}")
        return BlockError(f"code {code}")

    def kernel(self):
        if not self.compiled:
            return None
        return Kernel(context=self.params.ctypes.data, output=function(self.lib, "stopper_output"),
                      update=function(self.lib, "stopper_update"), owners=(self.params, self.lib), error=self.error,
                      nogil=True)


class Capped(Block):
    """A Python accumulator x <- x + u of width 2, advanced in closed form, that fails once
    x[0] would pass ``limit``; a failing advance hands back the rows it completed."""

    type_name = "TestCapped"

    def __init__(self, limit=1e9):
        self.limit = float(limit)
        self.inputs, self.outputs, self.feedthrough = {"u": 2}, {"y": 2}, False

    def initial_state(self):
        return np.zeros(2)

    def output(self, t, state, inputs):
        return {"y": state.copy()}

    def update(self, t, state, inputs):
        new = state + inputs["u"]
        if new[0] > self.limit:
            raise BlockError(f"state passes {self.limit:g}", port="y")
        return new

    def advance(self, t, state, inputs, n):
        rows = np.empty((n, 2))
        x = state.copy()
        for i in range(n):
            new = x + inputs["u"]
            if new[0] > self.limit:
                raise BlockError(f"state passes {self.limit:g}", port="y", rows={"y": rows[:i]})
            rows[i] = x = new
        return x, {"y": rows}


TYPES = (Leak, Scale, Wave, Mix, Ticker, Stopper, Capped)


def register(library, monkeypatch) -> None:
    """The test types known to diagrams, their kernels from ``library``."""
    for cls in TYPES:
        cls.lib = library
        monkeypatch.setitem(block_types(), cls.type_name, cls)
    CALLS.clear()
