"""A validated diagram as plain data: blocks, connections, logged signals, end time.

The builder (``blocks.builder.diagram_builder``, which the YAML loader drives) makes a ``Diagram``; the
planner (``blocks.engine.schedule``) and the executor (``blocks.simulate``) read it. A Diagram is
flat: the blocks of its subsystems are blocks of its own, named by their path
(``ctrl.integ``), so the planner and executor see one diagram. What the files wrote, the
subsystems with their ports and wires, is kept beside it (``root``, ``subsystems``) for
the commands that show it. A Diagram is not changed after loading and holds nothing
derived from it (the plans the planner builds are kept by the planner), so one Diagram
can be planned and run any number of times.
"""

from __future__ import annotations

import dataclasses
import posixpath
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from blocks.block import Block
from blocks.issues import Issue
from blocks.limits import MAX_DECIMATE
from blocks.builder.references import Reference


@dataclass(frozen=True)
class FileScope:
    """Where the relative paths of one diagram file lead: its folder, and that folder as a
    reference relative to the top diagram's folder (``"."`` for the top diagram itself;
    ``sub`` for a subsystem read from ``sub/pi.yaml``). ``Diagram.files`` names every file
    by such a reference, so a diagram and its subsystems can be copied as one tree."""

    folder: Path = field(default_factory=Path.cwd)
    ref_dir: str = "."

    def ref(self, path: str) -> str:
        """The reference, from the top diagram's folder, of ``path`` as this file names it
        (kept as written in the top diagram; an absolute path stays absolute)."""
        if self.ref_dir == "." or Path(path).expanduser().is_absolute():
            return path
        return posixpath.normpath(posixpath.join(self.ref_dir, Path(path).as_posix()))

    def path(self, path: str) -> Path:
        """Where ``path``, as this file names it, lies (relative ones against its folder)."""
        given = Path(path).expanduser()
        return given if given.is_absolute() else self.folder / path


@dataclass
class BlockSpec:
    """A block of the diagram: its name, configured block object, period and offset.

    A block of a subsystem is named by its path (``ctrl.integ``) and written in the
    subsystem's file (``file``, None: the diagram's own)."""

    name: str
    type_name: str
    block: Block
    period: Fraction | None
    offset: Fraction
    params: dict
    line: int
    params_file: str | None = None
    """The block's params_file (resolved against its diagram's folder), if it has one."""
    references: dict[str, str] = field(default_factory=dict)
    """This block's block references: parameter -> the (path) name of the block it refers
    to; for a reference a diagram loaded on its own leaves unbound, the reference's name."""
    file: str | None = None
    type_ref: str | None = None
    """The type as the diagram names it (``Gain``, ``python:mod:Cls``); None: ``type_name``."""
    scope: FileScope = field(default_factory=FileScope)
    """Where the relative paths of its file lead."""
    units: dict[str, str | list[str]] = field(default_factory=dict)
    """The units the diagram gives its ports (``blocks.builder.annotations``), by port."""
    labels: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """The element names the diagram gives its ports, by port."""

    def port_units(self, port: str) -> str | list[str] | None:
        """The unit(s) of ``port``: the diagram's, else the block's own (None: unknown)."""
        return self.units.get(port) or self.block.port_units(port)

    def element_labels(self, port: str) -> list[str] | None:
        """The element names of ``port``: the diagram's, else the block's (None: numbered)."""
        given = self.labels.get(port)
        return list(given) if given is not None else self.block.element_labels(port)


@dataclass(frozen=True)
class Connection:
    """A wire from an output port to an input port, optionally delayed by one sample.

    Either end may name some of its port's elements (``c.y[1] -> g.u``, ``a.y -> g.u[0]``,
    by label, index or slice: ``blocks.builder.elements``): ``src_select`` / ``dst_select`` as
    written, and once the widths are known the 0-based ``src_elements`` / ``dst_elements``
    they stand for (None: the whole port). Several connections may then drive one input,
    each some of its elements."""

    src_block: str
    src_port: str
    dst_block: str
    dst_port: str
    delay: int = 0
    initial: tuple[float, ...] | None = None
    line: int = 0
    file: str | None = None
    """The file the connection is written in (None: the diagram's own; a subsystem's file
    for a wire of a subsystem or one into or out of it)."""
    src_select: str | None = None
    dst_select: str | None = None
    src_elements: tuple[int, ...] | None = None
    dst_elements: tuple[int, ...] | None = None

    @property
    def src(self) -> str:
        """The source port, ``block.port``."""
        return f"{self.src_block}.{self.src_port}"

    @property
    def dst(self) -> str:
        """The destination port, ``block.port``."""
        return f"{self.dst_block}.{self.dst_port}"

    @property
    def src_text(self) -> str:
        """The source as written: ``c.y`` or ``c.y[1]``."""
        return self.src if self.src_select is None else f"{self.src}[{self.src_select}]"

    @property
    def dst_text(self) -> str:
        return self.dst if self.dst_select is None else f"{self.dst}[{self.dst_select}]"

    @property
    def by_element(self) -> bool:
        """Whether either end names elements."""
        return self.src_select is not None or self.dst_select is not None

    def __str__(self) -> str:
        return f"{self.src_text} -> {self.dst_text}" + (" (delay 1)" if self.delay else "")


@dataclass(frozen=True)
class LogEntry:
    """A signal to record: ``block.port`` at every ``decimate``-th sample hit."""

    block: str
    port: str
    decimate: int = 1
    line: int = 0
    file: str | None = None

    @property
    def signal(self) -> str:
        return f"{self.block}.{self.port}"


@dataclass(frozen=True)
class DiagramPort:
    """An input or output of a diagram as a whole (or of a subsystem): the inner ports it
    stands for (an input may feed several inputs; an output is one output), with their
    width and, where their blocks know them, units and element names."""

    name: str
    signals: tuple[str, ...]
    """Inner ports by their path name (``ctrl.integ.u``)."""
    width: int
    units: str | list[str] | None = None
    labels: tuple[str, ...] | None = None
    line: int | None = None
    file: str | None = None


@dataclass(frozen=True)
class DeclaredReference:
    """A block reference a diagram leaves to the diagram that includes it (``references:``),
    and, when it is loaded on its own, the type of the block that stands in for it."""

    name: str
    type_name: str | None = None
    line: int | None = None


@dataclass
class Composite:
    """One diagram file's level of a diagram: the top diagram or one of its subsystems.

    It keeps what the file wrote, with every name as its path in the whole diagram: the
    blocks written in it, its subsystems, its own wires (``wires``: endpoints may be a
    subsystem's ports, ``ctrl.e``), its ports and its block references. ``validate`` and
    ``graph`` show the diagram by it; the planner and executor use the flat blocks only."""

    path: str
    """``""`` for the top diagram, else the subsystem's path (``ctrl``, ``ctrl.inner``)."""
    diagram_name: str
    file: str | None
    """The YAML file it was read from; None for a level built in Python."""
    line: int | None = None
    """Where the including diagram names the subsystem (None for the top)."""
    including_file: str | None = None
    source: str | None = None
    """The diagram file as the including entry names it (``diagram: pi.yaml``)."""
    blocks: tuple[str, ...] = ()
    subsystems: tuple[str, ...] = ()
    wires: tuple[Connection, ...] = ()
    log: tuple[LogEntry, ...] = ()
    """The signals it asks to log (those of its subsystems by path: ``ctrl.integ.y``)."""
    inputs: dict[str, DiagramPort] = field(default_factory=dict)
    outputs: dict[str, DiagramPort] = field(default_factory=dict)
    references: dict[str, DeclaredReference] = field(default_factory=dict)
    """The block references it leaves to its includer (``references:``)."""
    bindings: dict[str, str] = field(default_factory=dict)
    """For a subsystem: each of its references -> the block it is bound to, by path."""
    bind: dict[str, str] = field(default_factory=dict)
    """For a subsystem: its entry's ``bind`` as written (names in the including level)."""
    params: dict[str, Any] = field(default_factory=dict)
    """For a subsystem: the overrides it was given, by dotted path inside it (``prop.k``),
    from its entry's ``params`` and from ``--set``."""

    @property
    def origin(self) -> str:
        """Where it comes from, for people: its file as the including entry names it, its
        file, or ``built in Python``."""
        return self.source or self.file or "built in Python"

    def name_of(self, path: str) -> str:
        """``path`` (a block or subsystem inside this level) as this level's file names it."""
        return path[len(self.path) + 1:] if self.path else path


@dataclass(frozen=True)
class Conversion:
    """A connection between ports of different value types and the rule that converts it."""

    connection: Connection
    source_type: str
    target_type: str
    rule: str

    def __str__(self) -> str:
        c = self.connection
        return f"{c.src} ({self.source_type}) -> {c.dst} ({self.target_type}): {self.rule}"


@dataclass
class Diagram:
    """A validated diagram: blocks, connections, logged signals and the end time.

    Flat: a subsystem's blocks are among ``blocks`` under their path names
    (``ctrl.integ``), its wires among ``connections`` from output to input, so planning
    and running see no subsystems. ``root`` and ``subsystems`` keep how the files were
    composed; ``inputs`` and ``outputs`` are the diagram's own ports."""

    name: str
    description: str
    file: str
    blocks: dict[str, BlockSpec]
    connections: list[Connection]
    log: list[LogEntry]
    t_end: Fraction | None
    source_hash: str
    t_end_line: int | None = None
    base_dir: Path = field(default_factory=Path.cwd)
    files: dict[str, Path] = field(default_factory=dict)
    """Every file the diagram read, by the reference it makes: its blocks' params files and
    the files their path parameters name (an FMU's ``path``), as written relative to the
    diagram's folder (``../fmu/X.fmu``) or absolute, the ``python:`` modules it imported
    from its folder (``mymod.py``) and the diagram files of its subsystems (``pi.yaml``);
    a subsystem's own files by their reference from the top diagram's folder
    (``sub/gains.yaml``). Each maps to the path it was read from. What a copy of the
    diagram needs elsewhere (``blocks.sweep.bundle``)."""
    root: Composite | None = None
    """The top level as its file wrote it (None: a Diagram made without the builder)."""
    subsystems: dict[str, Composite] = field(default_factory=dict)
    """Every subsystem, nested ones too, by path, in the order they are written."""

    def __repr__(self) -> str:
        """'<Diagram 'toy-multirate' (diagrams/toy.yaml): 6 blocks, 7 connections, logs plant.y; t_end 1 s>'."""
        from blocks.timebase import format_duration

        n = len(self.subsystems)
        subs = f" ({n} subsystem{'s' if n != 1 else ''})" if n else ""
        logged = [e.signal for e in self.log]
        logs = ", ".join(logged) if len(logged) <= 3 else f"{len(logged)} signals"
        t_end = f"; t_end {format_duration(self.t_end)}" if self.t_end is not None else ""
        return (f"<Diagram {self.name!r} ({self.file}): {len(self.blocks)} blocks{subs}, "
                f"{len(self.connections)} connections, logs {logs or 'nothing'}{t_end}>")

    @property
    def inputs(self) -> dict[str, DiagramPort]:
        """The diagram's own inputs (``inputs:``): a diagram meant to be a subsystem."""
        return self.root.inputs if self.root else {}

    @property
    def outputs(self) -> dict[str, DiagramPort]:
        """The diagram's own outputs (``outputs:``)."""
        return self.root.outputs if self.root else {}

    def issue(self, line: int | None, message: str, hint: str = "") -> Issue:
        return Issue(self.file, line, message, hint)

    def issue_at(self, item: BlockSpec | Connection | LogEntry, message: str, hint: str = "") -> Issue:
        """An issue at ``item``'s line, in the file it is written in."""
        return Issue(item.file or self.file, item.line, message, hint)

    def open_issue(self) -> Issue | None:
        """Why the diagram cannot run on its own, or None: it has inputs, or block
        references that an including diagram binds. Such a diagram loads and validates
        (a stand-in takes a reference's place), but runs only as a subsystem."""
        root = self.root
        if root is None or not (root.inputs or root.references):
            return None
        parts = []
        if root.inputs:
            parts.append(f"inputs ({', '.join(root.inputs)})")
        if root.references:
            parts.append(f"block references ({', '.join(root.references)})")
        use = f"ctrl: {{diagram: {Path(root.file).name}}}" if root.file else "DiagramBuilder.add_subsystem"
        return self.issue(None, f"diagram '{self.name}' has {' and '.join(parts)} that an including "
                          "diagram gives it: it runs only as a subsystem",
                          f"use it as a block of another diagram ({use}) and connect its inputs there")

    def decimated(self, factor: int) -> "Diagram":
        """This diagram logging every ``factor``-th sample of what it logs (each log entry's
        own ``decimate`` times ``factor``): ``run --decimate``. ValueError unless ``factor``
        is a positive whole number."""
        if isinstance(factor, bool) or not isinstance(factor, int) or factor < 1:
            raise ValueError(f"decimation must be a positive whole number, got {factor!r}")
        if any(e.decimate * factor > MAX_DECIMATE for e in self.log):
            raise ValueError(f"decimation {factor} makes a log entry's decimate more than {MAX_DECIMATE}")
        return dataclasses.replace(self, log=[dataclasses.replace(e, decimate=e.decimate * factor) for e in self.log])

    def drivers_of(self, block: str, port: str) -> list[Connection]:
        """The connections feeding input ``block.port``: one, or several that each drive some
        of its elements; none for an unconnected input."""
        return [c for c in self.connections if c.dst_block == block and c.dst_port == port]

    def width(self, signal: str) -> int:
        """Width of an output signal ``block.port`` (the block may be a path, ``ctrl.u``)."""
        block, port = signal.rsplit(".", 1)
        return self.blocks[block].block.outputs[port]

    def element_labels(self, block: str, port: str) -> list[str] | None:
        """The names of the elements of port ``block.port``, the diagram's or its block's
        (None: numbered from 0)."""
        return self.blocks[block].element_labels(port)

    def port_units(self, block: str, port: str) -> str | list[str] | None:
        """The unit(s) of port ``block.port``, the diagram's or its block's (None: unknown)."""
        return self.blocks[block].port_units(port)

    def split_key(self, key: str) -> tuple[str, str] | None:
        """``ctrl.prop.k.0`` -> (``ctrl.prop``, ``k.0``): the block a ``block.param`` key
        names and the path into its parameters; None when no block of it is named."""
        parts = key.split(".")
        for n in range(len(parts) - 1, 0, -1):
            block = ".".join(parts[:n])
            if block in self.blocks:
                return block, ".".join(parts[n:])
        return None

    def references(self) -> list[Reference]:
        """Every block reference of the diagram (``reflex.hand -> plant``), in block order."""
        return [Reference(name, param, target) for name, spec in self.blocks.items()
                for param, target in spec.references.items()]

    def conversions(self) -> list[Conversion]:
        """The connections between ports of different value types (an FMU's Int32 output
        into a plain input, a plain output into an FMU's Boolean input), with the rules
        that convert them, in connection order."""
        out = []
        for c in self.connections:
            src, dst = self.blocks[c.src_block].block, self.blocks[c.dst_block].block
            a, b = src.port_type(c.src_port), dst.port_type(c.dst_port)
            if a != b:
                rule = dst.input_rule(c.dst_port) or src.output_rule(c.src_port) or "exact"
                out.append(Conversion(c, a, b, rule))
        return out

    def parameters(self) -> dict[str, dict]:
        """Parameters of every block after params files and overrides (JSON-friendly)."""
        return {name: jsonable(spec.params) for name, spec in self.blocks.items()}

    def composition(self) -> dict[str, dict]:
        """Each subsystem's file and the overrides it was given (for run.json)."""
        return {path: {"diagram": sub.origin, "name": sub.diagram_name,
                       **({"params": jsonable(sub.params)} if sub.params else {}),
                       **({"bind": dict(sub.bindings)} if sub.bindings else {})}
                for path, sub in self.subsystems.items()}


def jsonable(value: Any) -> Any:
    """``value`` with every mapping, sequence and array turned into JSON types (other
    objects as their text): parameters as run.json records them and the loader hashes them."""
    kind = type(value)
    if kind is float or kind is int or kind is str or kind is bool or value is None:
        return value  # the common leaves first: every run records its parameters
    if kind is dict:
        return {str(k): jsonable(v) for k, v in value.items()}
    if kind is list:
        return [jsonable(v) for v in value]
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (bool, int, float, str)) or value is None:
        return value
    return str(value)
