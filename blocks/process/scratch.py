"""The program's temporary files: one private folder for a process and all it starts, removed at its exit.

What the program writes for a while (an FMU's or an SSP's unpacked archive, a sweep's
diagram bundle in each process that runs points, Dask's worker folders) goes into
``folder(prefix)``: a new folder inside ``root()``. The root is made on first use
(``tempfile.mkdtemp`` in TMPDIR, mode 700) by the first process that needs one, which
names it in the environment (``ENV``) and removes it, everything in it, at its exit.
Processes it starts take their folders inside it: forked ones (a sweep's local runner,
forked Dask workers) and spawned ones (which read ``ENV``). So a child killed by a signal,
which cannot clean up after itself, leaves nothing behind once the process that made the
root exits: normally, or on Ctrl-C or SIGTERM (which the command line turns into a
normal exit). Only a SIGKILL of that process leaves its root in TMPDIR.
"""

from __future__ import annotations

import atexit
import os
import shutil
import stat
import tempfile
import threading
from pathlib import Path

ENV = "BLOCKS_SCRATCH"
"""The environment variable naming the root for the processes this one starts."""

PREFIX = "blocks-"
"""How the root's name begins in TMPDIR."""

_lock = threading.Lock()
_root: tuple[int, Path, bool] | None = None
"""(the process that found or made it, the root, whether that process made it)."""


def root() -> Path:
    """This process's scratch root: the one it inherited (made by the process that started
    it, still there and private to this user), else a new one that it removes at exit."""
    global _root
    with _lock:
        if _root is not None and _root[0] == os.getpid() and _usable(_root[1]):
            return _root[1]
        inherited = _root[1] if _root is not None else Path(os.environ.get(ENV, "") or ".")
        if os.environ.get(ENV) and _usable(inherited):
            _root = (os.getpid(), inherited, False)
        else:
            made = Path(tempfile.mkdtemp(prefix=PREFIX))
            _root = (os.getpid(), made, True)
            os.environ[ENV] = str(made)
        return _root[1]


def folder(prefix: str) -> Path:
    """A new private folder in the scratch root, its name beginning with ``prefix``."""
    return Path(tempfile.mkdtemp(prefix=prefix, dir=root()))


def _usable(path: Path) -> bool:
    """Whether ``path`` is a real folder (not a link) of this user that only this user may use."""
    try:
        info = os.lstat(path)
    except OSError:
        return False
    owner = os.getuid() if hasattr(os, "getuid") else info.st_uid
    return stat.S_ISDIR(info.st_mode) and info.st_uid == owner and not info.st_mode & (stat.S_IRWXG | stat.S_IRWXO)


@atexit.register
def _remove() -> None:
    """At exit, the process that made the root removes it (a child leaves it to that one)."""
    if _root is not None and _root[0] == os.getpid() and _root[2]:
        shutil.rmtree(_root[1], ignore_errors=True)
        if os.environ.get(ENV) == str(_root[1]):
            del os.environ[ENV]
