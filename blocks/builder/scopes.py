"""Subsystems as levels of one flat diagram: names by path, overrides and bindings routed.

A diagram with subsystems is a tree of builders: the top one and, for each subsystem
entry, the builder it includes. ``expand`` walks the tree into ``Level``s, in the order
their blocks stand in the flat diagram (a subsystem's blocks where its entry is), each
with the prefix of its names (``ctrl.``), where its relative paths lead (``FileScope``),
the overrides that reach its blocks and what its block references are bound to. A
diagram that includes itself, directly or not, is refused with the chain; the nesting
and the blocks subsystems add stop at the limits of ``blocks.limits``.

Overrides (``--set ctrl.prop.k=2``, a subsystem entry's ``params: {prop.k: 2}``) are
paths of names: each part before the parameter names a subsystem of the level reached
so far, until one names a block. The override written further out wins: ``--set`` over
the top diagram's entries, those over the entries of the subsystems inside.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator, Mapping

from blocks.builder.context import BuildContext, known, suggest
from blocks.builder.diagram import FileScope
from blocks.issues import DiagramError
from blocks.limits import MAX_SUBSYSTEM_BLOCKS, MAX_SUBSYSTEM_DEPTH
from blocks.builder.records import BlockEntry, DiagramRecord, ReferenceEntry, Site, SubsystemEntry

NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
"""A block's (or subsystem's, port's, reference's) name as a diagram writes it."""
CLI_RANK = 1
"""The rank of the caller's overrides (``--set``, ``--grid``): above every entry's ``params``."""


@dataclass
class Override:
    """A value for a path into a block's parameters (``("contact", "mu_s")``), from the
    caller (``site`` None: reported as the caller gave ``key``) or from a subsystem
    entry's ``params`` (``site``: that mapping, ``key`` its key). The highest ``rank`` wins."""

    path: tuple[str, ...]
    value: Any
    key: str
    rank: int
    site: Site | None = None

    def report(self, ctx: BuildContext, message: str, hint: str = "") -> None:
        if self.site is None:
            ctx.override_error(self.key, message, hint)
        else:
            ctx.add(self.site.issue(message, hint, key=self.key))


@dataclass(frozen=True)
class Bound:
    """What a block reference leads to: a block, by its path name, or (``stand_in``) the
    block standing in for a reference of a diagram loaded on its own, by its name."""

    target: str
    stand_in: bool = False


@dataclass
class Level:
    """One builder placed in the flat diagram: at the top (``path`` ``""``) or as the
    subsystem ``path``."""

    builder: DiagramRecord
    path: str
    parent: Level | None
    entry: SubsystemEntry | None
    scope: FileScope
    code_dir: Path
    depth: int
    blocks: dict[str, BlockEntry] = field(default_factory=dict)
    subsystems: dict[str, "Level"] = field(default_factory=dict)
    failed: set[str] = field(default_factory=set)
    """Names whose entry is spoiled (already reported): not reported again where used."""
    references: dict[str, ReferenceEntry] = field(default_factory=dict)
    bindings: dict[str, Bound | None] = field(default_factory=dict)
    """Each declared reference -> what it is bound to (None: a bad binding, reported)."""
    overrides: dict[str, list[Override]] = field(default_factory=dict)
    """Block (local name) -> the overrides that reach it, lowest rank first."""
    params: dict[str, Any] = field(default_factory=dict)
    """For a subsystem: the overrides routed into it, by dotted path inside it."""
    order: list[str] = field(default_factory=list)
    """Its blocks and subsystems in the order written."""

    def flat(self, local: str) -> str:
        """The path name of this level's ``local`` block or subsystem (``ctrl.integ``)."""
        return f"{self.path}.{local}" if self.path else local

    def name_of(self, flat: str) -> str | None:
        """The name this level's file gives the block or subsystem at path ``flat``; None
        when it is not written in this level."""
        if not self.path:
            return flat if "." not in flat else None
        head = self.path + "."
        rest = flat[len(head):] if flat.startswith(head) else None
        return rest if rest and "." not in rest else None

    @property
    def file(self) -> str:
        return self.builder.file

    def names(self) -> list[str]:
        """Every name written in this level that is a block or subsystem, as path names."""
        return [self.flat(n) for n in (*self.blocks, *self.subsystems)]

    def has(self, local: str) -> bool:
        return local in self.blocks or local in self.subsystems or local in self.failed

    def placed(self) -> Iterator[tuple["Level", str, BlockEntry]]:
        """(level, name, entry) of every block, in the flat diagram's order: a subsystem's
        blocks where its entry is written."""
        for name in self.order:
            if name in self.blocks:
                yield self, name, self.blocks[name]
            elif name in self.subsystems:
                yield from self.subsystems[name].placed()

    def levels(self) -> Iterator["Level"]:
        """This level and every level inside it, in the order their blocks stand."""
        yield self
        for sub in self.subsystems.values():
            yield from sub.levels()

    def describe(self) -> str:
        """``subsystem 'ctrl' (pi.yaml)`` for messages."""
        source = self.entry.source if self.entry is not None and self.entry.source else self.builder.label
        return f"subsystem '{self.path}' ({source})"


def expand(ctx: BuildContext, root: DiagramRecord) -> Level:
    """The level tree of ``root``, with names checked, overrides routed and references bound."""
    top = Level(root, "", None, None, FileScope(root.base_dir, "."),
                Path(ctx.files_map.get(".", root.base_dir)), 0)
    _Expander(ctx, root).fill(top, [root])
    route_overrides(ctx, top)
    bind_references(ctx, top)
    return top


class _Expander:
    def __init__(self, ctx: BuildContext, root: DiagramRecord):
        self.ctx = ctx
        self.root = root
        self.added = 0

    def fill(self, level: Level, chain: list[DiagramRecord]) -> None:
        """Check the names of ``level``'s entries and place its subsystems (recursively)."""
        ctx, b = self.ctx, level.builder
        for problem in b.problems:
            ctx.add(problem.issue)
            if problem.name is not None:
                level.failed.add(problem.name)
        seen: dict[str, Site] = {}
        for ref in b.references:
            if not isinstance(ref.name, str) or not NAME.match(ref.name):
                ctx.add(ref.site.issue(f"invalid reference name {ref.name!r}",
                                       "use letters, digits and '_' (not starting with a digit)"))
            elif ref.name in level.references:
                ctx.add(ref.site.issue(f"reference '{ref.name}' is declared twice"))
            else:
                level.references[ref.name] = ref
        for entry in b.entries:
            name = entry.name
            if not isinstance(name, str) or not NAME.match(name):
                ctx.add(entry.site.issue(f"invalid block name {name!r}",
                                         "use letters, digits and '_' (not starting with a digit)"))
                continue
            if name in seen:
                first = seen[name]
                ctx.add(entry.site.issue(f"block '{level.flat(name)}' is added twice (first at {first.file}:"
                                         f"{first.line})",
                                         "the blocks of a diagram have different names"))
                continue
            seen[name] = entry.site
            if name in level.references:
                ctx.add(level.references[name].site.issue(
                    f"reference '{name}' has the name of a block of this diagram",
                    "a reference stands for a block the including diagram binds; give it another name"))
                level.failed.add(name)
            elif isinstance(entry, SubsystemEntry):
                level.order.append(name)
                self.subsystem(level, entry, chain)
            else:
                level.order.append(name)
                level.blocks[name] = entry
                self.count(level, entry.site, 1)

    def subsystem(self, level: Level, entry: SubsystemEntry, chain: list[DiagramRecord]) -> None:
        ctx, name = self.ctx, entry.name
        path = level.flat(name)
        scope = level.scope
        inner = entry.builder
        if not isinstance(inner, DiagramRecord):
            try:
                inner, read = inner.open(scope, path)
            except DiagramError as exc:
                for issue in exc.issues:
                    ctx.add(issue)
                level.failed.add(name)
                return
            ctx.files.update(read)
        elif inner.texts and Path(inner.file).is_file():  # a builder read from a file, given in Python
            ctx.files.setdefault(_relative_dir(Path(inner.file), self.root.base_dir), Path(inner.file))
        if any(inner is b for b in chain):
            names = [b.label for b in chain[next(i for i, b in enumerate(chain) if b is inner):]]
            ctx.add(entry.site.issue(f"subsystem '{path}': {inner.label} includes itself: "
                                     f"{' -> '.join(names + [inner.label])}",
                                     "a diagram cannot contain itself; remove the subsystem that closes the chain"))
            level.failed.add(name)
            return
        if level.depth + 1 > MAX_SUBSYSTEM_DEPTH:
            ctx.add(entry.site.issue(f"subsystem '{path}': subsystems nested deeper than {MAX_SUBSYSTEM_DEPTH} "
                                     "levels", "the limit guards against hostile chains of files"))
            level.failed.add(name)
            return
        folder = inner.base_dir
        ref_dir = _relative_dir(folder, self.root.base_dir)
        code_root = ctx.files_map.get(".")
        code_dir = folder if code_root is None or Path(ref_dir).is_absolute() else Path(code_root) / ref_dir
        child = Level(inner, path, level, entry, FileScope(folder, ref_dir), code_dir, level.depth + 1)
        level.subsystems[name] = child
        for text in inner.texts or [inner.fingerprint()]:
            ctx.hash.update(text.encode("utf-8"))
        self.fill(child, chain + [inner])

    def count(self, level: Level, site: Site, n: int) -> None:
        """Count the blocks subsystems add; past MAX_SUBSYSTEM_BLOCKS, stop the build."""
        if level.depth == 0:
            return
        self.added += n
        if self.added > MAX_SUBSYSTEM_BLOCKS:
            top = level
            while top.parent is not None and top.parent.depth > 0:
                top = top.parent
            raise DiagramError(self.ctx.issues + [top.entry.site.issue(
                f"the subsystems add more than {MAX_SUBSYSTEM_BLOCKS} blocks",
                "the limit guards against files that include each other many times over")])


def _relative_dir(folder: Path, top: Path) -> str:
    """``folder`` as a posix path relative to ``top`` (``.``, ``sub``, ``../lib``), or
    absolute where it has none (another drive)."""
    try:
        return Path(os.path.relpath(folder, top)).as_posix()
    except ValueError:
        return Path(folder).resolve().as_posix()


# -- overrides ---------------------------------------------------------------------------------


def route_overrides(ctx: BuildContext, top: Level) -> None:
    """Give every block the overrides that reach it: the caller's at the top, each
    subsystem entry's ``params`` inside its subsystem; the lowest rank first, so that
    each subsystem's ``params`` (what it was given from outside) ends with the winner."""
    given: list[tuple[Level, Override]] = []
    for level in top.levels():
        if level.entry is None or level.entry.params is None:
            continue
        params, site = level.entry.params, level.entry.site
        if not isinstance(params, Mapping):
            ctx.add(site.issue(f"{level.describe()}: 'params' must be a mapping of block.param paths to values",
                               "params: {prop.k: 2.0}", key="params"))
            continue
        inner_site = site.within("params")
        for key, value in params.items():
            if not isinstance(key, str):
                ctx.add(inner_site.issue(f"{level.describe()}: params key {key!r} is not a block.param path",
                                         key=key))
                continue
            given.append((level, Override((), value, key, -level.parent.depth, inner_site)))
    given += [(top, Override((), value, key, CLI_RANK)) for key, value in ctx.overrides.items()]
    for level, ov in sorted(given, key=lambda g: g[1].rank):
        if level.entry is not None:
            level.params[ov.key] = ov.value
        route(ctx, level, str(ov.key).split("."), ov)


def route(ctx: BuildContext, level: Level, parts: list[str], ov: Override) -> None:
    """Follow ``parts`` from ``level`` to the block they name and give it ``ov``."""
    first, rest = parts[0], parts[1:]
    if not level.has(first):
        names = level.names()
        ov.report(ctx, f"no block named '{level.flat(first)}'", suggest(level.flat(first), names) or
                  f"blocks are: {known(names)}")
        return
    if first in level.failed:
        return
    if first in level.subsystems:
        sub = level.subsystems[first]
        if not rest:
            ov.report(ctx, "expected --set block.param=value")
            return
        sub.params[".".join(rest)] = ov.value
        route(ctx, sub, rest, ov)
        return
    level.overrides.setdefault(first, []).append(
        Override(tuple(rest), ov.value, ov.key, ov.rank, ov.site))


# -- block references --------------------------------------------------------------------------


def bind_references(ctx: BuildContext, top: Level) -> None:
    """What each level's declared references lead to: at the top, their stand-ins; inside,
    the blocks the including entry's ``bind`` names (checked)."""
    for name in top.references:
        top.bindings[name] = Bound(name, stand_in=True)
    for level in top.levels():
        if level.entry is not None:
            _bind(ctx, level)


def _bind(ctx: BuildContext, level: Level) -> None:
    entry, parent = level.entry, level.parent
    bind = entry.bind if entry.bind is not None else {}
    site = entry.site
    if not isinstance(bind, Mapping):
        ctx.add(site.issue(f"{level.describe()}: 'bind' must be a mapping of its references to blocks",
                           "bind: {plant: hand}", key="bind"))
        level.bindings = dict.fromkeys(level.references)
        return
    inner_site = site.within("bind")
    for key in bind:
        if key not in level.references:
            ctx.add(inner_site.issue(f"{level.describe()} declares no reference {key!r}",
                                     suggest(key, level.references) or
                                     f"its references are: {known(level.references)}", key=key))
    for name in level.references:
        if name not in bind:
            level.bindings[name] = None
            ctx.add(site.issue(f"{level.describe()} needs its reference '{name}' bound to a block of this diagram",
                               f"add bind: {{{name}: <block>}} to the entry '{entry.name}'"))
            continue
        target = bind[name]
        found = resolve_reference(parent, target)
        what = f"{level.describe()}: bind {name}"
        if found == NOT_A_NAME:
            ctx.add(inner_site.issue(f"{what}: expected the name of a block of this diagram, got {target!r}",
                                     key=name))
        elif found == SUBSYSTEM:
            ctx.add(inner_site.issue(f"{what}: '{parent.flat(target)}' is a subsystem, not a block",
                                     "a reference names a block", key=name))
        elif found == UNKNOWN:
            names = [*parent.blocks, *parent.references]
            ctx.add(inner_site.issue(f"{what}: no block named '{target}'",
                                     suggest(target, names) or f"blocks are: {known(names)}", key=name))
        level.bindings[name] = found if isinstance(found, Bound) else None


NOT_A_NAME, UNKNOWN, SUBSYSTEM, SPOILED = "not a name", "unknown", "subsystem", "spoiled"
"""Why ``resolve_reference`` finds no block (SPOILED: the name's entry failed, reported)."""


def resolve_reference(level: Level, target: Any) -> Bound | str:
    """What ``target``, a block name as ``level``'s file writes it, refers to: one of its
    blocks, or one of its own references (bound further out; SPOILED if that binding
    failed); else why not (NOT_A_NAME, UNKNOWN, SUBSYSTEM)."""
    if not isinstance(target, str):
        return NOT_A_NAME
    if target in level.blocks:
        return Bound(level.flat(target))
    if target in level.references:
        return level.bindings.get(target) or SPOILED
    if target in level.failed:
        return SPOILED
    if target in level.subsystems:
        return SUBSYSTEM
    return UNKNOWN
