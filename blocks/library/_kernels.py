"""The library blocks' compiled kernels (blocks/csrc/library.c, lib_*.c): addresses and contexts.

Each library block (a ``KernelBlock``) packs its parameters into one flat float64 array,
the context its C functions read (lib_common.h's header [W, T], then its numbers, sizes
as doubles), and gets a ``Kernel`` with the addresses from ``blocks._native.library()``.
Matrix-vector products are library.c's own (each row summed in column order from its
first product, no fused multiply-add), so they equal numpy's ``ndarray.dot`` for
single-term rows and to round-off otherwise. Kernels exist for any size: the context
holds the matrices. The kernels only read their context and keep their scratch on the
stack (or in memory of their own call), so they say ``nogil``.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from blocks.engine.compiled import failure
from blocks.engine.kernel import Kernel, KernelRecord, Tunable, address

NOMEM = 1
"""library.c's failure code when a kernel gets no memory for its scratch vectors."""


@functools.cache
def functions() -> dict[str, int]:
    """{name: address} of the library kernels; empty when blocks._native is missing."""
    try:
        import blocks._native as _native
    except ImportError:
        return {}
    return dict(_native.library())


def make_kernel(context: np.ndarray, output: str | None = None, update: str | None = None,
                advance: str | None = None, *owners: Any, failures=None,
                tunables: tuple[Tunable, ...] = ()) -> Kernel | None:
    """A Kernel of the named library functions reading ``context``; None without them.
    ``failures``: the block's ``Kernel.error`` (default: this module's ``error``). Its
    record is the context itself, of the kernel type the functions are named after
    (``gain_output``: ``gain``), with the block's ``tunables`` (slots of the context)."""
    table = functions()
    names = [name for name in (output, update, advance) if name is not None]
    if not names or any(name not in table for name in names):
        return None
    context = np.ascontiguousarray(context, dtype=np.float64)
    kind = names[0].rsplit("_", 1)[0]
    return Kernel(
        context=address(context),
        output=table[output] if output else 0,
        update=table[update] if update else 0,
        advance=table[advance] if advance else 0,
        owners=(context, *owners),
        error=failures or error,
        nogil=True,
        record=KernelRecord(kind, context, tunables),
    )


def tunables(name: str, first: int, shape: tuple[int, ...], description: str) -> tuple[Tunable, ...]:
    """The elements of a parameter ``name`` (a scalar: ``shape`` (), a vector, a matrix,
    row-major) at record slots from ``first`` as finite tunables: ``k``, ``k[2]``, ``k[1,2]``."""
    if not shape:
        return (Tunable(name, first, description, finite=True),)
    out = []
    for i, index in enumerate(np.ndindex(*shape)):
        label = ",".join(str(j + 1) for j in index)
        out.append(Tunable(f"{name}[{label}]", first + i, description, finite=True))
    return tuple(out)


def error(code: int, which: int, t: float, phase: str) -> BaseException:
    """The exception of a library kernel's failure code (``Kernel.error``)."""
    if code == NOMEM:
        return MemoryError(f"compiled {phase} at t={t:.10g} s: no memory for its scratch vectors")
    return failure(code, which, t, phase)


def cached(block: Any, key: tuple, build) -> Kernel | None:
    """``build()``'s Kernel, kept on the block while ``key`` holds: the period, the widths
    and the parameters' values the context copies, so a parameter changed on the block
    between runs reaches its kernel as it reaches its Python methods."""
    held = getattr(block, "_kernel_cache", None)
    if held is not None and held[0] == key:
        return held[1]
    kernel = build()
    block._kernel_cache = (key, kernel)
    return kernel
