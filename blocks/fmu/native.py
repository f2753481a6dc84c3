"""The FMU block's compiled functions, from ``blocks._native.fmu_kernel()``: the kernel's
(blocks/csrc/fmu_block_step.c), the model-exchange loops' (fmu_me_integration.c) and the
channel's to an FMU in a process of its own (fmu_channel.c), with the layouts of their tables. One place, imported
by the modules that use them (``kernel``, ``solvers``, ``channel``, ``host``)."""

from __future__ import annotations

import functools
from typing import Any


@functools.cache
def native() -> dict[str, Any] | None:
    """The C functions and context layouts (``fmu_kernel()`` of blocks._native); None
    when the extension is not built."""
    try:
        from .. import _native
    except ImportError:
        return None
    return _native.fmu_kernel()
