"""KernelBlock: every library block is defined once, by its C kernel, which its Python
methods call; so without the compiled extension such a block loads and validates but says,
at its first hit, why it cannot run; and its kernel follows a parameter changed between
runs."""

from __future__ import annotations

from fractions import Fraction

import numpy as np

import pytest

import blocks
from blocks.block import Block
from blocks.library import LIBRARY, Bias, _kernels
from blocks.library.kernel_block import KernelBlock

DIAGRAM = """
blocks:
  s: {type: Sine, period: 1 ms}
  b: {type: Bias, params: {bias: 1.0}}
connections: [s.y -> b.u]
log: [b.y]
"""


@pytest.mark.parametrize("cls", LIBRARY, ids=lambda cls: cls.__name__)
def test_every_library_block_is_defined_once_by_its_kernel(cls):
    """No block of the library has a step of its own beside its kernel's: its output,
    update and advance are KernelBlock's, which call the C functions (or Block's advance,
    which steps them)."""
    assert issubclass(cls, KernelBlock)
    for method in ("output", "update", "advance"):
        owner = next(c for c in cls.__mro__ if method in vars(c))
        assert owner.__module__ in (KernelBlock.__module__, Block.__module__), (method, owner)


def test_without_the_extension_a_signal_block_loads_and_says_why_it_cannot_run(monkeypatch):
    monkeypatch.setattr(_kernels, "functions", lambda: {})
    monkeypatch.setattr(blocks.engine.compiled, "usable_kernel", lambda *args: None)
    diagram = blocks.loads_diagram(DIAGRAM)
    assert diagram.blocks["b"].block.kernel() is None
    results = blocks.simulate(diagram, t_end="2 ms")
    assert results.status.startswith("failed at t=0 s")
    assert "runs its compiled kernel, and the extension blocks._native is missing" in results.status


def test_a_parameter_changed_between_runs_reaches_the_kernel():
    block = Bias(1.0)
    block.bind(Fraction(1, 1000))
    block.set_width(2)
    first = block.kernel()
    assert block.kernel() is first  # kept while the parameters hold
    block.bias = np.array(5.0)
    assert block.kernel() is not first
    np.testing.assert_array_equal(block.output(0.0, None, {"u": np.zeros(2)})["y"], [5.0, 5.0])
