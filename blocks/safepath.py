"""Paths that come from a diagram, which may be someone else's: keep them where they belong.

A diagram names files to read (``params_file``); unless the user trusts it (``--trust``),
those must lie in the diagram's own folder or below, so that a diagram from elsewhere
cannot read, and copy into its results, a file of the user's that it has no business
with (``~/.ssh/...``, ``/etc/...``). And a diagram's ``name:`` names its results folder
(``runs/<name>``), so it is made one safe folder name, never a path.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

from .limits import MAX_FOLDER_NAME

_UNSAFE = re.compile(r"(?:[^\w.-]|\.{2,})+")
"""Runs of anything but letters, digits (of any script), '_', '-' and single dots: path
separators, NUL and other control characters, spaces, and '..'."""


OUTSIDE_HINT = ("a diagram reads files only from its own folder and below; pass --trust (Python: trust=True) "
                "if you trust this diagram")
"""The hint of every refusal of a file outside a diagram's folder."""


def unusable_path(exc: ValueError) -> str:
    """Why a path that the system refused with ``exc`` cannot be opened (``os.open`` raises
    ValueError for a NUL character, UnicodeEncodeError for a character that the system's
    file-name encoding cannot write, as ASCII cannot 'ü' in a C locale without UTF-8 mode)."""
    if isinstance(exc, UnicodeEncodeError):
        return (f"the path has a character ({exc.object[exc.start:exc.end]!r}) that this system's file names "
                f"({sys.getfilesystemencoding()}) cannot hold; run in a UTF-8 locale (LC_ALL=C.UTF-8) or with "
                "PYTHONUTF8=1")
    return "the path contains a NUL character"


def inside(path: str | Path, folder: str | Path) -> bool:
    """Whether ``path`` is ``folder`` or below it once links and '..' are resolved (so a
    link inside the folder that points out of it is outside)."""
    try:
        return Path(path).resolve().is_relative_to(Path(folder).resolve())
    except (OSError, RuntimeError, ValueError):  # a loop of links, a NUL in the name
        return False


def link_out_of(folder: str | Path, *names: str) -> Path | None:
    """The first of ``folder/name`` that is a symbolic link leading out of ``folder`` (or
    nowhere), or None: a results folder writes into its own entries (``plots/``,
    ``sweep.csv``, ``runs/``), and a link there must not carry its files elsewhere."""
    for name in names:
        entry = Path(folder) / name
        if entry.is_symlink() and not inside(entry, folder):
            return entry
    return None


def folder_name(name: str, default: str = "diagram") -> str:
    """``name`` as one folder name that stays where it is put: each run of unsafe characters
    (``_UNSAFE``) becomes '_', leading dots and dashes go (no hidden folder, nothing that
    reads as an option), and the rest is cut to MAX_FOLDER_NAME bytes of UTF-8;
    ``default`` when nothing is left. ``../../x`` -> ``_x``, ``/tmp/x`` -> ``_tmp_x``."""
    safe = _UNSAFE.sub("_", name).lstrip(".-")
    return safe.encode("utf-8")[:MAX_FOLDER_NAME].decode("utf-8", "ignore") or default
