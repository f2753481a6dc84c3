"""The library blocks' compiled kernels (blocks/csrc/library.c): addresses and contexts.

Each library block's ``kernel()`` packs its parameters into one flat float64 array, the
context its C functions read (sizes first, as doubles), and returns a ``Kernel`` with
the addresses from ``blocks._native.library()``. The kernels compute exactly what the
Python methods compute; where that rests on reproducing numpy's BLAS (matrix-vector
products), ``matvec_exact`` first checks the C product against ``ndarray.dot`` on random
matrices of the sizes a block uses, and the block runs in Python when they differ.
"""

from __future__ import annotations

import functools
import random
from typing import Any

import numpy as np

from blocks.kernel import Kernel

MATVEC_MAX_L = 7
"""Longest dot (matrix columns) a kernel's matrix-vector product reproduces for several rows."""

DDOT_MAX_L = 15
"""Longest dot a single-row product reproduces (BLAS ddot's sequential tail)."""


@functools.cache
def functions() -> dict[str, int]:
    """{name: address} of the library kernels; empty when blocks._native is missing."""
    try:
        import blocks._native as _native
    except ImportError:
        return {}
    return dict(_native.library())


def make_kernel(context: np.ndarray, output: str | None = None, update: str | None = None,
                advance: str | None = None, *owners: Any) -> Kernel | None:
    """A Kernel of the named library functions reading ``context``; None without them."""
    table = functions()
    names = [name for name in (output, update, advance) if name is not None]
    if not names or any(name not in table for name in names):
        return None
    context = np.ascontiguousarray(context, dtype=np.float64)
    return Kernel(
        context=context.__array_interface__["data"][0],
        output=table[output] if output else 0,
        update=table[update] if update else 0,
        advance=table[advance] if advance else 0,
        owners=(context, *owners),
    )


def matvec_supported(rows: int, cols: int) -> bool:
    """Whether library.c's matvec covers a (rows x cols) matrix at all."""
    if rows < 1 or cols < 1:
        return False
    return cols == 1 or (rows == 1 and cols <= DDOT_MAX_L) or cols <= MATVEC_MAX_L


def matvec_exact(rows: int, cols: int) -> bool:
    """Whether library.c's matvec equals ``ndarray.dot`` bit for bit for (rows x cols)
    matrices here (checked once per kind of shape, see ``_checked``)."""
    return matvec_supported(rows, cols) and _checked(rows == 1, cols)


@functools.cache
def _checked(single: bool, cols: int) -> bool:
    """The C product against ``ndarray.dot`` on random matrices of ``cols`` columns and
    one row (``single``) or several row counts, through the gain kernel, whose matrix
    mode is that product."""
    table = functions()
    if "gain_output" not in table:
        return False
    import blocks._native as _native  # not "from blocks import": no cycle

    rng = random.Random(20240601 + cols)  # not numpy.random: importing it costs 10 ms

    def normal(count: int) -> np.ndarray:
        return np.array([rng.gauss(0.0, 1.0) * rng.choice((1e-3, 1.0, 1e3)) for _ in range(count)])

    # 67 rows take every path of BLAS's gemv: groups of four rows, a pair, a single one
    for r in (1,) * 16 if single else (67, 67, 67, 2, 3, 5):
        k = normal(r * cols).reshape(r, cols)
        u = normal(cols)
        context = np.concatenate(((1.0, r, cols), k.ravel()))
        out = np.empty(r)
        _native.call("output", table["gain_output"], context.__array_interface__["data"][0], 0.0,
                     None, [u], out)
        if not np.array_equal(out, k.dot(u)):
            return False  # another BLAS kernel: the blocks that need this product run in Python
    return True


def cached(block: Any, key: tuple, build) -> Kernel | None:
    """``build()``'s Kernel, kept on the block while ``key`` (period, widths, model) holds."""
    held = getattr(block, "_kernel_cache", None)
    if held is not None and held[0] == key:
        return held[1]
    kernel = build()
    block._kernel_cache = (key, kernel)
    return kernel
