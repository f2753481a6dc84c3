"""One file written atomically: a reader sees the old file or the whole new one, never a part.

The content goes to a temporary file beside the target (same folder, so the same file
system), is flushed to disk, and then renamed over the target with ``os.replace``, which
is atomic on POSIX and Windows. Should anything fail on the way, the temporary file goes
and the target is left as it was. The temporary file is created with the usual
permissions (0666 less the umask), so the result is readable as a plainly written file is.

A *set* of files that must belong together (a run's results) is a different matter:
``results_folder`` stages the set and swaps it in under a lock.
"""

from __future__ import annotations

import contextlib
import os
import secrets
from pathlib import Path
from typing import BinaryIO, Iterator

TEMP_SUFFIX = ".tmp"
"""Temporary files are ``.NAME.RANDOM.tmp`` beside the target: hidden, and plainly not the result."""


@contextlib.contextmanager
def atomic_writer(path: str | Path) -> Iterator[BinaryIO]:
    """A binary file object whose content replaces ``path`` when the block ends without an error."""
    path = Path(path)
    temp = path.with_name(f".{path.name}.{secrets.token_hex(4)}{TEMP_SUFFIX}")
    fd = os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
    try:
        with os.fdopen(fd, "wb") as f:
            yield f
            f.flush()
            os.fsync(f.fileno())
        os.replace(temp, path)
    except BaseException:
        temp.unlink(missing_ok=True)
        raise


def write_atomically(path: str | Path, data: bytes | str, encoding: str = "utf-8") -> Path:
    """Write ``data`` (text is encoded with ``encoding``) to ``path`` atomically; returns ``path``."""
    with atomic_writer(path) as f:
        f.write(data.encode(encoding) if isinstance(data, str) else data)
    return Path(path)
