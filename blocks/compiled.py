"""The compiled side of a run: blocks with kernels, their buffers, and C runners of their steps.

A block whose ``kernel()`` offers every function the schedule needs of it runs all its
hits in C (``blocks._native.Runner``, see ``blocks/csrc/runner.c``). Each such block
writes its outputs into one buffer of its own; a kernel reads its inputs through
pointers into the buffers of the blocks that feed it, so values pass on with no copy.
Where the two worlds meet, values are copied: a Python block's output into the input
buffer of a compiled reader when it is computed, a compiled block's outputs into its
Python readers' inputs after each C call that computed them (copies, because the buffer
changes in place and a Python block may keep what it was given). An input with a default
has a buffer of its own too, which holds the default until its source first fires.
Loggers of compiled blocks are filled in C. A C call releases the GIL over the steps of
kernels that say they need none (``Kernel.nogil``), so runs in other threads go on meanwhile.

A kernel with a ``bind`` is bound to its block's state once per run, here, after every
other check has chosen it; the bound kernel gets that state when it is a flat float64
array (the plant's, whose bound context is the run's scratch) and NULL otherwise (an FMU's). An update that returns ``END_RUN`` is handed to the
executor's ``end`` while the C call goes on; a kernel's ``RAISED`` exception comes back
in the failure.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from .block import BlockError
from .kernel import END_RUN, RAISED, Kernel, address

try:
    from ._native import Runner as NativeRunner
except ImportError:  # an uncompiled checkout: every block runs in Python
    NativeRunner = None

OP_OUTPUT, OP_UPDATE, OP_ADVANCE, OP_COPY = 0, 1, 2, 3
"""Op codes of ``runner.c``; an op is a row ``[code, slot, a, b]`` (copy: ``[code, width,
destination, source]``)."""

EXACT_TICKS = 2**53
"""Tick times are exact in C while ``tick * numerator`` stays below this."""


def failure(code: int, which: int, t: float, phase: str) -> BaseException:
    """The exception of a failure code whose block names no ``Kernel.error``."""
    return BlockError(f"compiled {phase} failed at t={t:.10g} s with code {code} (detail {which})")


def flat(state: Any) -> bool:
    """A state a kernel updates in place: a flat, C-contiguous, writable float64 array."""
    return (isinstance(state, np.ndarray) and state.dtype == np.float64 and state.ndim == 1
            and state.flags.c_contiguous and state.flags.writeable)


class CompiledBlock:
    """One block run through its kernel: its output buffer, input pointers and state."""

    def __init__(self, name: str, block: Any, kernel: Kernel, state: np.ndarray | None, slot: int):
        self.name, self.block, self.kernel, self.state, self.slot = name, block, kernel, state, slot
        self.offsets: dict[str, int] = {}
        width = 0
        for port, w in block.outputs.items():
            self.offsets[port] = width
            width += w
        self.width = width
        self.out = np.zeros(width)
        self.views = {p: self.out[o:o + block.outputs[p]] for p, o in self.offsets.items()}
        self.pointers = np.zeros(max(len(block.inputs), 1), dtype=np.int64)
        self.rows: np.ndarray | None = None
        self.logs = (0, 0)
        """The range of this block's entries in the run's log table."""
        self.forwards: list[tuple[list[int], tuple[str, str]]] = []
        """Copies of its outputs into readers' buffers after each of its hits, with their
        steps: inputs that hold a default until this block first fires."""


class CompiledSide:
    """The blocks of a run that have kernels, and what their C steps need."""

    def __init__(self, diagram, schedule, states: list, index: dict[str, int], inputs: dict,
                 loggers: dict[str, list], chunk: int):
        self.d, self.s = diagram, schedule
        self.blocks: dict[str, CompiledBlock] = {}
        self.owners: list[Any] = []
        self.logged: list = []
        self.failure: tuple[str, BaseException] | None = None
        """A block whose ``kernel()`` or kernel ``bind`` raised, and what: the run reports it
        as that block's failure."""
        if NativeRunner is None or not self.exact_ticks():
            return
        updated = {b for p in (*schedule.programs, schedule.initial) for b in p.update}
        for name, spec in diagram.blocks.items():
            state = states[index[name]]
            try:
                kernel = self.usable_kernel(spec.block, inputs[name], state, name in updated,
                                            name in schedule.advanced)
                if kernel is not None and kernel.bind is not None:
                    kernel, state = kernel.bind(state), (state if flat(state) else None)
            except Exception as exc:
                self.failure = (name, exc)
                self.blocks.clear()
                return
            if kernel is not None:
                self.blocks[name] = CompiledBlock(name, spec.block, kernel, state, len(self.blocks))
        if not self.blocks:
            return
        self.inputs = inputs
        self.buffers: dict[tuple[str, str], np.ndarray] = {}
        """Input buffers of compiled blocks fed by Python blocks or delayed connections."""
        self.wire(chunk)
        self.build_logs(loggers)
        self.slots = np.array([[cb.kernel.output, cb.kernel.update, cb.kernel.advance, cb.kernel.context,
                                0 if cb.state is None else address(cb.state), address(cb.pointers),
                                address(cb.out), cb.width, 0 if cb.rows is None else address(cb.rows),
                                0 if cb.rows is None else cb.rows.shape[0],
                                schedule.period_ticks[cb.name] or 0, int(cb.kernel.nogil)]
                               for cb in self.blocks.values()],
                              dtype=np.int64)

    @staticmethod
    def usable_kernel(block: Any, inputs: dict, state: Any, updated: bool, advanced: bool) -> Kernel | None:
        """The block's kernel if it offers every function the schedule needs of it and its
        inputs and state are what the kernel reads; else None (the block runs in Python)."""
        kernel = block.kernel()
        if not isinstance(kernel, Kernel) or not kernel.output:
            return None
        if any(not (isinstance(v := inputs[p], np.ndarray) and v.shape == (w,) and v.dtype == np.float64)
               for p, w in block.inputs.items()):
            return None  # an input default of another width: the Python methods meet it as they would
        if state is not None and ((kernel.bind is None and not flat(state)) or (updated and not kernel.update)):
            return None
        if advanced and not kernel.advance:
            return None
        return kernel

    def exact_ticks(self) -> bool:
        tick = self.s.base_tick
        return (self.s.n_ticks + self.s.hyperperiod) * tick.numerator < EXACT_TICKS and tick.denominator < EXACT_TICKS

    def wire(self, chunk: int) -> None:
        """Point every compiled block's inputs at the values they read."""
        feeds = {(c.dst_block, c.dst_port): c for c in self.d.connections}
        ticks = self.s.event_ticks
        if len(ticks):  # from t = 0 to the first event, between events, around the hyperperiod
            longest = int(np.diff(np.concatenate(([0], ticks, [self.s.hyperperiod + ticks[0]]))).max())
        else:  # no events: one span from t = 0 to the end
            longest = max(self.s.n_ticks, 1)
        for cb in self.blocks.values():
            for i, port in enumerate(cb.block.inputs):
                c = feeds.get((cb.name, port))
                if c is None:
                    value = self.inputs[cb.name][port]
                    self.owners.append(value)
                elif not c.delay and c.src_block in self.blocks and port not in cb.block.input_defaults:
                    value = self.blocks[c.src_block].views[c.src_port]
                elif not c.delay and c.src_block in self.blocks:
                    # it holds its default until the source's first hit, then follows it
                    value = self.buffers[cb.name, port] = np.array(self.inputs[cb.name][port], dtype=float)
                    source = self.blocks[c.src_block].views[c.src_port]
                    self.blocks[c.src_block].forwards.append(
                        ([OP_COPY, source.size, address(value), address(source)], (cb.name, "input")))
                else:
                    value = self.buffers[cb.name, port] = np.array(self.inputs[cb.name][port], dtype=float)
                cb.pointers[i] = address(value)
            if cb.name in self.s.advanced:
                period = self.s.period_ticks[cb.name]
                cb.rows = np.empty((max(1, min(chunk, -(-longest // period))), cb.width))
        self.owners.append(self.buffers)

    def build_logs(self, loggers: dict[str, list]) -> None:
        """The log table (a block's loggers side by side) and its counters."""
        rows = []
        for cb in self.blocks.values():
            first = len(rows)
            for lg in loggers[cb.name]:
                port = lg.name.rsplit(".", 1)[1]
                rows.append([address(lg.buf), cb.block.outputs[port], cb.offsets[port], lg.buf.shape[0],
                             lg.decimate])
                self.logged.append(lg)
            cb.logs = (first, len(rows))
        self.log_table = np.array(rows, dtype=np.int64).reshape(-1, 5)
        self.counters = np.zeros((len(rows), 2), dtype=np.int64)

    def sync_logs(self) -> None:
        """Copy the C side's counts into the loggers (rows written, hits seen)."""
        if self.logged:
            for lg, (pos, hits) in zip(self.logged, self.counters.tolist()):
                lg.pos, lg.hits = pos, hits

    # -- ops ---------------------------------------------------------------------------

    def forward_ops(self, name: str) -> list[tuple[list[int], tuple[str, str]]]:
        """The copies that follow a compiled block's outputs (``CompiledBlock.forwards``)."""
        return self.blocks[name].forwards

    def output_op(self, name: str, log: bool) -> list[int]:
        cb = self.blocks[name]
        first, end = cb.logs if log else (0, 0)
        return [OP_OUTPUT, cb.slot, first, end]

    def update_op(self, name: str) -> list[int]:
        return [OP_UPDATE, self.blocks[name].slot, 0, 0]

    def advance_op(self, name: str) -> list[int]:
        cb = self.blocks[name]
        return [OP_ADVANCE, cb.slot, *cb.logs]

    def copy_op(self, c) -> list[int]:
        """A delayed connection between compiled blocks takes its source's value."""
        source = self.blocks[c.src_block].views[c.src_port]
        return [OP_COPY, source.size, address(self.buffers[c.dst_block, c.dst_port]), address(source)]

    def runner(self, events: list[tuple[int, list[list[int]], list[tuple[str, str]]]],
               end: Callable[[str, BaseException, int], int]) -> "Runner":
        """A C runner of ``events``: (tick offset, ops, (block, phase) per op) each.
        ``end(block, exception, tick)`` takes an update's request to end the run (its
        ``EndRun``, from the kernel's error factory) and returns the tick the run ends at."""
        table, ops, steps = [], [], []
        for offset, event_ops, event_steps in events:
            table.append([offset, len(ops), len(ops) + len(event_ops)])
            ops += event_ops
            steps += event_steps
        tick = self.s.base_tick

        def on_end(op: int, which: int, k: int) -> int:
            name, phase = steps[op]
            return end(name, self.error(name, phase, END_RUN, which, k), k)

        native = NativeRunner(self.slots, np.array(ops, dtype=np.int64).reshape(-1, 4),
                              np.array(table, dtype=np.int64).reshape(-1, 3), self.log_table, self.counters,
                              tick.numerator, tick.denominator, (self.owners, self.blocks), on_end)
        return Runner(native, steps, self)

    def error(self, name: str, phase: str, code: int, which: int, tick: int) -> BaseException:
        """The exception of a kernel's failure, from its block's error factory."""
        cb = self.blocks[name]
        t = tick * self.s.base_tick.numerator / self.s.base_tick.denominator
        return (cb.kernel.error or failure)(code, which, t, phase)


class Runner:
    """A compiled piece of an event program: ``run(k, next_k)`` returns None or the
    failure ``(code, which, op, tick, raised)``, which ``failure`` turns into its block,
    phase, tick and exception (``raised`` itself for ``RAISED``)."""

    def __init__(self, native, steps: list[tuple[str, str]], side: CompiledSide):
        self.native = native
        self.run: Callable[[int, int], Any] = native.run
        self.steps = steps
        self.side = side

    def failure(self, result: tuple[int, int, int, int, Any]) -> tuple[str, str, int, BaseException]:
        """(block, phase, tick, exception) of a failure ``run`` returned."""
        code, which, op, tick, raised = result
        name, phase = self.steps[op]
        if code == RAISED:
            return name, phase, tick, raised
        return name, phase, tick, self.side.error(name, phase, code, which, tick)
