"""The hierhand blocks' compiled kernels (``blocks.kernel.Kernel``): what they share.

The adapters live in C (``hierhand/csrc/python/py_kernels.c``) and call the very functions
the blocks' Python methods call, so either path gives the same bits. ``KERNELS`` holds
their addresses by ``"Block.phase"`` (``"HandPlant.advance"``); a block's ``kernel()``
packs its context (the addresses of its model and parameter arrays) with ``context``
and ``blocks.kernel.address``. The adapters call no Python and write only the state, the
outputs and the plant's ``Scratch`` (one per run, made by its Kernel's ``bind``), so every
Kernel says ``nogil``: the executor runs them with the GIL released.
"""

from __future__ import annotations

import numpy as np

from . import _native

KERNELS: dict[str, int] = _native.kernels()
"""Function addresses by ``"Block.phase"``: the types of ``blocks/csrc/blocks_kernel.h``."""

model_address = _native.model_address
"""``model_address(model)``: the address of a ``hierhand._native.Model`` (keep it alive)."""


def context(*addresses: int) -> np.ndarray:
    """Addresses and counts as a C ``uintptr_t[]``: the kernel's context is
    ``blocks.kernel.address`` of it, and the array goes into the kernel's owners."""
    return np.array(addresses, dtype=np.uintp)
