"""Diagrams run in several threads at once (blocks/csrc/native_run_hooks.c releasing the GIL).

The executor runs kernels that say ``nogil`` with the GIL released, so threads that
simulate diagrams run in parallel. What a thread gets must not depend on that: the toy
diagram (library kernels) run in two threads at once, round after round, gives every
logged sample and time of a serial run, bit for bit. The gate kernel (``kernel_sources/
leak.c``) shows the GIL released: its output waits for a flag that only another thread's
Python code can set. Equality is asserted here, never timing.
"""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

from blocks import Block, load_diagram, loads_diagram, simulate
from blocks.engine.kernel import Kernel
from blocks.registry import block_types

from ..kernel_library import function

TOY = Path(__file__).resolve().parents[3] / "diagrams" / "toy.yaml"
ROUNDS = 5


def assert_same(a, b) -> None:
    assert a.status == b.status and list(a) == list(b)
    for name in a:
        assert np.array_equal(a[name][0], b[name][0]) and np.array_equal(a[name][1], b[name][1]), name


def in_threads(run, count: int = 2) -> list:
    """``run(i)`` for i in range(count), each in a thread of its own, all at once."""
    with ThreadPoolExecutor(count) as pool:
        return list(pool.map(run, range(count)))


def test_the_toy_diagram_in_two_threads_at_once_gives_the_serial_samples():
    serial = simulate(load_diagram(TOY))
    assert serial.complete
    for _ in range(ROUNDS):
        for r in in_threads(lambda i: simulate(load_diagram(TOY))):
            assert_same(r, serial)


def test_one_toy_diagram_simulated_in_two_threads_at_once_gives_the_serial_samples():
    d = load_diagram(TOY)
    serial = simulate(d)
    for _ in range(ROUNDS):
        for r in in_threads(lambda i: simulate(d)):
            assert_same(r, serial)


class Gate(Block):
    """y = 1 once the gate is open (``gate_output``); patience in seconds."""

    type_name = "TestGate"
    lib = None

    def __init__(self, patience=30.0):
        self.flags = np.array([0.0, 0.0, patience])
        self.inputs, self.outputs = {}, {"y": 1}

    def output(self, t, state, inputs):
        raise AssertionError("runs compiled")

    def kernel(self):
        return Kernel(context=self.flags.ctypes.data, output=function(self.lib, "gate_output"),
                      owners=(self.flags, self.lib), nogil=True)


GATED = """
time: {t_end: 1 ms}
blocks:
  gate: {type: TestGate, period: 1 ms}
log: [gate.y]
"""


@pytest.fixture
def gate(library, monkeypatch):
    Gate.lib = library
    monkeypatch.setitem(block_types(), Gate.type_name, Gate)
    return loads_diagram(GATED, filename="gate.yaml")


def open_when_waiting(gate: Gate) -> None:
    """Open the gate once its output waits (seen from Python, so with the GIL released)."""
    while gate.flags[1] == 0.0:
        threading.Event().wait(0.001)
    gate.flags[0] = 1.0


@pytest.mark.parametrize("where", ["worker thread", "main thread"])
def test_a_nogil_kernel_runs_with_the_gil_released(gate, where):
    """Run in a worker thread, the main thread opens the gate; run in the main thread (which
    releases the GIL while another thread exists), a helper thread opens it."""
    block = gate.blocks["gate"].block
    if where == "worker thread":
        with ThreadPoolExecutor(1) as pool:
            future = pool.submit(simulate, gate)
            open_when_waiting(block)
            r = future.result()
    else:
        helper = threading.Thread(target=open_when_waiting, args=(block,))
        helper.start()
        r = simulate(gate)
        helper.join()
    assert r.complete, r.status
    assert r["gate.y"][1].ravel().tolist() == [1.0, 1.0]
