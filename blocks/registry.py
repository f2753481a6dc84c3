"""Block types by name: the framework's library plus every ``blocks.types`` entry point.

A diagram can only name registered types. ``python:module:Class`` names arbitrary
code and is refused unless the caller passes ``trust=True`` (``--trust`` on the CLI),
because loading a diagram must never run code the user did not choose to run.
"""

from __future__ import annotations

import importlib

from .block import Block
from .plugins import load_group

ENTRY_POINT_GROUP = "blocks.types"
PYTHON_PREFIX = "python:"


class RegistryError(Exception):
    """A type name that does not resolve to a Block subclass."""

    def __init__(self, message: str, hint: str = ""):
        super().__init__(message)
        self.hint = hint


_cache: dict[str, type[Block]] | None = None
_load_errors: dict[str, str] = {}


def block_types() -> dict[str, type[Block]]:
    """All registered block types by name (library first, then installed entry points)."""
    global _cache
    if _cache is None:
        from .library import LIBRARY

        types: dict[str, type[Block]] = {cls.registered_name(): cls for cls in LIBRARY}
        installed, errors = load_group(ENTRY_POINT_GROUP, _not_a_block)
        types.update(installed)
        _load_errors.update(errors)
        _cache = types
    return _cache


def _not_a_block(obj) -> str | None:
    return None if isinstance(obj, type) and issubclass(obj, Block) else "is not a Block subclass"


def resolve_type(name: str, trust: bool = False) -> type[Block]:
    """The Block class for a diagram's ``type:`` text."""
    if name.startswith(PYTHON_PREFIX):
        if not trust:
            raise RegistryError(
                f"type '{name}' imports Python code from the diagram",
                "pass --trust (Python: trust=True) if you trust this file, or register the "
                f"block through the '{ENTRY_POINT_GROUP}' entry point")
        return _import_class(name[len(PYTHON_PREFIX):])
    types = block_types()
    if name in types:
        return types[name]
    if name in _load_errors:
        raise RegistryError(f"block type '{name}' is registered but failed to load: {_load_errors[name]}",
                            "reinstall the package that provides it")
    import difflib

    close = difflib.get_close_matches(name, types, n=3)
    hint = f"did you mean {', '.join(repr(c) for c in close)}?" if close else \
        "run 'hierhand blocks' to list the registered types"
    raise RegistryError(f"unknown block type '{name}'", hint)


def _import_class(target: str) -> type[Block]:
    module_name, _, attr = target.partition(":")
    if not module_name or not attr:
        raise RegistryError(f"'{PYTHON_PREFIX}{target}' is not of the form python:module:Class")
    try:
        obj = getattr(importlib.import_module(module_name), attr)
    except Exception as exc:
        raise RegistryError(f"cannot import '{target}': {exc}") from None
    if not (isinstance(obj, type) and issubclass(obj, Block)):
        raise RegistryError(f"'{target}' is not a Block subclass")
    return obj
