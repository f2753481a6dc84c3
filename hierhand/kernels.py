"""The hierhand blocks' compiled kernels (``blocks.kernel.Kernel``): what they share.

The adapters live in C (``hierhand/csrc/python/py_kernels.c``) and call the very functions
the blocks' Python methods call, so either path gives the same bits. ``KERNELS`` holds
their addresses by ``"Block.phase"`` (``"HandPlant.advance"``); a block's ``kernel()``
packs its context (the addresses of its model and parameter arrays) with ``context``.
"""

from __future__ import annotations

import numpy as np

from . import _native

KERNELS: dict[str, int] = _native.kernels()
"""Function addresses by ``"Block.phase"``: the types of ``blocks/csrc/blocks_kernel.h``."""

model_address = _native.model_address
"""``model_address(model)``: the address of a ``hierhand._native.Model`` (keep it alive)."""


def data_address(array: np.ndarray) -> int:
    """The address of a C-contiguous float64 array's first value (keep the array alive)."""
    if not (isinstance(array, np.ndarray) and array.dtype == np.float64 and array.flags.c_contiguous):
        raise TypeError("a kernel's context must point at C-contiguous float64 arrays")
    return array.__array_interface__["data"][0]


def context(*addresses: int) -> np.ndarray:
    """Addresses and counts as a C ``uintptr_t[]``: the kernel's context is
    ``address_of`` it, and the array goes into the kernel's owners."""
    return np.array(addresses, dtype=np.uintp)


def address_of(array: np.ndarray) -> int:
    """The address of any C-contiguous array's data (a ``context`` array, say)."""
    if not (isinstance(array, np.ndarray) and array.flags.c_contiguous):
        raise TypeError("a kernel's context must be a C-contiguous array")
    return array.__array_interface__["data"][0]
