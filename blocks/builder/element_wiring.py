"""Connections that name elements (``c.y[1] -> g.u``, ``a.y -> g.u[0]``): their elements
resolved once the widths are known, and the inputs they assemble checked.

A selection is read with the grammar of ``blocks.builder.elements`` against its port's width
and element names (the block's, or the diagram's own: ``blocks.port_info``). The
elements an input's connections drive must not overlap and, unless the input has a
default (one value, or one per element) that holds the rest, must cover it; each problem is one line at the connection
(or the block) it is written at.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable, Sequence

import numpy as np

from blocks.builder.diagram import BlockSpec, Connection
from blocks.builder.elements import ElementError, contiguous, pick

LabelsOf = Callable[[str, str], "Sequence[str] | None"]
"""The element names of ``(block, port)``, or None when they are numbered from 0."""


def resolve(c: Connection, written: Connection, specs: dict[str, BlockSpec], labels_of: LabelsOf) -> Connection:
    """``c`` with the 0-based elements its selections stand for; ElementError naming the
    end as written (``written``: the wire in its file) when one names no element."""
    src_elements = dst_elements = None
    if c.src_select is not None:
        width = specs[c.src_block].block.outputs[c.src_port]
        src_elements = tuple(pick(c.src_select, labels_of(c.src_block, c.src_port), width, f"output {written.src}"))
    if c.dst_select is not None:
        width = specs[c.dst_block].block.inputs[c.dst_port]
        dst_elements = tuple(pick(c.dst_select, labels_of(c.dst_block, c.dst_port), width, f"input {written.dst}"))
    return replace(c, src_elements=src_elements, dst_elements=dst_elements)


def carried(c: Connection, specs: dict[str, BlockSpec]) -> int | None:
    """How many values ``c`` carries: its source selection's, else its source port's width."""
    return len(c.src_elements) if c.src_elements is not None else specs[c.src_block].block.outputs[c.src_port]


def received(c: Connection, specs: dict[str, BlockSpec]) -> int | None:
    """How many values ``c``'s destination takes: its selection's, else its port's width."""
    return len(c.dst_elements) if c.dst_elements is not None else specs[c.dst_block].block.inputs[c.dst_port]


def elements_text(indices: Sequence[int]) -> str:
    """``2, 3`` or ``element 2``."""
    return ("element " if len(indices) == 1 else "elements ") + ", ".join(str(j) for j in indices)


def check_assembled(connections: Sequence[Connection], written: dict[int, Connection],
                    specs: dict[str, BlockSpec], report: Callable[[str | None, int | None, str, str], None]) -> None:
    """Report, by ``report(file, line, message, hint)``, elements of an input driven twice
    and inputs whose connections name elements and leave some of them without a value."""
    into: dict[tuple[str, str], list[Connection]] = {}
    for c in connections:
        into.setdefault((c.dst_block, c.dst_port), []).append(c)
    for (name, port), feeding in into.items():
        if all(c.dst_elements is None for c in feeding):
            continue  # one whole connection (two are reported where they are written)
        spec = specs[name]
        width = spec.block.inputs[port]
        by: dict[int, Connection] = {}
        for c in feeding:
            wire = written.get(id(c), c)
            targets = c.dst_elements if c.dst_elements is not None else tuple(range(width))
            twice = sorted({j for j in targets if j in by})
            if twice:
                first = written.get(id(by[twice[0]]), by[twice[0]])
                report(c.file, c.line, f"{elements_text(twice)} of input {wire.dst} driven twice: by "
                       f"{wire.src_text} and by {first.src_text} (line {first.line})",
                       "each element of an input takes one connection")
            for j in targets:
                by.setdefault(j, c)
        missing = [j for j in range(width) if j not in by]
        default = spec.block.input_defaults.get(port)
        if missing and (default is None or np.size(default) not in (1, width)):
            given = "; ".join(f"{written.get(id(c), c)} (line {c.line})" for c in feeding)
            local = name.rpartition(".")[2]
            hint = (f"connect them, e.g. '- <block>.<port> -> {local}.{port}[{missing[0]}:{missing[-1] + 1}]'"
                    if contiguous(missing) else f"connect each, e.g. '- <block>.<port> -> {local}.{port}[{missing[0]}]'")
            report(spec.file, spec.line, f"input {name}.{port} of block '{name}' ({spec.type_name}): "
                   f"{elements_text(missing)} of {width} not connected (the others by {given})", hint)

