"""Loading the objects that installed packages register under an entry-point group.

Block types (``blocks.types``) and sweep measures (``blocks.measures``) come from plug-ins
this way. A plug-in that fails to import, or registers something of the wrong kind, is
left out with its reason kept, so one broken package does not break every diagram or
sweep; the reason is told when its name is asked for.
"""

from __future__ import annotations

from typing import Any, Callable


def entry_points(group: str):
    """The installed entry points of ``group`` (``importlib.metadata``, imported only
    when a plug-in is looked for: it costs a command's start more than the rest)."""
    from importlib import metadata

    return metadata.entry_points(group=group)


def load_group(group: str, refuse: Callable[[Any], str | None]) -> tuple[dict[str, Any], dict[str, str]]:
    """Every entry point of ``group`` loaded: (name -> object, name -> why it is left out).

    ``refuse(obj)`` returns why a loaded object is not of the right kind ('is not callable'),
    or None to take it.
    """
    found: dict[str, Any] = {}
    errors: dict[str, str] = {}
    for ep in entry_points(group=group):
        try:
            obj = ep.load()
        except Exception as exc:  # a broken plug-in must not break the others
            errors[ep.name] = f"{ep.value}: {exc}"
            continue
        reason = refuse(obj)
        if reason is None:
            found[ep.name] = obj
        else:
            errors[ep.name] = f"{ep.value} {reason}"
    return found, errors
