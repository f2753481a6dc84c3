"""A diagram's blocks checked and constructed: type, timing, parameters, references.

Each block entry of every level (``blocks.builder.scopes``) is checked up to its constructor
call: its type resolves, its period and offset are durations that fit, its parameters
(its params file, then ``params``, then the overrides that reach it) are the type's, its
path parameters lead to files and its block references to blocks. The blocks are then
made in an order where every referenced block comes first (``blocks.builder.references``), and
bound to their period. A problem with a parameter value is reported where that value
was written: the ``--set`` that gave it, else the deepest part of the path written in
the block's ``params:``, its params file or a subsystem entry's ``params``.
"""

from __future__ import annotations

import copy
import re
import sys
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any, Mapping, NamedTuple

from blocks.block import Block, ParameterError
from blocks.builder.context import BuildContext, known, suggest
from blocks.builder.params_reader import default_params_reader
from blocks.builder.records import BlockEntry, Site, SourceError
from blocks.builder.diagram import BlockSpec
from blocks.limits import MAX_PORT_WIDTH
from blocks.builder.param_paths import PathError, set_path
from blocks.builder.references import build_order, chain_text
from blocks.registry import PYTHON_PREFIX, RegistryError, block_types, library_types, resolve_type
from blocks.safepath import OUTSIDE_HINT, inside
from blocks.builder.scopes import NOT_A_NAME, SUBSYSTEM, UNKNOWN, Bound, Level, Override, resolve_reference
from blocks.timebase import DurationError, parse_duration, positive_duration



_PARAMETER = re.compile(r"parameter '([^'.\[]+)'")
"""How a block's ValueError names the parameter it is about (``blocks.library._params``)."""


def _named(exc: Exception) -> tuple[str, ...]:
    """The parameter a constructor's exception names (``("k",)``), or ``()``: so that it is
    reported where that parameter was given (the diagram's line, or ``--set``)."""
    found = _PARAMETER.match(str(exc))
    return (found[1],) if found else ()

class ParamsFile(NamedTuple):
    """A block's params file: its content and where it is (its path, and the lines of its
    parameters when its front end knows them)."""

    data: Mapping
    site: Site


@dataclass
class Placed:
    """A block entry of a level, checked up to its constructor call."""

    name: str
    """Its path name in the flat diagram (``ctrl.integ``)."""
    level: Level
    entry: BlockEntry
    cls: type[Block]
    period: Fraction | None
    offset: Fraction | None
    params: dict
    instance: Block | None = None
    source: ParamsFile | None = None
    references: dict[str, Bound] = field(default_factory=dict)
    arguments: dict[str, str] = field(default_factory=dict)
    """Constructor arguments that differ from ``params``: path parameters read from the
    files map (``params`` keeps the path the diagram names)."""

    @property
    def site(self) -> Site:
        return self.entry.site

    @property
    def overrides(self) -> list[Override]:
        """The overrides that reach this block, lowest rank first."""
        return self.level.overrides.get(self.level.name_of(self.name), [])


def deep_merge(base: Mapping, top: Mapping) -> dict:
    """``top`` over ``base``: nested mappings merge key by key, anything else replaces.
    Values are copied, except blocks (a block reference given as the block itself)."""
    out = {k: _copied(v) for k, v in base.items()}
    for key, value in top.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = deep_merge(out[key], value)
        else:
            out[key] = _copied(value)
    return out


def _copied(value: Any) -> Any:
    return value if isinstance(value, Block) else copy.deepcopy(value)


def type_ref(cls: type[Block]) -> str:
    """How a diagram names ``cls``: its registered name, else ``python:module:Class``."""
    name = cls.registered_name()
    if library_types().get(name) is cls or block_types().get(name) is cls:
        return name
    return f"{PYTHON_PREFIX}{cls.__module__}:{cls.__qualname__}"


class Constructor:
    """Checks and makes the blocks of every level; ``specs`` are those that were made."""

    def __init__(self, ctx: BuildContext, top: Level):
        self.ctx = ctx
        self.top = top
        self.specs: dict[str, BlockSpec] = {}
        self.failed: set[str] = set()
        """Path names of blocks that were not made (reported): not reported again where used."""
        self.stand_ins: dict[str, Block] = {}

    def error(self, site: Site, key: Any, message: str, hint: str = "") -> None:
        self.ctx.add(site.issue(message, hint, key=key))

    def make_all(self) -> dict[str, BlockSpec]:
        """Every level's blocks, in the flat diagram's order (a subsystem's where its entry is)."""
        order_of: list[str] = []
        placed: dict[str, Placed] = {}
        self.make_stand_ins()
        for level in self.top.levels():
            for name in level.failed:
                self.failed.add(level.flat(name))
        instances = self.instances()
        for level, local, entry in self.top.placed():
            name = level.flat(local)
            order_of.append(name)
            if name in self.failed:
                continue
            p = self.place(level, name, entry)
            if p is None or not self.check_references(p, instances):
                self.failed.add(name)
            else:
                placed[name] = p
        order, cycles = build_order({n: {k: b.target for k, b in p.references.items() if not b.stand_in}
                                     for n, p in placed.items()})
        cyclic = {r.block for cycle in cycles for r in cycle}
        for cycle in cycles:
            first = placed[cycle[0].block]
            self.param_error(first, (cycle[0].param,), f"block references form a cycle: {chain_text(cycle)}",
                             "a referenced block is built before the blocks that refer to it; "
                             "remove one of these references")
        for name in order:
            p = placed[name]
            # a block on a cycle, or referring to a block that failed (reported there), is not built
            ready = name not in cyclic and all(b.stand_in or b.target in self.specs for b in p.references.values())
            spec = self.make(p) if ready else None
            if spec is None:
                self.failed.add(name)
            else:
                self.specs[name] = spec
        return {name: self.specs[name] for name in order_of if name in self.specs}

    # -- stand-ins and instances ------------------------------------------------------

    def make_stand_ins(self) -> None:
        """The blocks that take the place of the top diagram's own references."""
        for name, ref in self.top.references.items():
            if ref.stand_in is None:
                continue
            if isinstance(ref.stand_in, Block):  # a block made elsewhere stands in as it is
                self.stand_ins[name] = ref.stand_in
                continue
            try:
                cls = ref.stand_in if isinstance(ref.stand_in, type) else \
                    resolve_type(str(ref.stand_in), self.top.builder.trust, self.top.code_dir)
                self.stand_ins[name] = cls.example()
                self.stand_ins[name].name = name
            except RegistryError as exc:
                self.error(ref.site, name, f"reference '{name}': {exc}", exc.hint)
            except Exception as exc:  # the type's example could not be made
                self.error(ref.site, name, f"reference '{name}': cannot make a stand-in "
                           f"{ref.stand_in}: {exc}")

    def instances(self) -> dict[int, str]:
        """The Block instances added as blocks, by identity -> path name."""
        found: dict[int, str] = {}
        for level in self.top.levels():
            for local, entry in level.blocks.items():
                if isinstance(entry.block, Block):
                    name = level.flat(local)
                    other = found.setdefault(id(entry.block), name)
                    if other != name:
                        self.error(entry.site, None, f"block '{name}' is the Block instance already placed as "
                                   f"'{other}'", "an instance is one block; add it by type to use it twice "
                                   "(a builder with instances can be one subsystem only)")
                        self.failed.add(name)
        return found

    # -- an entry up to its constructor call ------------------------------------------

    def place(self, level: Level, name: str, entry: BlockEntry) -> Placed | None:
        """Check a block's type, timing and parameters, up to its constructor call."""
        site = entry.site
        given = entry.block
        instance = given if isinstance(given, Block) else None
        if instance is not None:
            cls = type(instance)
        elif isinstance(given, type) and issubclass(given, Block):
            cls = given
        elif not isinstance(given, str):
            self.error(site, "type", f"block '{name}' needs a 'type' naming a block type",
                       "run 'hierhand blocks' to list the registered types")
            return None
        else:
            try:
                cls = resolve_type(given, level.builder.trust, level.code_dir)
            except RegistryError as exc:
                self.error(site, "type", f"block '{name}': {exc}", exc.hint)
                return None
            if given.startswith(PYTHON_PREFIX):
                self.module_files(level, cls)
        period = offset = None
        if entry.period is not None:
            try:
                period = positive_duration(entry.period, f"block '{name}': period")
            except DurationError as exc:
                self.error(site, "period", str(exc), "write e.g. period: 1 ms; leave it out to inherit")
                return None
        if entry.offset is not None:
            try:
                offset = parse_duration(entry.offset)
            except DurationError as exc:
                self.error(site, "offset", f"block '{name}': offset: {exc}")
                return None
            if period is None:
                self.error(site, "offset", f"block '{name}': an offset needs a period", "add period: ... to the block")
                return None
            if not 0 <= offset < period:
                self.error(site, "offset", f"block '{name}': offset must be in [0, period)",
                           "an offset is a phase within one period")
                return None
        if instance is not None:
            return self.place_instance(level, name, entry, cls, period, offset)
        source = None
        if entry.params_file is not None:
            source = self.params_file(level, name, entry)
            if source is None:
                return None
        checked = self.params(level, name, entry, cls, source)
        if checked is None:
            return None
        params, path_refs = checked
        p = Placed(name, level, entry, cls, period, offset, params, source=source)
        for key, ref in path_refs.items():
            real = self.ctx.found(level.scope.ref(ref), Path(params[key]).expanduser())
            if real != Path(params[key]).expanduser():
                p.arguments[key] = str(real)
        return p

    def place_instance(self, level: Level, name: str, entry: BlockEntry, cls: type[Block],
                       period: Fraction | None, offset: Fraction | None) -> Placed | None:
        """A Block instance: its parameters are its constructor's arguments."""
        site = entry.site
        if entry.params is not None or entry.params_file is not None:
            self.error(site, "params", f"block '{name}' is a Block instance; it takes no params",
                       "give them to its constructor, or add it by type with params=...")
            return None
        ok = True
        for ov in level.overrides.get(level.name_of(name), []):
            ov.report(self.ctx, f"block '{name}' ({cls.registered_name()}) was added as a Block instance; "
                      "its parameters cannot be overridden", "add it by type to override its parameters")
            ok = False
        params = dict(entry.block.constructor_arguments())
        return Placed(name, level, entry, cls, period, offset, params, instance=entry.block) if ok else None

    def module_files(self, level: Level, cls: type) -> None:
        """Record the files of a ``python:`` type's module when it comes from the diagram's
        folder (a package: every .py file in it); installed modules are not the diagram's."""
        module = sys.modules.get(cls.__module__)
        origin = getattr(module, "__file__", None)
        if not origin:
            return
        folder = Path(level.code_dir).resolve()
        origin = Path(origin).resolve()
        top = origin.relative_to(folder).parts[0] if inside(origin, folder) else None
        if top is None:
            return
        found = sorted((folder / top).rglob("*.py")) if (folder / top).is_dir() else [folder / top]
        for path in found:
            if "__pycache__" not in path.parts:
                self.ctx.files[level.scope.ref(path.relative_to(folder).as_posix())] = path

    def params(self, level: Level, name: str, entry: BlockEntry, cls: type[Block],
               source: ParamsFile | None) -> tuple[dict, dict[str, str]] | None:
        """The block's parameters (params file, then ``params``, then overrides), checked
        against its type's, and its path parameters as the diagram names them; None if
        reported bad. Relative paths in ``params`` become paths from its diagram's folder."""
        site = entry.site
        inline = entry.params if entry.params is not None else {}
        if not isinstance(inline, Mapping):
            self.error(site, "params", f"block '{name}': 'params' must be a mapping")
            return None
        params = deep_merge(source.data if source else {}, inline)
        declared = cls.parameters()
        accepts_any = cls.accepts_any_parameter()
        ok = True
        given = [(inline, site.within("params"))]
        if source is not None:
            given.insert(0, (source.data, source.site))
        for mapping, where in given:
            for key in mapping:
                if key not in declared and not accepts_any:
                    self.ctx.add(where.issue(f"block '{name}' ({cls.registered_name()}) has no parameter {key!r}",
                                             suggest(key, declared) or f"parameters: {known(declared)}", key=key))
                    ok = False
        for ov in level.overrides.get(level.name_of(name), []):
            parts = list(ov.path)
            if not parts or not all(parts):
                ov.report(self.ctx, "expected --set block.param=value")
                ok = False
                continue
            parts = cls.override_path(parts)
            if parts[0] not in declared and not accepts_any:
                ov.report(self.ctx, f"block '{name}' ({cls.registered_name()}) has no parameter {parts[0]!r}",
                          suggest(parts[0], declared) or f"parameters: {known(declared)}")
                ok = False
                continue
            try:
                set_path(params, name, parts, ov.value, cls.param_default)
            except PathError as exc:
                ov.report(self.ctx, str(exc), exc.hint)
                ok = False
        missing = [p for p, d in declared.items() if d.default is d.empty and p not in params]
        if missing:
            self.error(site, "params", f"block '{name}' ({cls.registered_name()}) is missing parameter(s) "
                       f"{', '.join(missing)}", f"add them under params: of block '{level.name_of(name)}'")
            ok = False
        if not ok:
            return None
        path_refs = {}
        overridden = {ov.path[0] for ov in level.overrides.get(level.name_of(name), []) if ov.path}
        for key in cls.path_params:
            value = params.get(key)
            if isinstance(value, str) and value.strip():
                path_refs[key] = value
                if not Path(value).expanduser().is_absolute():
                    params[key] = str(level.scope.folder / value)
                if (key in cls.confined_params and key not in overridden and not level.builder.trust
                        and not inside(Path(params[key]).expanduser(), level.scope.folder)):
                    self.error(site, "params", f"block '{name}': {key} '{value}' is outside the diagram's folder",
                               OUTSIDE_HINT)
                    return None
        return params, path_refs

    def params_file(self, level: Level, name: str, entry: BlockEntry) -> ParamsFile | None:
        """Read the block's params file; without ``trust`` it must lie in its diagram's
        folder tree (see ``blocks.safepath``)."""
        rel, site = entry.params_file, entry.site
        if not isinstance(rel, str):
            self.error(site, "params_file", f"block '{name}': params_file must be a path")
            return None
        folder = level.scope.folder
        path = folder / rel
        if not level.builder.trust and not inside(path, folder):
            self.error(site, "params_file", f"block '{name}': params_file '{rel}' is outside the diagram's folder",
                       OUTSIDE_HINT)
            return None
        ref = level.scope.ref(rel)
        read = level.builder.read_params or default_params_reader()
        try:
            found = read(self.ctx.files_map.get(ref, path))
        except FileNotFoundError:
            self.error(site, "params_file", f"block '{name}': params_file '{rel}' not found (looked at {path})",
                       "params_file is relative to the diagram's folder")
            return None
        except SourceError as exc:
            if exc.line is None:  # the file as a whole: reported where the diagram names it
                self.error(site, "params_file", f"block '{name}': params_file '{rel}': {exc.message}", exc.hint)
            else:
                self.ctx.error(str(path), exc.line, exc.message, exc.hint)
            return None
        self.ctx.found(ref, path)
        self.ctx.hash.update(found.text.encode("utf-8"))
        return ParamsFile(found.params, Site(str(path), 1, found.positions))

    # -- references -------------------------------------------------------------------

    def check_references(self, p: Placed, instances: dict[int, str]) -> bool:
        """Resolve the block's block-reference parameters (names of its level's blocks or
        references; for an instance, the blocks it was made with); False (reported) if one
        is bad."""
        ok = True
        level = p.level
        for key in p.cls.block_params:
            if key not in p.params:
                continue
            target = p.params[key]
            if isinstance(target, Block) and id(target) in instances:  # from Python, the block itself
                flat = instances[id(target)]
                if p.instance is not None or level.name_of(flat) is not None:
                    p.references[key] = Bound(flat)
                    p.params[key] = level.name_of(flat) or flat
                    continue
            if p.instance is not None:
                standing = next((n for n, b in self.stand_ins.items() if b is target), None)
                if standing is not None:  # the block one of the top diagram's references stands in for
                    p.references[key] = Bound(standing, stand_in=True)
                    p.params[key] = standing
                    continue
                if isinstance(target, Block):
                    self.error(p.site, None, f"block '{p.name}': parameter '{key}' is a block that is not in "
                               "this diagram", "add that block to the diagram too")
                    ok = False
                continue
            what = f"block '{p.name}': parameter '{key}'"
            found = resolve_reference(level, target)
            if found == NOT_A_NAME:
                self.param_error(p, (key,), f"{what} must be the name of a block of this diagram, got {target!r}",
                                 f"e.g. {key}: <block name>")
            elif target == level.name_of(p.name):
                self.param_error(p, (key,), f"{what} refers to the block itself",
                                 f"name another block of this diagram; blocks are: {known(level.blocks)}")
            elif found == UNKNOWN:
                names = [*level.blocks, *level.references]
                self.param_error(p, (key,), f"{what} names no block '{target}'",
                                 suggest(target, names) or f"blocks are: {known(names)}")
            elif found == SUBSYSTEM:
                self.param_error(p, (key,), f"{what} names subsystem '{level.flat(target)}', not a block",
                                 "a subsystem's blocks are its own; refer to a block of this diagram")
            elif isinstance(found, Bound) and found.stand_in and found.target not in self.stand_ins:
                if self.top.references[found.target].stand_in is None:
                    self.param_error(p, (key,), f"{what} names '{found.target}', a reference that an including "
                                     "diagram binds, and this diagram is loaded on its own",
                                     f"load it as a subsystem (bind: {{{found.target}: <block>}}), or name a "
                                     f"stand-in type: references: {{{found.target}: <type>}}")
            elif isinstance(found, Bound):
                p.references[key] = found
                continue
            ok = False
        return ok

    def param_error(self, p: Placed, path: tuple, message: str, hint: str = "") -> None:
        """An issue about a parameter value (``path``: the parameter, then keys and indices
        into it), reported where that value comes from: the override that gave it (or a
        part of it), the caller's first, else the deepest part of the path written in the
        block's ``params:`` or its params file, else the block's parameters as a whole."""
        parts = [str(x) for x in path]
        for ov in reversed(p.overrides):
            given = list(ov.path)
            if parts and (given[:len(parts)] == parts or parts[:len(given)] == given):
                ov.report(self.ctx, message, hint)
                return
        site = p.site
        line, found = site.within("params").line_at(path) if p.entry.params is not None else (None, 0)
        file = site.file
        if p.source is not None:
            file_line, file_found = p.source.site.line_at(path)
            if file_found > found:
                file, line, found = p.source.site.file, file_line, file_found
        if not found:
            line = site.key("params") if p.entry.params is not None else site.key("params_file")
        self.ctx.error(file, line, message, hint)

    # -- construction -----------------------------------------------------------------

    def make(self, p: Placed) -> BlockSpec | None:
        """Construct and bind the block, its references given as the blocks they name."""
        name, site, cls, period = p.name, p.site, p.cls, p.period
        type_name = p.entry.block if isinstance(p.entry.block, str) else cls.registered_name()
        block = p.instance
        if block is None:
            arguments = dict(p.params)
            arguments.update(p.arguments)
            arguments.update({key: self.stand_ins[b.target] if b.stand_in else self.specs[b.target].block
                              for key, b in p.references.items()})
            try:
                block = cls(**arguments)
            except Exception as exc:  # a block's own message says which parameter is wrong
                problems = exc.problems if isinstance(exc, ParameterError) else [(_named(exc), str(exc))]
                hint = getattr(exc, "hint", "") or f"see 'hierhand blocks {cls.registered_name()}' for its parameters"
                for path, text in problems:
                    self.param_error(p, path, f"block '{name}' ({type_name}): {text}", hint)
                return None
        try:
            block.bind(period)
        except Exception as exc:  # the period does not suit the block: said at the period
            self.error(site, "period", f"block '{name}' ({type_name}): {exc}")
            return None
        if period is None and block.period is not None:
            period = block.period  # a block with a natural rate (an FMU's default step)
        block.name = name
        for kind in ("inputs", "outputs"):
            ports = getattr(block, kind)
            if not isinstance(ports, Mapping) or not all(
                    isinstance(q, str) and (w is None or (isinstance(w, int) and 0 < w <= MAX_PORT_WIDTH))
                    for q, w in ports.items()):
                self.ctx.add(site.issue(f"block '{name}' ({type_name}) declares invalid {kind}: {ports!r}",
                                        f"ports map names to integer widths from 1 to {MAX_PORT_WIDTH} "
                                        "(or None to infer)"))
                return None
        params_file = str(p.level.scope.folder / p.entry.params_file) if p.entry.params_file is not None else None
        return BlockSpec(name, cls.registered_name(), block, period, p.offset or Fraction(0), p.params, site.line,
                         params_file, references={k: b.target for k, b in p.references.items()},
                         file=site.file if site.file != self.top.file else None,
                         type_ref=p.entry.block if isinstance(p.entry.block, str) else type_ref(cls),
                         scope=p.level.scope)
