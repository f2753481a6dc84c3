"""What a diagram records before it is built: its entries, each with where it was said.

A ``DiagramBuilder`` (``blocks.builder.diagram_builder``) fills a ``DiagramRecord`` from Python calls, a
front end (the YAML file's, an SSP's) from a file; the build (``blocks.builder.assemble``) reads
it. Each entry keeps its ``Site``: the file and line of the Python call, or of the text,
with the ``Positions`` of its parts, so that a problem with any part of it is reported
where that part is. The builder knows no file format: a front end answers ``Positions``
for its text, and reads the params files its diagrams name (``ParamsReader``).
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping, Protocol, Sequence

from blocks.issues import Issue

if TYPE_CHECKING:
    from blocks.builder.diagram import FileScope


class Positions(Protocol):
    """Where the parts of a value a front end read are written (the YAML front end's
    mappings and lists answer this for their text)."""

    def line_at(self, path: Sequence[Any]) -> tuple[int | None, int]:
        """The line of the deepest part of ``path`` (mapping keys and list indices,
        ``("params", "fingers", 1)``) that is written, and how many of its parts are (0:
        none; the line is then the value's own, if known)."""


@dataclass(frozen=True, slots=True)
class _Part:
    """The positions of the part under ``key`` of a value whose positions are ``whole``."""

    whole: Positions
    key: Any

    def line_at(self, path: Sequence[Any]) -> tuple[int | None, int]:
        line, found = self.whole.line_at((self.key, *path))
        return line, max(found - 1, 0)


@dataclass(frozen=True, slots=True)
class Site:
    """Where part of a diagram was said: a file and line, and for a front end's text the
    ``Positions`` of the entry's parts (None: a Python call, whose parts are all at its
    line)."""

    file: str
    line: int | None = None
    positions: Positions | None = None

    def line_at(self, path: Sequence[Any]) -> tuple[int | None, int]:
        """The line of the deepest part of ``path`` written in the entry and how many of
        its parts are; (the site's line, 0) when none is."""
        if self.positions is not None:
            line, found = self.positions.line_at(tuple(path))
            if found:
                return line, found
        return self.line, 0

    def key(self, key: Any) -> int | None:
        """The line of ``key`` in the entry, or the site's line (a Python call's line)."""
        return self.line_at((key,))[0]

    def within(self, key: Any) -> "Site":
        """The site of the value written under ``key`` (a Python call's: this one)."""
        line, found = self.line_at((key,))
        if not found:
            return self if self.positions is None else Site(self.file, self.line)
        return Site(self.file, line, _Part(self.positions, key))

    def issue(self, message: str, hint: str = "", key: Any = None) -> Issue:
        return Issue(self.file, self.line if key is None else self.key(key), message, hint)


class SourceError(Exception):
    """A file a front end cannot read for the builder (a params file): ``message`` at
    ``line`` (1-based; None: the file as a whole), with a hint."""

    def __init__(self, message: str, line: int | None, hint: str = ""):
        super().__init__(message)
        self.message = message
        self.line = line
        self.hint = hint


@dataclass(frozen=True, slots=True)
class ParamsText:
    """A params file as a front end read it: its text (the diagram's hash covers it), its
    parameters (a mapping, empty for an empty file) and where they are written."""

    text: str
    params: Mapping
    positions: Positions | None = None


ParamsReader = Callable[[Path], ParamsText]
"""Reads the params file at a path: FileNotFoundError when there is none, SourceError when
it cannot be read as one."""

def call_site(depth: int = 2) -> Site:
    """The file and line of the caller's caller (a builder method's caller)."""
    frame = sys._getframe(depth)
    return Site(frame.f_code.co_filename, frame.f_lineno)


@dataclass
class BlockEntry:
    """``add``: a block by type (a registered name, ``python:mod:Class`` or a class) or
    an instance, with its timing and parameters as given."""

    name: Any
    block: Any
    period: Any
    offset: Any
    params: Any
    params_file: Any
    site: Site


@dataclass
class SubsystemEntry:
    """``add_subsystem``: another diagram's builder as one block of this one."""

    name: Any
    builder: "DiagramRecord | DiagramSource"
    params: Any
    bind: Any
    site: Site
    source: str | None = None
    """The diagram file as the including YAML names it (``pi.yaml``)."""


@dataclass
class WireEntry:
    """``connect``: ``src`` (an output ``block.port``) to ``dst`` (an input)."""

    src: Any
    dst: Any
    delay: Any
    initial: Any
    site: Site
    has_initial: bool = False


@dataclass
class PortEntry:
    """``input`` (the inner inputs it feeds) or ``output`` (the inner output it is)."""

    name: Any
    signals: tuple
    site: Site


@dataclass
class ReferenceEntry:
    """``reference``: a block reference the including diagram binds, and the type that
    stands in for it when this diagram is loaded on its own (None: no stand-in)."""

    name: Any
    stand_in: Any
    site: Site


@dataclass
class Annotation:
    """``annotate`` (or a block entry's ``units`` / ``elements``): the unit(s) and element
    names the diagram gives a port (``signal``: ``block.port``) of a block that has none."""

    signal: Any
    units: Any
    elements: Any
    site: Site


@dataclass
class LogRequest:
    """``log``: a signal (``block.port``, ``sub.block.port``), or (``every``) every signal."""

    signal: Any
    decimate: Any
    site: Site
    every: bool = False


@dataclass
class Problem:
    """A problem the front end found in its file; ``name``: a block entry it spoils (so
    that wires to that block are not reported again)."""

    issue: Issue
    name: str | None = None


class DiagramSource(Protocol):
    """A subsystem's diagram that a front end reads only when the build reaches it (a file
    that includes itself is then one more level of the chain, which the build refuses)."""

    def open(self, scope: "FileScope", path: str) -> tuple["DiagramRecord", dict[str, Path]]:
        """The builder of the subsystem ``path`` (``ctrl``) and the files read for it, by
        reference from the top diagram's folder (``scope``: where the including file's
        paths lead). Raises DiagramError with the problems of reading it."""


class DiagramRecord:
    """A diagram as recorded: its fields and entries, in the order given."""

    def __init__(self, name: Any = "diagram", description: Any = "", t_end: Any = None, *,
                 base_dir: str | Path | None = None, trust: bool = True, where: Site,
                 read_params: ParamsReader | None = None):
        self.site = where
        self.read_params = read_params
        """How its params files are read (None: ``blocks.builder.params_reader``)."""
        self.name = name
        self.description = description
        self.t_end = t_end
        self.t_end_site: Site | None = None
        """Where the end time is written (a YAML ``time`` mapping, with a ``t_end`` key); None: ``site``."""
        self.base_dir = Path(base_dir) if base_dir is not None else Path.cwd()
        self.trust = trust
        self.file = self.site.file
        self.label = f"diagram '{name}' ({self.site.file}:{self.site.line})"
        """The diagram in a chain of subsystems (its file, for one read from a file)."""
        self.entries: list[BlockEntry | SubsystemEntry] = []
        self.wires: list[WireEntry] = []
        self.inputs: list[PortEntry] = []
        self.outputs: list[PortEntry] = []
        self.references: list[ReferenceEntry] = []
        self.logs: list[LogRequest] = []
        self.annotations: list[Annotation] = []
        self.problems: list[Problem] = []
        self.texts: list[str] = []
        """The source texts the diagram comes from (its YAML), for its hash."""
        self.files_map: dict[str, Path] = {}
        """Where to read each file the diagram names, by reference (``load_diagram``'s
        ``files``); used for the top diagram, its subsystems' files included."""
        self.files_read: dict[str, Path] = {}
        """Files the front end read for it (its subsystems' diagram files), by reference."""

    def fingerprint(self) -> str:
        """What this builder records, as text: the source of a diagram made in code, which
        its hash covers as a YAML diagram's hash covers its text."""
        from blocks.builder.diagram import jsonable

        def block(value: Any) -> Any:
            if isinstance(value, type):
                return f"{value.__module__}:{value.__qualname__}"
            if hasattr(value, "constructor_arguments"):
                return [block(type(value)), jsonable(value.constructor_arguments())]
            return jsonable(value)

        record = {
            "name": jsonable(self.name), "t_end": jsonable(self.t_end),
            "blocks": [[jsonable(e.name), ["subsystem", jsonable(e.params), jsonable(e.bind)]
                        if isinstance(e, SubsystemEntry) else
                        [block(e.block), jsonable(e.period), jsonable(e.offset), jsonable(e.params),
                         jsonable(e.params_file)]] for e in self.entries],
            "wires": [jsonable([w.src, w.dst, w.delay, w.initial]) for w in self.wires],
            "inputs": [jsonable([p.name, list(p.signals)]) for p in self.inputs],
            "outputs": [jsonable([p.name, list(p.signals)]) for p in self.outputs],
            "references": [jsonable([r.name, block(r.stand_in)]) for r in self.references],
            "log": [jsonable([r.signal, r.decimate, r.every]) for r in self.logs],
        }
        if self.annotations:
            record["annotations"] = [jsonable([a.signal, a.units, a.elements]) for a in self.annotations]
        return json.dumps(record, sort_keys=True, default=str)

