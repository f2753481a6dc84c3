"""One run of an op table: its memory, its blocks' states, and their bound kernels.

The arena (``OpTable.initial`` copied), the log buffers and their counters, the blocks'
states and the input mappings a Python block is called with belong to one run; so does
the choice of kernels (``blocks.engine.compiled.usable_kernel``). A kernel with a ``bind`` is
bound to its block's state once per run, here, after every other check has chosen it;
the bound kernel gets that state when it is a flat float64 array (the plant's, whose
bound context is the run's scratch) and NULL otherwise (an FMU's). What ``kernel()`` or
``bind`` raises is the block's failure at t = 0 ('kernel').
"""

from __future__ import annotations

from typing import Any

import numpy as np

from blocks.engine import compiled
from blocks.engine.finite import nonfinite_error
from blocks.engine.kernel import Kernel, address
from blocks.engine.optable import L_CAPACITY, L_WIDTH, LC_ROWS, OpTable

KERNEL_COLUMNS = ("output", "update", "advance", "context", "state", "nogil")
"""A run's kernel rows, one per block (all zero for a Python block), as the host reads them."""

STATE_OF_LIST = -1
"""A kernel row's state: the block's entry of the run's states list (native_run.h's
RUN_STATE_OF_LIST), whose data the host binds."""


class Binding:
    """What one run of ``table`` owns: states, input mappings, kernels, arena and logs."""

    def __init__(self, diagram: Any, table: OpTable, check_finite: bool = True):
        self.diagram, self.table = diagram, table
        self.check_finite = check_finite
        """Whether an output value that is not finite fails the run (``blocks.engine.finite``)."""
        names = table.names
        specs = [diagram.blocks[n].block for n in names.blocks]
        self.blocks = specs
        self.states: list[Any] = [blk.initial_state() for blk in specs]
        self.arena = table.initial.copy()
        self.inputs: list[dict[str, np.ndarray]] = []
        first = 0
        rows = table.inputs.tolist()
        for blk, ports, feeds in zip(specs, names.inputs, names.feeds):
            mapping = {}
            for j, (port, feed) in enumerate(zip(ports, feeds)):
                offset, width = rows[first + j]
                if port in blk.input_defaults and feed in ("unconnected", "default until fired"):
                    mapping[port] = np.array(blk.input_defaults[port], dtype=float)
                else:
                    mapping[port] = self.arena[offset:offset + width].copy()
            self.inputs.append(mapping)
            first += len(ports)
        self.logs = [np.empty((int(row[L_CAPACITY]), int(row[L_WIDTH]))) for row in table.logs]
        self.counters = np.zeros((len(table.logs), 2), dtype=np.int64)
        self.kernels: list[Kernel | None] = [None] * len(specs)
        self.failure: tuple[str, BaseException] | None = None
        """A block whose ``kernel()`` or kernel ``bind`` raised, and what."""
        if compiled.native() is not None:
            self.choose_kernels()

    def choose_kernels(self) -> None:
        updated, advanced = self.table.roles
        for b, (name, blk) in enumerate(zip(self.table.names.blocks, self.blocks)):
            state = self.states[b]
            try:
                kernel = compiled.usable_kernel(blk, self.inputs[b], state, b in updated, b in advanced)
                if kernel is not None and kernel.bind is not None:
                    kernel = kernel.bind(state)
            except Exception as exc:
                self.failure = (name, exc)
                self.kernels = [None] * len(self.blocks)
                return
            self.kernels[b] = kernel

    def state_address(self, b: int) -> int:
        """Where a compiled block's kernel finds its state (0: none, or not a flat array)."""
        state = self.states[b]
        return address(state) if state is not None and compiled.flat(state) else 0

    def kernel_rows(self) -> np.ndarray:
        """The kernel rows (``KERNEL_COLUMNS``) the C host binds; a flat state is named by
        ``STATE_OF_LIST``, its array's data found by the host in the states list."""
        rows = [[0] * len(KERNEL_COLUMNS) if k is None else
                [k.output, k.update, k.advance, k.context, self._state_column(b), int(k.nogil)]
                for b, k in enumerate(self.kernels)]
        return np.array(rows, dtype=np.int64).reshape(len(self.blocks), len(KERNEL_COLUMNS))

    def _state_column(self, b: int) -> int:
        state = self.states[b]
        return STATE_OF_LIST if state is not None and compiled.flat(state) else 0

    def kernel_error(self, b: int, code: int, which: int, tick: int, phase: str) -> BaseException:
        """The exception of block ``b``'s kernel failure ``code``, from its error factory
        (the block's ``EndRun`` for ``END_RUN`` from an update)."""
        kernel = self.kernels[b]
        return (kernel.error or compiled.failure)(code, which, self.table.time(tick), phase)

    def nonfinite_error(self, b: int, which: int) -> BaseException:
        """The error of block ``b``'s output value ``which`` that is not finite (``NONFINITE``)."""
        name = self.table.names.blocks[b]
        return nonfinite_error(self.table, self.arena, lambda port: self.diagram.element_labels(name, port), b, which)

    def rows_logged(self, entry: int) -> np.ndarray:
        """The rows log entry ``entry`` (a row of the logs table) holds."""
        return self.logs[entry][:int(self.counters[entry, LC_ROWS])]
