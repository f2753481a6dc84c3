"""No silent NaN: a run stops at the first output value that is not finite.

Both interpreters check what every output op and every advance computes (the C core in
``core.c``, the reference loop with ``nonfinite_output``): a NaN or an infinity fails
the op, code ``NONFINITE``, with the value's index among its block's outputs. Here that
index becomes the error the run's status names: the block's port, the element (by the
label the diagram or the block gives it), the value. The rows logged before it are kept;
the value itself is not logged. ``simulate(..., check_finite=False)`` (``hierhand run
--allow-nonfinite``) lets such values through.
"""

from __future__ import annotations

import numpy as np

from blocks.block import BlockError
from blocks.engine.optable import B_FIRST_PORT, B_OUT, B_WIDTH, P_OFFSET, P_WIDTH, OpTable

NONFINITE = -3
"""``BLK_NONFINITE`` (core.h): an op whose outputs hold a value that is not finite."""

HINT = "a run stops at the first NaN or infinity a block outputs; check_finite=False (--allow-nonfinite) lets it go on"


class NonFiniteOutput(BlockError):
    """An output value that is not finite: its ``port``, ``element`` (0-based), the element's
    ``label`` and the ``value``."""

    def __init__(self, port: str, element: int, label: str, value: float):
        where = f"{port}[{label}]" + ("" if label == str(element) else f" (element {element})")
        super().__init__(f"{where} = {value!r} is not finite (hint: {HINT})", port=port)
        self.element = element
        self.label = label
        self.value = value


def first_nonfinite(values: np.ndarray) -> int:
    """The index of the first value that is not finite, or -1."""
    bad = np.flatnonzero(~np.isfinite(values))
    return int(bad[0]) if bad.size else -1


def nonfinite_output(table: OpTable, arena: np.ndarray, b: int, selection: int) -> int:
    """The index among block ``b``'s outputs of the first value its output op computed (the
    ports of ``selection``; -1: all) that is not finite, or -1: core.c's check."""
    block = table.blocks[b]
    out = int(block[B_OUT])
    if selection < 0:
        return first_nonfinite(arena[out:out + int(block[B_WIDTH])])
    for j in table.selection(selection):
        port = table.ports[int(block[B_FIRST_PORT]) + j]
        at, width = int(port[P_OFFSET]), int(port[P_WIDTH])
        found = first_nonfinite(arena[at:at + width])
        if found >= 0:
            return at - out + found
    return -1


def nonfinite_error(table: OpTable, arena: np.ndarray, labels_of, b: int, which: int) -> NonFiniteOutput:
    """The error of block ``b``'s output value ``which`` (its index among the block's
    outputs, whose place in the arena holds it): its port, element and label
    (``labels_of(port)``: the element names, or None to number them)."""
    block = table.blocks[b]
    at = int(block[B_OUT]) + which
    for j, name in enumerate(table.names.ports[b]):
        port = table.ports[int(block[B_FIRST_PORT]) + j]
        element = at - int(port[P_OFFSET])
        if 0 <= element < int(port[P_WIDTH]):
            labels = labels_of(name)
            label = str(labels[element]) if labels is not None else str(element)
            return NonFiniteOutput(name, element, label, float(arena[at]))
    raise ValueError(f"block {table.names.blocks[b]!r} has no output value {which}")
