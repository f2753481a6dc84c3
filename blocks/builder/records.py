"""What a diagram records before it is built: its entries, each with where it was said.

A ``DiagramBuilder`` (``blocks.builder.diagram_builder``) fills a ``DiagramRecord`` from Python calls, the
YAML loader from a file; the build (``blocks.builder.assemble``) reads it. Each entry keeps its
``Site``: the file and line of the Python call, or of the YAML text, with the mapping it
was written as, so that a problem with any part of it is reported where that part is.
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from blocks.issues import Issue
from blocks.diagram_file.yaml_source import LineDict

if TYPE_CHECKING:
    from blocks.builder.diagram import FileScope


@dataclass(frozen=True, slots=True)
class Site:
    """Where part of a diagram was said: a file and line, and for YAML the mapping it was
    written as (a ``LineDict``), whose keys know their own lines."""

    file: str
    line: int | None = None
    mapping: Any = None

    def key(self, key: Any) -> int | None:
        """The line of ``key`` in the mapping, or the site's line (a Python call's line)."""
        if isinstance(self.mapping, LineDict) and key in self.mapping:
            return self.mapping.line_of(key)
        return self.line

    def issue(self, message: str, hint: str = "", key: Any = None) -> Issue:
        return Issue(self.file, self.line if key is None else self.key(key), message, hint)


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
                 base_dir: str | Path | None = None, trust: bool = True, where: Site):
        self.site = where
        self.name = name
        self.description = description
        self.t_end = t_end
        self.t_end_site: Site | None = None
        """Where the end time is written (a YAML ``time`` mapping); None: ``site``."""
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

