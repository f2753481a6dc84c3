"""Checks of what Python code passes to the public API, as TypeErrors that say what is wrong.

A diagram's own values are checked by the builder, with the file and line; these are the
arguments a caller gives: a flag that must be a real boolean (``trust="no"`` is a
non-empty string, which Python counts as true, and would let a diagram's Python code
run), overrides that must map text keys to plain values a diagram could hold.
"""

from __future__ import annotations

import numbers
import os
from collections.abc import Mapping
from typing import Any

from blocks.limits import MAX_YAML_DEPTH


def boolean(name: str, value: Any) -> bool:
    """``value`` if it is True or False; TypeError otherwise (not 1, "yes" or "no")."""
    if value is True or value is False:
        return value
    raise TypeError(f"{name} must be True or False, got {value!r} ({type(value).__name__})")


def overrides_mapping(overrides: Any) -> dict[str, Any]:
    """``overrides`` as a dict of ``"block.param"`` keys to plain values (numbers, text,
    booleans, None, and lists and mappings of them, acyclic and at most MAX_YAML_DEPTH deep,
    as a YAML value is); TypeError or ValueError naming the key otherwise."""
    if overrides is None:
        return {}
    if not isinstance(overrides, Mapping):
        raise TypeError(f"overrides must be a mapping of 'block.param' to values, got {type(overrides).__name__}")
    for key, value in overrides.items():
        if not isinstance(key, str):
            raise TypeError(f"overrides: key {key!r} must be text, 'block.param', not {type(key).__name__}")
        _plain(value, f"overrides[{key!r}]", 1, set())
    return dict(overrides)


_SCALARS = (str, numbers.Number, os.PathLike, type(None))


def _plain(value: Any, where: str, depth: int, active: set[int]) -> None:
    if isinstance(value, _SCALARS):
        return
    if hasattr(value, "dtype") and hasattr(value, "tolist"):  # numpy arrays and scalars hold numbers
        if getattr(value.dtype, "hasobject", False):
            raise TypeError(f"{where}: an array of Python objects is not a parameter value")
        return
    if not isinstance(value, (list, tuple, Mapping)):
        raise TypeError(f"{where}: a {type(value).__name__} is not a parameter value (numbers, text, "
                        "booleans, None, lists and mappings of them)")
    if depth > MAX_YAML_DEPTH:
        raise ValueError(f"{where}: nested deeper than {MAX_YAML_DEPTH} levels")
    if id(value) in active:
        raise ValueError(f"{where}: holds itself (a recursive list or mapping)")
    active.add(id(value))
    try:
        items = value.items() if isinstance(value, Mapping) else enumerate(value)
        for key, item in items:
            if isinstance(value, Mapping) and not isinstance(key, (str, int, float, bool)):
                raise TypeError(f"{where}: key {key!r} is not a plain value")
            _plain(item, where, depth + 1, active)
    finally:
        active.discard(id(value))


def diagram_argument(value: Any, name: str = "diagram") -> Any:
    """``value`` if it is a ``Diagram``; TypeError naming the argument otherwise, with how to
    make one of what was given (a path, a builder)."""
    from blocks.builder.diagram import Diagram

    if isinstance(value, Diagram):
        return value
    if isinstance(value, (str, os.PathLike)):
        hint = f"load the file first: load_diagram({str(value)!r})"
    elif hasattr(value, "build") and hasattr(value, "add"):
        hint = "build the builder first: builder.build()"
    else:
        hint = "load one with load_diagram(path) or make one with DiagramBuilder(...).build()"
    raise TypeError(f"{name} must be a Diagram, got {type(value).__name__} ({hint})")
