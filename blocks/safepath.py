"""Paths that come from a diagram, which may be someone else's: keep them where they belong.

A diagram names files to read (``params_file``); unless the user trusts it (``--trust``),
those must lie in the diagram's own folder or below, so that a diagram from elsewhere
cannot read, and copy into its results, a file of the user's that it has no business
with (``~/.ssh/...``, ``/etc/...``).
"""

from __future__ import annotations

from pathlib import Path


def inside(path: str | Path, folder: str | Path) -> bool:
    """Whether ``path`` is ``folder`` or below it once links and '..' are resolved (so a
    link inside the folder that points out of it is outside)."""
    try:
        return Path(path).resolve().is_relative_to(Path(folder).resolve())
    except (OSError, RuntimeError, ValueError):  # a loop of links, a NUL in the name
        return False
