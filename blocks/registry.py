"""Block types by name: the framework's library plus every ``blocks.types`` entry point.

An entry point names one Block subclass, registered under the entry point's name, or a
collection: a list or tuple of Block subclasses or their ``"module:Class"`` references, each
registered under its ``registered_name()``, so a package with many types needs one entry
point and keeps their list where it likes. A type that fails to load is left out with its
reason. A name that two plug-ins give to different classes is left out too, with both
named, whatever the install order; a plug-in cannot replace a library type.

A diagram can only name registered types. ``python:module:Class`` names arbitrary
code and is refused unless the caller passes ``trust=True`` (``--trust`` on the CLI),
because loading a diagram must never run code the user did not choose to run. Its module
is looked up in the diagram's folder first (``module.py`` or a package ``module/``), then
on the Python path.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path

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
_library: dict[str, type[Block]] | None = None
_load_errors: dict[str, str] = {}


def library_types() -> dict[str, type[Block]]:
    """The library's types by name, which no plug-in can replace: a diagram of them alone
    resolves its types without loading every installed plug-in (and their imports)."""
    global _library
    if _library is None:
        from .library import LIBRARY

        _library = {cls.registered_name(): cls for cls in LIBRARY}
    return _library


def block_types() -> dict[str, type[Block]]:
    """All registered block types by name (library first, then installed entry points)."""
    global _cache
    if _cache is None:
        library = library_types()
        loaded, errors = load_group(ENTRY_POINT_GROUP, _not_a_block_or_collection)
        claims: dict[str, set[type[Block]]] = {}
        for entry, obj in loaded.items():
            for name, cls in _registrations(entry, obj, errors):
                claims.setdefault(name, set()).add(cls)
        types = dict(library)
        for name in sorted(claims):
            classes = claims[name] - {library.get(name)}
            if name in library and classes:
                errors[name] = f"{_names(classes)} cannot replace the library's type"
            elif len(classes) == 1:
                types[name] = classes.pop()
            elif classes:
                errors[name] = f"{_names(classes)} all register it; uninstall all but one"
        _load_errors.update(errors)
        _cache = types
    return _cache


def _is_block(obj) -> bool:
    return isinstance(obj, type) and issubclass(obj, Block)


def _not_a_block_or_collection(obj) -> str | None:
    return None if _is_block(obj) or isinstance(obj, (list, tuple)) else \
        "is neither a Block subclass nor a list or tuple of them"


def _registrations(entry: str, obj, errors: dict[str, str]) -> list[tuple[str, type[Block]]]:
    """(name, class) of what the entry point ``entry`` loaded: a Block subclass under the
    entry point's name, or each type of a collection under its own; what fails goes to
    ``errors`` (a reference that does not load under its class's name, anything else that
    is not a Block under the entry point's)."""
    if _is_block(obj):
        return [(entry, obj)]
    found = []
    for item in obj:
        if isinstance(item, str):
            name = item.rpartition(":")[2]
            try:
                from importlib.metadata import EntryPoint

                cls = EntryPoint(name, item, ENTRY_POINT_GROUP).load()
            except Exception as exc:  # a broken type must not break the collection's others
                errors[name] = f"{item}: {exc}"
                continue
            if not _is_block(cls):
                errors[name] = f"{item} is not a Block subclass"
                continue
        elif _is_block(item):
            cls = item
        else:
            errors[entry] = f"{errors[entry]}; " if entry in errors else ""
            errors[entry] += f"holds {item!r}, which is neither a Block subclass nor a 'module:Class' reference"
            continue
        found.append((cls.registered_name(), cls))
    return found


def _names(classes) -> str:
    return " and ".join(sorted(f"{cls.__module__}:{cls.__qualname__}" for cls in classes))


def resolve_type(name: str, trust: bool = False, base_dir: str | Path | None = None) -> type[Block]:
    """The Block class for a diagram's ``type:`` text; ``base_dir``, the diagram's folder,
    is where a ``python:`` type's module is looked for first."""
    if name.startswith(PYTHON_PREFIX):
        if not trust:
            raise RegistryError(
                f"type '{name}' imports Python code from the diagram",
                "pass --trust (Python: trust=True) if you trust this file, or register the "
                f"block through the '{ENTRY_POINT_GROUP}' entry point")
        return _import_class(name[len(PYTHON_PREFIX):], base_dir)
    library = library_types()
    if name in library:
        return library[name]
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
    if _load_errors:  # a collection that failed to load leaves its types unknown: say so
        hint += "; left out because they failed to load: " + \
            "; ".join(f"'{entry}' ({why})" for entry, why in sorted(_load_errors.items()))
    raise RegistryError(f"unknown block type '{name}'", hint)


def _import_class(target: str, base_dir: str | Path | None = None) -> type[Block]:
    module_name, _, attr = target.partition(":")
    if not module_name or not attr:
        raise RegistryError(f"'{PYTHON_PREFIX}{target}' is not of the form python:module:Class")
    try:
        module = _local_module(module_name, Path(base_dir)) if base_dir is not None else None
        if module is None:
            module = _path_module(module_name, base_dir)
        obj = getattr(module, attr)
    except RegistryError:
        raise
    except Exception as exc:
        raise RegistryError(f"cannot import '{target}': {type(exc).__name__}: {exc}") from None
    if not (isinstance(obj, type) and issubclass(obj, Block)):
        raise RegistryError(f"'{target}' is not a Block subclass")
    return obj


def _local_module(module_name: str, base_dir: Path):
    """The module ``module_name`` from the diagram's folder, or None if it has no such file.

    The file is imported from its path under a name of its own (made from the file's path,
    size and modification time), never by putting the folder on ``sys.path``: two
    diagrams in different folders may each have a ``blocks_mine.py``, and neither may
    shadow the other or an installed module. A package folder imports its submodules
    relatively (``from . import helpers``).
    """
    top, _, rest = module_name.partition(".")
    folder = base_dir.resolve()
    package = folder / top / "__init__.py"
    single = folder / f"{top}.py"
    if package.is_file():
        origin, search = package, [str(package.parent)]
    elif single.is_file() and not rest:
        origin, search = single, None
    else:
        return None
    stat = origin.stat()
    import hashlib

    key = hashlib.sha256(f"{origin}\0{stat.st_size}\0{stat.st_mtime_ns}".encode()).hexdigest()[:16]
    alias = f"_blocks_diagram_{key}_{top}"
    module = sys.modules.get(alias)
    if module is None:
        spec = importlib.util.spec_from_file_location(alias, origin, submodule_search_locations=search)
        module = importlib.util.module_from_spec(spec)
        sys.modules[alias] = module  # as a normal import does: dataclasses, pickle look it up
        try:
            spec.loader.exec_module(module)
        except BaseException:
            del sys.modules[alias]
            raise
    return importlib.import_module(f"{alias}.{rest}") if rest else module


def _path_module(module_name: str, base_dir: str | Path | None):
    """The module ``module_name`` from ``sys.path``; not found there: a RegistryError
    naming the places searched."""
    try:
        return importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        top = module_name.partition(".")[0]
        if exc.name not in (module_name, top):
            raise  # the module exists but imports something missing: that is the message
    where = ""
    if base_dir is not None:
        where = (f"no {top}.py or {top}/__init__.py in the diagram's folder "
                 f"{Path(base_dir).resolve()}, and ")
    raise RegistryError(
        f"cannot import 'python:{module_name}': {where}no module '{module_name}' on the Python "
        f"path (sys.path: {', '.join(p or '.' for p in sys.path)})",
        f"put {top}.py beside the diagram, or install the package that provides it")
