"""Keep numba's on-disk cache of the model's kernels consistent with their sources.

Numba keys a cached function on its own source file only, yet a compiled kernel also
contains the functions it calls from other modules (and the layout constants). After an
edit to, say, ``contact.py`` the cached ``advance_kernel`` would silently keep the old
contact law. ``invalidate_if_stale`` hashes all kernel sources and, when the hash differs
from the one recorded beside the cache, empties the cache index of every given function.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Iterable

KERNEL_SOURCES = ("layout.py", "kinematics.py", "dynamics.py", "contact.py", "kernel.py")
STAMP_NAME = "hierhand_model_kernels.sha256"


def sources_digest(directory: Path = Path(__file__).parent) -> str:
    h = hashlib.sha256()
    for name in KERNEL_SOURCES:
        h.update(name.encode())
        h.update((directory / name).read_bytes())
    return h.hexdigest()


def invalidate_if_stale(dispatchers: Iterable, stamp_name: str = STAMP_NAME) -> bool:
    """Flush the cache indexes of ``dispatchers`` if the kernel sources changed.

    Returns whether it flushed. Does nothing where caching is unavailable (no ``_cache``
    on the dispatcher, or a read-only cache directory). Modules that share a cache folder
    pass a ``stamp_name`` of their own, so that one module's refreshed stamp cannot hide
    another's stale cache.
    """
    dispatchers = [d for d in dispatchers if getattr(d, "_cache", None) is not None]
    paths = {getattr(d._cache, "cache_path", None) for d in dispatchers}
    paths.discard(None)
    if not paths:
        return False
    digest = sources_digest()
    stale = False
    for path in paths:
        stamp = Path(path) / stamp_name
        try:
            if not stamp.is_file() or stamp.read_text().strip() != digest:
                stale = True
        except OSError:
            return False
    if not stale:
        return False
    try:
        for d in dispatchers:
            d._cache.flush()
        for path in paths:
            Path(path).mkdir(parents=True, exist_ok=True)
            (Path(path) / stamp_name).write_text(digest + "\n")
    except OSError:
        return False
    return True


def model_dispatchers() -> list:
    """Every compiled function defined in the kernel source modules."""
    from numba.core.registry import CPUDispatcher

    from . import contact, dynamics, kernel, kinematics

    found = []
    for module in (kinematics, dynamics, contact, kernel):
        for obj in vars(module).values():
            if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == module.__name__:
                found.append(obj)
    return found
