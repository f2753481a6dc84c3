"""Which blocks of a run go through their compiled kernels, and what a kernel failure says.

A block whose ``kernel()`` offers every function the run asks of it (an output; an
update if the block is updated, an advance if it is advanced) and whose inputs and state
are what the kernel reads runs every hit through that kernel; any other block runs
through its Python methods, as a callback op of the same table. The choice is made per
run (``blocks.engine.binding``). Without the compiled extension ``blocks._native`` no kernel
can be called, and every block runs in Python.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from blocks.block import BlockError
from blocks.engine.kernel import Kernel


def failure(code: int, which: int, t: float, phase: str) -> BaseException:
    """The exception of a failure code whose block names no ``Kernel.error``."""
    return BlockError(f"compiled {phase} failed at t={t:.10g} s with code {code} (detail {which})")


@functools.cache
def native() -> Any:
    """The extension ``blocks._native`` (the C core's host and single kernel calls); None
    in an uncompiled checkout, where every block runs in Python, in the reference loop."""
    try:
        import blocks._native as extension
    except ImportError:
        return None
    return extension


def flat(state: Any) -> bool:
    """A state a kernel updates in place: a flat, C-contiguous, writable float64 array."""
    return (isinstance(state, np.ndarray) and state.dtype == np.float64 and state.ndim == 1
            and state.flags.c_contiguous and state.flags.writeable)


def usable_kernel(block: Any, inputs: dict, state: Any, updated: bool, advanced: bool) -> Kernel | None:
    """The block's kernel if it offers every function the table needs of it and its inputs
    and state are what the kernel reads; else None (the block runs in Python)."""
    kernel = block.kernel()
    if not isinstance(kernel, Kernel) or not kernel.output:
        return None
    if any(not (isinstance(v := inputs[p], np.ndarray) and v.shape == (w,) and v.dtype == np.float64)
           for p, w in block.inputs.items()):
        return None  # an input default of another width: the Python methods meet it as they would
    if state is not None and ((kernel.bind is None and not flat(state)) or (updated and not kernel.update)):
        return None
    if advanced and not kernel.advance:
        return None
    return kernel
