"""A validated diagram as plain data: blocks, connections, logged signals, end time.

The loader (``blocks.loader``) makes a ``Diagram`` from a YAML file; the planner
(``blocks.schedule``) and the executor (``blocks.simulate``) read it. A Diagram is not
changed after loading and holds nothing derived from it (the plans the planner builds
are kept by the planner), so one Diagram can be planned and run any number of times.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from .block import Block
from .issues import Issue
from .references import Reference


@dataclass
class BlockSpec:
    """A block of the diagram: its name, configured block object, period and offset."""

    name: str
    type_name: str
    block: Block
    period: Fraction | None
    offset: Fraction
    params: dict
    line: int
    params_file: str | None = None
    """The block's params_file (resolved against the diagram's folder), if it has one."""

    @property
    def references(self) -> dict[str, str]:
        """This block's block references: parameter -> name of the block it refers to."""
        return {p: self.params[p] for p in type(self.block).block_params if p in self.params}


@dataclass(frozen=True)
class Connection:
    """A wire from an output port to an input port, optionally delayed by one sample."""

    src_block: str
    src_port: str
    dst_block: str
    dst_port: str
    delay: int = 0
    initial: tuple[float, ...] | None = None
    line: int = 0

    @property
    def src(self) -> str:
        return f"{self.src_block}.{self.src_port}"

    @property
    def dst(self) -> str:
        return f"{self.dst_block}.{self.dst_port}"

    def __str__(self) -> str:
        return f"{self.src} -> {self.dst}" + (" (delay 1)" if self.delay else "")


@dataclass(frozen=True)
class LogEntry:
    """A signal to record: ``block.port`` at every ``decimate``-th sample hit."""

    block: str
    port: str
    decimate: int = 1
    line: int = 0

    @property
    def signal(self) -> str:
        return f"{self.block}.{self.port}"


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
    """A validated diagram: blocks, connections, logged signals and the end time."""

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
    diagram's folder (``../fmu/X.fmu``) or absolute, and the ``python:`` modules it imported
    from its folder (``mymod.py``); each maps to the path it was read from. What a copy of
    the diagram needs elsewhere (``blocks.sweep.bundle``)."""

    def issue(self, line: int | None, message: str, hint: str = "") -> Issue:
        return Issue(self.file, line, message, hint)

    def driver_of(self, block: str, port: str) -> Connection | None:
        """The connection feeding input ``block.port``, if any."""
        for c in self.connections:
            if c.dst_block == block and c.dst_port == port:
                return c
        return None

    def width(self, signal: str) -> int:
        """Width of an output signal ``block.port``."""
        block, port = signal.split(".")
        return self.blocks[block].block.outputs[port]

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


def jsonable(value: Any) -> Any:
    """``value`` with every mapping, sequence and array turned into JSON types (other
    objects as their text): parameters as run.json records them and the loader hashes them."""
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (bool, int, float, str)) or value is None:
        return value
    return str(value)
