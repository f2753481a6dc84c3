"""Blocks without a kernel as ops of the table: their Python methods, called over the arena.

A Python block reads its inputs from a mapping of arrays and returns arrays; the table
keeps every value in the run's arena. Between the two, for every call:

- **inputs**: before a call, each connected input whose values in the arena have changed
  since the block last saw them gets a new array with them (one nobody else holds may be
  overwritten in place instead); an input that has not changed keeps its array, and an
  unconnected one keeps its default. A block may therefore keep what it is given.
- **outputs**: the ports a step stands for must be float64 arrays of their declared
  width, checked at every call; their values are copied into the arena.
- **advance**: ``n`` hits return ``(state, rows)``; the rows are checked and copied into
  the block's rows in the arena. A failing advance may hand back the rows it completed
  (``BlockError.rows``), which are logged like a kernel's.
- **update**: the new state, or an ``EndRun`` (with its state, if it gives one).

This module is the readable statement of those rules, which the reference loop runs as
they stand; the C Run (``blocks/csrc/native_python_blocks.c``) does outputs, updates and inputs itself,
for speed, and comes here for advances and for the messages of outputs that fail the
check.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from blocks.engine.binding import Binding
from blocks.block import BlockError, EndRun
from blocks.engine.optable import B_ROWS, B_WIDTH, I_OFFSET, I_WIDTH, P_OFFSET, P_WIDTH


class PythonSide:
    """The Python blocks of one run (``Binding.kernels[b] is None``)."""

    empty = staticmethod(np.empty)
    ndarray = np.ndarray
    end_run = EndRun
    """What the C host creates input arrays with, checks outputs against, and catches."""

    def __init__(self, binding: Binding):
        self.binding = binding
        table = binding.table
        self.table = table
        names = table.names
        self.outputs: dict[int, list[tuple[str, int, int]]] = {}
        """Per Python block, its output ports: (name, arena offset, width)."""
        self.inputs: dict[int, list[tuple[str, int, int]]] = {}
        """Per Python block, its connected input ports: (name, arena offset, width)."""
        ports, inputs = table.ports.tolist(), table.inputs.tolist()
        for b, kernel in enumerate(binding.kernels):
            if kernel is not None:
                continue
            _, _, first_input, n_inputs, _, _, _, first_port, n_ports = table.blocks[b].tolist()
            self.outputs[b] = [(p, row[P_OFFSET], row[P_WIDTH])
                               for p, row in zip(names.ports[b], ports[first_port:first_port + n_ports])]
            self.inputs[b] = [(p, row[I_OFFSET], row[I_WIDTH])
                              for p, feed, row in zip(names.inputs[b], names.feeds[b],
                                                      inputs[first_input:first_input + n_inputs])
                              if feed != "unconnected"]
        self.seen = {b: [binding.arena[o:o + w].copy() for _, o, w in ins] for b, ins in self.inputs.items()}
        """What each connected input's values were when its block last saw them."""

    def ports_of(self, b: int, selection: int) -> list[tuple[str, int, int]]:
        """The ports an output op stands for (its selection; -1: all)."""
        ports = self.outputs[b]
        return ports if selection < 0 else [ports[j] for j in self.table.selection(selection)]

    # -- the rules -------------------------------------------------------------------

    def refresh(self, b: int) -> None:
        """New arrays for the inputs of block ``b`` whose values have changed."""
        arena, mapping = self.binding.arena, self.binding.inputs[b]
        for (port, offset, width), seen in zip(self.inputs[b], self.seen[b]):
            now = arena[offset:offset + width]
            if now.tobytes() != seen.tobytes():
                seen[:] = now
                mapping[port] = now.copy()

    def output(self, b: int, selection: int, t: float) -> None:
        """Block ``b``'s outputs at ``t``: the ports of ``selection`` into the arena."""
        binding = self.binding
        self.refresh(b)
        out = binding.blocks[b].output(t, binding.states[b], binding.inputs[b])
        values, at = self.outputs_checked(b, out, selection), 0
        for _, offset, width in self.ports_of(b, selection):
            binding.arena[offset:offset + width] = values[at:at + width]
            at += width

    def outputs_checked(self, b: int, out: Any, selection: int) -> np.ndarray:
        """The values of the ports of ``selection`` in ``out`` (what ``output`` returned), one
        after the other; a BlockError naming the port if one is not a float64 array of
        its width."""
        if not isinstance(out, dict):
            raise BlockError(f"output() returned {type(out).__name__}, expected a dict of port arrays")
        values = []
        for port, _, width in self.ports_of(b, selection):
            v = out.get(port)
            if not (isinstance(v, np.ndarray) and v.shape == (width,) and v.dtype == np.float64):
                got = f"shape {v.shape} {v.dtype}" if isinstance(v, np.ndarray) else repr(type(v).__name__)
                raise BlockError(f"output '{port}' must be a float64 array of shape ({width},), got {got}", port=port)
            values.append(v)
        return np.concatenate(values) if values else np.zeros(0)

    def update(self, b: int, t: float) -> EndRun | None:
        """Block ``b``'s update at ``t``; its EndRun if it asked to end the run."""
        binding = self.binding
        self.refresh(b)
        try:
            binding.states[b] = binding.blocks[b].update(t, binding.states[b], binding.inputs[b])
        except EndRun as end:
            if end.has_state:
                binding.states[b] = end.state
            return end
        return None

    def advance(self, b: int, t: float, n: int) -> tuple[int, BaseException | None]:
        """``n`` hits of block ``b`` from ``t`` into its rows: (n, None), or the rows
        completed and the exception when it raised (the caller has refreshed the inputs)."""
        binding = self.binding
        try:
            state, rows = binding.blocks[b].advance(t, binding.states[b], binding.inputs[b], n)
            self.write_rows(b, rows, n)
        except BaseException as exc:  # an interrupt too: the host tells them apart
            return self.partial_rows(b, exc, n), exc
        binding.states[b] = state
        return n, None

    def write_rows(self, b: int, rows: Any, n: int) -> None:
        block = self.table.blocks[b]
        width, at = int(block[B_WIDTH]), int(block[B_ROWS])
        view = self.binding.arena[at:at + n * width].reshape(n, width)
        column = 0
        for port, _, w in self.outputs[b]:
            v = rows.get(port) if isinstance(rows, dict) else None
            if not (isinstance(v, np.ndarray) and v.shape == (n, w)):
                raise BlockError(f"advance() output '{port}' must have shape ({n}, {w})", port=port)
            view[:, column:column + w] = v
            column += w

    def partial_rows(self, b: int, exc: BaseException, n: int) -> int:
        """The rows a failing advance of ``n`` hits completed (``BlockError.rows``), written;
        how many."""
        rows = exc.rows if isinstance(exc, BlockError) else None
        ports = self.outputs[b]
        if not isinstance(rows, dict) or not ports or not isinstance(rows.get(ports[0][0]), np.ndarray):
            return 0
        m = rows[ports[0][0]].shape[0] if rows[ports[0][0]].ndim else n + 1
        if m > n:
            return 0
        try:
            self.write_rows(b, rows, m)
        except (BlockError, ValueError):
            return 0
        return m

    def kernel_end(self, b: int, which: int, tick: int) -> BaseException:
        """What a compiled update's request to end the run stands for: the block's EndRun
        (or another exception, which fails the update)."""
        from blocks.engine.kernel import END_RUN

        return self.binding.kernel_error(b, END_RUN, which, tick, "update")
