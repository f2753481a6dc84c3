"""The reference loop: the op table run in plain Python, one function per op kind.

This is the executable statement of what a tick means, written to be read; the C core
(``blocks/csrc/core.c``) does the same, fast, and the tests hold the two to the same
samples on random diagrams. A run: the initial program at tick 0, its advances stepping
to the first event; the events in order, each program's advances stepping to the next
event; at the end tick the final program, outputs only. A block that asks to end the
run moves the end to its next hit (the first one asking is the one reported, the
earliest end wins). An interrupt stops the run where every block got to.

Compiled blocks run through their kernels here too (one ``blocks._native.call`` per
call, so a diagram of Python and compiled blocks runs the same mix as in C); Python
blocks through ``blocks.engine.python_blocks``. The loop also runs where the C core cannot: in
an uncompiled checkout, and for runs whose tick times are not exact in double.
"""

from __future__ import annotations

from typing import Callable

from blocks.engine.binding import Binding
from blocks.block import EndRun
from blocks.engine.compiled import native
from blocks.engine.finite import first_nonfinite, nonfinite_output
from blocks.engine.kernel import END_RUN
from blocks.engine.optable import (
    B_FIRST_INPUT,
    B_N_INPUTS,
    B_OUT,
    B_PERIOD,
    B_ROWS,
    B_ROWS_CAPACITY,
    B_WIDTH,
    C_DST,
    C_SRC,
    C_WIDTH,
    COPY,
    E_PROGRAM,
    E_TICK,
    H_FINAL,
    H_HYPERPERIOD,
    H_INITIAL,
    H_N_TICKS,
    I_OFFSET,
    I_WIDTH,
    L_CAPACITY,
    L_COLUMN,
    L_DECIMATE,
    L_WIDTH,
    LC_HITS,
    LC_ROWS,
    OP_A,
    OP_B,
    OP_C,
    OP_CODE,
    OP_D,
    OUTPUT,
    PHASES,
    UPDATE,
)
from blocks.engine.outcome import Outcome, stopped
from blocks.engine.python_blocks import PythonSide

class _Stop(Exception):
    """Carries the outcome of a run that stopped at an op."""

    def __init__(self, outcome: Outcome):
        super().__init__()
        self.outcome = outcome


class ReferenceLoop:
    """One run of a bound table (``Binding``) in Python."""

    def __init__(self, binding: Binding, progress: Callable[[int], None] | None = None):
        self.b = binding
        self.t = binding.table
        self.python = PythonSide(binding)
        self.progress = progress
        self.polls = 0
        self.events = self.t.events.tolist()
        self.ops = self.t.ops.tolist()
        self.end = int(self.t.header[H_N_TICKS])
        self.end_program = int(self.t.header[H_FINAL])
        self.reached = 0
        self.end_request: tuple[str, str, int] | None = None
        self.after = 0
        """The first event after the program running now, counted from the first event of
        the first hyperperiod (so events of later hyperperiods count on)."""

    def event_tick(self, position: int) -> int:
        cycle, row = divmod(position, len(self.events))
        return cycle * int(self.t.header[H_HYPERPERIOD]) + self.events[row][E_TICK]

    def run(self) -> Outcome:
        header = self.t.header
        try:
            if self.events and self.events[0][E_TICK] == 0:
                self.after = 1  # the event at tick 0 is the initial program's
            first = min(self.event_tick(self.after), self.end) if self.events else self.end
            self.program(int(header[H_INITIAL]), 0, first)
            self.poll()
            while self.events:
                k = self.event_tick(self.after)
                if k >= self.end:
                    break
                program = self.events[self.after % len(self.events)][E_PROGRAM]
                self.after += 1
                self.program(program, k, min(self.event_tick(self.after), self.end))
                self.poll()
            final = int(header[H_FINAL]) if self.end == int(header[H_N_TICKS]) else self.end_program
            self.program(final, self.end, self.end)
        except _Stop as stop:
            return stop.outcome
        except KeyboardInterrupt as interrupt:  # Ctrl-C anywhere in the loop's own Python
            return Outcome(None, self.reached, interrupt=interrupt, end_request=self.end_request)
        return Outcome(self.end, self.end, end_request=self.end_request)

    def poll(self) -> None:
        """After each event and between the chunks of an advance: progress now and then
        (Ctrl-C comes as a KeyboardInterrupt wherever Python runs)."""
        self.polls += 1
        if self.progress is not None and self.polls % 256 == 0:
            self.progress(self.reached)

    def program(self, p: int, k: int, next_k: int) -> None:
        """Program ``p`` at tick ``k``, its advances stepping to ``next_k``."""
        first, end, _ = self.t.programs[p]
        self.reached = k
        for op in self.ops[first:end]:
            if op[OP_CODE] == OUTPUT:
                self.output(op, k)
            elif op[OP_CODE] == UPDATE:
                self.update(op, k)
            elif op[OP_CODE] == COPY:
                self.copy(op)
            else:
                self.advance(op, k, next_k)
        self.reached = next_k

    # -- one function per op kind ---------------------------------------------------------

    def output(self, op: list[int], k: int) -> None:
        """A block's outputs at tick k into the arena, then the log entries of the op."""
        b = op[OP_A]
        t = self.t.time(k)
        if self.b.kernels[b] is None:
            self.guarded(op, k, lambda: self.python.output(b, op[OP_D], t))
        else:
            self.checked(op, k, self.kernel_call(op, k, "output", self.b.kernels[b].output, t, self.out(b)))
        bad = nonfinite_output(self.t, self.b.arena, b, op[OP_D]) if self.b.check_finite else -1
        if bad >= 0:
            self.fail(op, k, self.b.nonfinite_error(b, bad), python=False)
        row = self.out(b)
        for entry in range(op[OP_B], op[OP_C]):
            self.log(entry, row)

    def update(self, op: list[int], k: int) -> None:
        """A block's update at tick k; one that asks to end the run moves the end."""
        b = op[OP_A]
        t = self.t.time(k)
        if self.b.kernels[b] is None:
            end = self.guarded(op, k, lambda: self.python.update(b, t))
        else:
            code, which = self.kernel_call(op, k, "update", self.b.kernels[b].update, t, None)
            if code == END_RUN:
                end = self.guarded(op, k, lambda: self.b.kernel_error(b, END_RUN, which, k, "update"), python=False)
                if not isinstance(end, EndRun):
                    self.fail(op, k, end, python=False)
            else:
                self.checked(op, k, (code, which))
                end = None
        if end is not None:
            if self.end_request is None:
                self.end_request = (self.t.names.blocks[b], end.reason, k)
            self.end_at_next_hit(b)

    def advance(self, op: list[int], k: int, next_k: int) -> None:
        """A block stepped from tick k to next_k in chunks of at most its rows' capacity,
        each from the time of its first tick; every row logged, the last one its outputs."""
        b = op[OP_A]
        block = self.t.blocks[b]
        period, capacity, width = int(block[B_PERIOD]), int(block[B_ROWS_CAPACITY]), int(block[B_WIDTH])
        arena, at = self.b.arena, int(block[B_ROWS])
        n, stepped = (next_k - k) // period, 0
        while n > 0:
            m = min(n, capacity)
            first = k + stepped * period
            rows = arena[at:at + m * width]
            if self.b.kernels[b] is None:
                self.python.refresh(b)
                done, error = self.python.advance(b, self.t.time(first), m)
            else:
                done, error = self.kernel_advance(b, first, m, rows)
            logged = done if error is not None else m
            for i in range(logged if self.b.check_finite else 0):
                bad = first_nonfinite(rows[i * width:(i + 1) * width])
                if bad >= 0:
                    self.out(b)[:] = rows[i * width:(i + 1) * width]
                    logged, done, error = i, i + 1, self.b.nonfinite_error(b, bad)
                    break
            for i in range(logged):
                for entry in range(op[OP_B], op[OP_C]):
                    self.log(entry, rows[i * width:(i + 1) * width])
            if error is not None:
                self.fail(op, first + done * period, error, python=self.b.kernels[b] is None)
            self.out(b)[:] = rows[(m - 1) * width:m * width]
            n -= m
            stepped += m
            if op[OP_D]:
                self.reached = k + stepped * period
            if n > 0:
                self.poll()

    def copy(self, op: list[int]) -> None:
        """A delayed connection samples its source; an input takes its source's value."""
        dst, src, width = (int(x) for x in self.t.copies[op[OP_A]][[C_DST, C_SRC, C_WIDTH]])
        self.b.arena[dst:dst + width] = self.b.arena[src:src + width]

    # -- logging, ending, failing ------------------------------------------------------------

    def log(self, entry: int, outputs) -> None:
        """Every ``decimate``-th hit of a logged signal is kept, up to the log's capacity."""
        row = self.t.logs[entry]
        counters = self.b.counters[entry]
        if counters[LC_HITS] % row[L_DECIMATE] == 0 and counters[LC_ROWS] < row[L_CAPACITY]:
            self.b.logs[entry][counters[LC_ROWS]] = outputs[row[L_COLUMN]:row[L_COLUMN] + row[L_WIDTH]]
            counters[LC_ROWS] += 1
        counters[LC_HITS] += 1

    def end_at_next_hit(self, b: int) -> None:
        """The run ends at block b's next hit, the first event (within a hyperperiod) whose
        program updates it, if that comes before the end so far."""
        position = self.after
        for _ in range(len(self.events)):
            tick = self.event_tick(position)
            if tick >= self.end:
                return
            program = self.events[position % len(self.events)][E_PROGRAM]
            first, end, final = self.t.programs[program]
            if any(self.ops[i][OP_CODE] == UPDATE and self.ops[i][OP_A] == b for i in range(first, end)):
                self.end, self.end_program = tick, int(final)
                return
            position += 1

    def fail(self, op: list[int], tick: int, error: BaseException, python: bool) -> None:
        b = op[OP_A]
        raise _Stop(stopped(self.t.names.blocks[b], PHASES[op[OP_CODE]], tick, error, self.reached, python,
                            self.end_request))

    def guarded(self, op: list[int], k: int, call: Callable, python: bool = True):
        """A call for the op; what it raises stops the run there."""
        try:
            return call()
        except BaseException as exc:
            self.fail(op, k, exc, python)

    def checked(self, op: list[int], k: int, result: tuple[int, int]) -> None:
        """A kernel's return: a nonzero code fails the op with the block's own error."""
        code, which = result
        if code:
            self.fail(op, k, self.b.kernel_error(op[OP_A], code, which, k, PHASES[op[OP_CODE]]), python=False)

    # -- kernel calls ----------------------------------------------------------------------

    def out(self, b: int):
        block = self.t.blocks[b]
        return self.b.arena[int(block[B_OUT]):int(block[B_OUT] + block[B_WIDTH])]

    def input_views(self, b: int) -> list:
        block = self.t.blocks[b]
        first = int(block[B_FIRST_INPUT])
        rows = self.t.inputs[first:first + int(block[B_N_INPUTS])]
        return [self.b.arena[int(r[I_OFFSET]):int(r[I_OFFSET] + r[I_WIDTH])] for r in rows]

    def kernel_state(self, b: int):
        return self.b.states[b] if self.b.state_address(b) else None

    def kernel_call(self, op: list[int], k: int, kind: str, function: int, t: float, out) -> tuple[int, int]:
        """One call of a kernel function; an exception it raised (``BLK_RAISED``) stops the
        run at the op as it is."""
        b = op[OP_A]
        kernel = self.b.kernels[b]
        return self.guarded(op, k, lambda: native().call(kind, function, kernel.context, t, self.kernel_state(b),
                                                         self.input_views(b), out), python=False)

    def kernel_advance(self, b: int, first: int, m: int, rows) -> tuple[int, BaseException | None]:
        kernel = self.b.kernels[b]
        try:
            code, done, which = native().call("advance", kernel.advance, kernel.context, self.t.time(first),
                                              self.kernel_state(b), self.input_views(b), rows, m)
        except BaseException as exc:
            return 0, exc
        if code:
            done = max(0, min(done, m))
            return done, self.b.kernel_error(b, code, which, first + done * int(self.t.blocks[b][B_PERIOD]), "advance")
        return m, None
