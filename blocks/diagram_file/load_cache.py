"""Diagrams loaded before, given again while every file they read is unchanged.

Loading a diagram file reads and checks it, makes its blocks and plans it: milliseconds
for a small diagram. A command, a sweep point or a test that loads the same file again
with the same arguments gets the Diagram made before, when every file that diagram read
(its file, its params files, its subsystems' files, the files its blocks' path parameters
name: ``Diagram.files``) still holds the same bytes, compared by a digest of their
contents, so an edit is always seen, whatever the files' times say. A Diagram is not
changed after loading (its plans are kept on it too), so one object serves every load.

A diagram is kept only when none of its files was modified shortly before or after its
loading began (``SETTLED_NS``: a file written while it was read could otherwise be kept
with the digest of its new bytes beside the diagram of the old). The last ``KEEP`` loads
are kept.
"""

from __future__ import annotations

import hashlib
import os
import threading
import time
from collections import OrderedDict
from pathlib import Path
from typing import Any, Callable

KEEP = 32
"""How many loads (a file with one set of arguments each) are kept."""

SETTLED_NS = 2 * 10**9
"""A file modified less than this long before a load began is not trusted to have been
read whole (file times lag the clock by up to a timer tick, and an editor may still be
writing): its diagram is not kept, and the next load reads it again."""

_kept: OrderedDict[tuple, tuple[tuple[tuple[str, str | None], ...], Any]] = OrderedDict()
_lock = threading.Lock()


def digest(path: str | Path) -> str | None:
    """A digest of the file's bytes (None: it cannot be read)."""
    try:
        with open(path, "rb") as file:
            return hashlib.blake2b(file.read(), digest_size=16).hexdigest()
    except OSError:
        return None


def cached(key: tuple, load: Callable[[], Any]) -> Any:
    """The Diagram that ``load()`` made for ``key`` before, if the files it read are
    unchanged; else ``load()``'s, kept for the next time when its files allow it."""
    with _lock:
        held = _kept.get(key)
    if held is not None:
        files, diagram = held
        if all(digest(path) == known for path, known in files):
            with _lock:
                if key in _kept:
                    _kept.move_to_end(key)
            return diagram
    began = time.time_ns()
    diagram = load()
    paths = [str(diagram.file), *(str(p) for p in diagram.files.values())]
    try:
        settled = all(os.stat(p).st_mtime_ns < began - SETTLED_NS for p in paths)
    except OSError:
        settled = False
    if settled:
        files = tuple((p, digest(p)) for p in paths)
        with _lock:
            _kept[key] = (files, diagram)
            _kept.move_to_end(key)
            while len(_kept) > KEEP:
                _kept.popitem(last=False)
    return diagram


def forget() -> None:
    """Keep nothing loaded before (the next load of every file reads it again)."""
    with _lock:
        _kept.clear()
