"""The run as data: a diagram's plan compiled to one op table.

A Schedule says what happens at each kind of event; the op table says it as plain
arrays that the interpreters run: the C core (``blocks/csrc/core.c``, which needs no
Python) and the reference loop (``blocks.engine.reference_loop``). Its layouts are documented once,
in ``blocks/csrc/core.h``; the column names below are the same. In short:

- the **arena**: one float64 array per run holding every block's outputs, the buffers of
  delayed connections and of inputs that hold a default until their source first fires,
  the values of unconnected inputs and each advanced block's rows; ``initial`` is its
  content at t = 0. Every place a value lives is an offset into it.
- **blocks** (where their outputs and advance rows are, which inputs they read, their
  period), **inputs** (the offset each input port reads), **ports** (each output port's
  offset);
- **ops** of four kinds: a block's outputs (logging some signals), its update, its
  advance to the next event, a copy; **copies** (destination, source, width);
- **programs** (a range of ops each: the initial one, one per kind of event, the final
  ones), **events** (tick within the hyperperiod, program), **logs** (block, column,
  width, decimation, capacity) and **selections** (the ports a step of a block with
  per-port feedthrough stands for).

Nothing in it is a Python object or a pointer, so a table can be packed into bytes
(``OpTable.pack``, read back by ``blk_table_unpack``) and run anywhere. Which blocks run
through their kernels is not part of it: that is decided per run (``blocks.engine.compiled``).
A table depends only on the diagram and the end time, so it is built once per Schedule.
"""

from __future__ import annotations

import functools
import weakref
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from blocks.builder.diagram import Connection, Diagram
from blocks.builder.elements import contiguous, paired_runs
from blocks.issues import DiagramError
from blocks.engine.schedule import EventProgram, Schedule, final_program
from blocks.timebase import format_duration

ADVANCE_CHUNK = 4096
"""At most this many hits per ``advance`` call, so the rows an advance writes stay small."""

EXACT_TICKS = 2**53
"""Tick times are exact in double while ``tick * numerator`` stays below this."""

MAX_TICKS = 2**62
"""Runs of more base ticks (plus a hyperperiod) than this do not fit the table's integers."""

H_HYPERPERIOD, H_N_TICKS, H_TICK_NUM, H_TICK_DEN, H_INITIAL, H_FINAL, H_ARENA = range(7)
B_OUT, B_WIDTH, B_FIRST_INPUT, B_N_INPUTS, B_PERIOD, B_ROWS, B_ROWS_CAPACITY, B_FIRST_PORT, B_N_PORTS = range(9)
I_OFFSET, I_WIDTH = range(2)
P_BLOCK, P_OFFSET, P_WIDTH = range(3)
OP_CODE, OP_A, OP_B, OP_C, OP_D = range(5)
OUTPUT, UPDATE, ADVANCE, COPY = range(4)
C_DST, C_SRC, C_WIDTH = range(3)
PR_FIRST, PR_END, PR_FINAL = range(3)
E_TICK, E_PROGRAM = range(2)
L_BLOCK, L_COLUMN, L_WIDTH, L_DECIMATE, L_CAPACITY = range(5)
LC_ROWS, LC_HITS = range(2)
"""The columns of each table (core.h's BLK_* names without the prefix), and of a run's
log counters."""

PHASES = ("output", "update", "advance")
"""The phase of a block's op, by op code, as failures name it."""

TABLES = ("header", "blocks", "inputs", "ports", "ops", "copies", "programs", "events", "logs", "selections")
WIDTHS = (7, 9, 2, 3, 5, 3, 3, 2, 5, 1)
"""The tables in core.h's order, and their row widths."""

FEEDS = ("source", "delayed", "default until fired", "unconnected", "assembled")
"""What an input port reads: its source's output (or a run of its elements); a buffer a
delayed connection samples into; a buffer that holds its default until its source first
fires; its default; a buffer that copies of its elements assemble from one or several
outputs (connections naming elements), each as its source fires or, delayed, as its
destination does."""

PACK_MAGIC = 0x454C4241544B4C42
PACK_VERSION = 1


@dataclass(frozen=True)
class TableNames:
    """What the rows of a table stand for, for people and for the hosts: the diagram's
    names, which the arrays do not hold."""

    blocks: tuple[str, ...]
    ports: tuple[tuple[str, ...], ...]
    """Per block, its output ports' names (selections number them)."""
    inputs: tuple[tuple[str, ...], ...]
    """Per block, its input ports' names, in the order of the inputs table."""
    feeds: tuple[tuple[str, ...], ...]
    """Per block and input port, what it reads (``FEEDS``)."""
    logs: tuple[str, ...]
    log_order: tuple[int, ...]
    """For each row of the logs table, its entry's position in the diagram's ``log``."""
    copies: tuple[str, ...]
    programs: tuple[str, ...]


@dataclass(frozen=True)
class OpTable:
    """A compiled run (layouts: module docstring and ``blocks/csrc/core.h``). The arrays
    are read-only: one table serves every run of its diagram to its end time."""

    header: np.ndarray
    blocks: np.ndarray
    inputs: np.ndarray
    ports: np.ndarray
    ops: np.ndarray
    copies: np.ndarray
    programs: np.ndarray
    events: np.ndarray
    logs: np.ndarray
    selections: np.ndarray
    initial: np.ndarray
    names: TableNames
    base_tick: Fraction
    """The base tick in seconds (the header holds it as num / den while both fit in int64;
    else as 0 / 0, a table only the reference loop runs)."""

    def arrays(self) -> tuple[np.ndarray, ...]:
        """The int64 tables in core.h's order (``TABLES``)."""
        return tuple(getattr(self, name) for name in TABLES)

    @functools.cached_property
    def roles(self) -> tuple[frozenset[int], frozenset[int]]:
        """The blocks (indices) that the table updates, and those it advances: what each
        run asks of their kernels, found once per table."""
        code, block = self.ops[:, OP_CODE], self.ops[:, OP_A]
        return frozenset(block[code == UPDATE].tolist()), frozenset(block[code == ADVANCE].tolist())

    @property
    def n_ticks(self) -> int:
        return int(self.header[H_N_TICKS])

    @property
    def exact_in_double(self) -> bool:
        """Whether ``k * num / den`` in double is the exact tick time of every tick of the
        run, as the C core computes it (else only the reference loop, in integers, is)."""
        h, tick = self.header, self.base_tick
        return int(h[H_N_TICKS] + h[H_HYPERPERIOD]) * tick.numerator < EXACT_TICKS and tick.denominator < EXACT_TICKS

    def time(self, tick: int) -> float:
        """The time of ``tick`` in seconds, ``tick * num / den`` from the integers (exact
        rounding, as the C core's double arithmetic gives while ``exact_in_double``)."""
        return int(tick) * self.base_tick.numerator / self.base_tick.denominator

    def selection(self, index: int) -> list[int]:
        """The ports (numbered within their block) of selection ``index``."""
        count = int(self.selections[index])
        return self.selections[index + 1:index + 1 + count].tolist()

    def pack(self) -> bytes:
        """The table as ``blk_table_unpack`` reads it: magic, version, the ten row counts,
        the ten tables, the arena's initial values (int64 and float64, native order)."""
        counts = [len(self.selections) if name == "selections" else (1 if name == "header" else len(a))
                  for name, a in zip(TABLES, self.arrays())]
        head = np.array([PACK_MAGIC, PACK_VERSION, *counts], dtype=np.int64)
        return b"".join([head.tobytes(), *(a.tobytes() for a in self.arrays()), self.initial.tobytes()])


_tables: dict[int, OpTable] = {}
"""Tables already built, by Schedule (its id, while it lives)."""


def op_table(diagram: Diagram, schedule: Schedule) -> OpTable:
    """The op table of ``schedule`` (a plan of ``diagram`` with an end time), built once;
    a DiagramError for a run too long for its integers."""
    table = _tables.get(id(schedule))
    if table is None:
        if schedule.n_ticks + schedule.hyperperiod >= MAX_TICKS:
            raise DiagramError([diagram.issue(None, f"t_end is {schedule.n_ticks} base ticks of "
                                              f"{format_duration(schedule.base_tick)}: more than a run can count",
                                              "shorten t_end")])
        table = _tables[id(schedule)] = _Compiler(diagram, schedule).table()
        weakref.finalize(schedule, _tables.pop, id(schedule), None)
    return table


def stepping_table(diagram: Diagram, schedule: Schedule, extra: tuple[EventProgram, ...],
                   n_ticks: int, span: int) -> tuple[OpTable, list[int]]:
    """The op table of a run stepped in parts by a program of its own (an exported FMU):
    without logs, every event program with a final one (the outputs of a communication
    point at that event), ``extra`` programs after the others (their indices returned),
    and ``n_ticks`` in its header. ``span``: the base ticks an advance steps in one call
    where no event cuts it (the parts the run is stepped in), which the advanced blocks'
    rows hold. Not cached: an export builds it once."""
    compiler = _Compiler(diagram, schedule, logs=False, span=span)
    table = compiler.table(extra=extra, every_final=True, n_ticks=n_ticks)
    return table, compiler.extra_programs


def _frozen(rows: list, width: int) -> np.ndarray:
    array = np.array(rows, dtype=np.int64).reshape(-1, width) if width > 1 else np.array(rows, dtype=np.int64)
    array.setflags(write=False)
    return array


class _Compiler:
    """Lays out the arena and writes the programs of a Schedule as ops."""

    def __init__(self, diagram: Diagram, schedule: Schedule, logs: bool = True, span: int | None = None):
        self.d, self.s = diagram, schedule
        self.logs = logs
        self.span = span
        """Without events, the ticks one advance call covers (None: the whole run)."""
        self.names = list(diagram.blocks)
        self.index = {n: i for i, n in enumerate(self.names)}
        self.size = 0
        self.values: list[tuple[int, np.ndarray]] = []
        """Initial arena values other than zero: (offset, values)."""
        self.ops: list[list[int]] = []
        self.copies: list[list[int]] = []
        self.copy_names: list[str] = []
        self.selections: list[int] = []
        self.forwards: dict[str, list[tuple[str, int]]] = {n: [] for n in self.names}
        """Per block, the copies that follow its outputs: (its port, copy)."""
        self.sampled: dict[int, list[int]] = {}
        """Per delayed connection (its index), its copies."""

    def place(self, width: int, values: Any = None) -> int:
        offset = self.size
        self.size += width
        if values is not None:
            self.values.append((offset, values))
        return offset

    def table(self, extra: tuple[EventProgram, ...] = (), every_final: bool = False,
              n_ticks: int | None = None) -> OpTable:
        d, s = self.d, self.s
        if s.n_ticks is None or s.final is None:
            raise ValueError("an op table needs a plan with an end time")
        self.out: dict[str, int] = {}
        self.port_offset: dict[tuple[str, str], int] = {}
        ports, port_names = [], []
        for b, name in enumerate(self.names):
            outputs = d.blocks[name].block.outputs
            self.out[name] = self.place(sum(outputs.values()))
            at = self.out[name]
            for port, width in outputs.items():
                self.port_offset[name, port] = at
                ports.append([b, at, width])
                at += width
            port_names.append(tuple(outputs))
        inputs, input_names, feeds = self.lay_out_inputs()
        logs, log_names, log_order, block_logs = self.lay_out_logs()
        blocks = self.block_rows(inputs, block_logs)
        self.block_logs = block_logs
        programs, program_names = [], []

        def add(program: EventProgram, what: str) -> int:
            first = len(self.ops)
            self.emit(program)
            programs.append([first, len(self.ops), -1])
            program_names.append(what)
            return len(programs) - 1

        add(s.initial, "t = 0")
        event_program = [add(p, "event") for p in s.programs]
        final = add(s.final, "the end at t_end")
        first_tick = {}
        for tick, j in zip(s.event_ticks.tolist(), s.event_programs):
            first_tick.setdefault(j, tick)
        for j, p in enumerate(s.programs):
            if p.update or every_final:
                programs[event_program[j]][PR_FINAL] = add(final_program(d, s, first_tick[j]),
                                                           f"the end asked by a block, at an event of program {j + 1}")
        self.extra_programs = [add(p, "outputs of a communication point") for p in extra]
        events = [[tick, event_program[j]] for tick, j in zip(s.event_ticks.tolist(), s.event_programs)]
        num, den = s.base_tick.numerator, s.base_tick.denominator
        if max(num, den) >= 2**63:
            num = den = 0
        header = [s.hyperperiod, s.n_ticks if n_ticks is None else n_ticks, num, den, 0, final, self.size]
        initial = np.zeros(self.size)
        for offset, values in self.values:
            initial[offset:offset + len(values)] = values
        initial.setflags(write=False)
        names = TableNames(tuple(self.names), tuple(port_names), input_names, feeds, log_names, log_order,
                           tuple(self.copy_names), tuple(program_names))
        return OpTable(_frozen(header, 1), _frozen(blocks, 9), _frozen(inputs, 2), _frozen(ports, 3),
                       _frozen(self.ops, 5), _frozen(self.copies, 3), _frozen(programs, 3), _frozen(events, 2),
                       _frozen(logs, 5), _frozen(self.selections, 1), initial, names, s.base_tick)

    def lay_out_inputs(self):
        """Where each input port reads: its source's output (a run of its elements), or a
        buffer of its own when the connection is delayed, when it holds a default until its
        source first fires, when nothing feeds it (its default), or when connections naming
        elements assemble it."""
        d = self.d
        feeding: dict[tuple[str, str], list[tuple[int, Connection]]] = {}
        for i, c in enumerate(d.connections):
            feeding.setdefault((c.dst_block, c.dst_port), []).append((i, c))
        rows, names, feeds = [], [], []
        for name in self.names:
            blk = d.blocks[name].block
            kinds = []
            for port, width in blk.inputs.items():
                conns = feeding.get((name, port), [])
                default = _value(blk.input_defaults.get(port), width)
                one = conns[0][1] if len(conns) == 1 else None
                if not conns:
                    kind, offset = "unconnected", self.place(width, default)
                elif one is None or one.dst_elements is not None or not contiguous(one.src_elements or ()):
                    kind, offset = "assembled", self.assemble(name, port, width, conns)
                else:
                    i, c = conns[0]
                    source = self.port_offset[c.src_block, c.src_port] + (c.src_elements or (0,))[0]
                    if c.delay:
                        kind = "delayed"
                        initial = None if c.initial is None else np.broadcast_to(
                            np.asarray(c.initial, dtype=float), (width,))
                        offset = self.place(width, initial)
                        self.sampled[i] = [self.copy(offset, source, width, f"{c.src_text} -> {name}.{port} (delay 1)")]
                    elif port in blk.input_defaults:
                        kind, offset = "default until fired", self.place(width, default)
                        self.forwards[c.src_block].append((c.src_port, self.copy(
                            offset, source, width,
                            f"{c.src_text} -> {name}.{port} (its default until {c.src_block} first fires)")))
                    else:
                        kind, offset = "source", source
                rows.append([offset, width])
                kinds.append(kind)
            names.append(tuple(blk.inputs))
            feeds.append(tuple(kinds))
        return rows, tuple(names), tuple(feeds)

    def assemble(self, name: str, port: str, width: int, conns: list[tuple[int, Connection]]) -> int:
        """The buffer of an input that connections assemble, element by element: the
        input's default (or zeros), a delayed part's initial value where it goes; each
        connection's copies, in runs, after its source's outputs or, delayed, at its
        destination's hits."""
        blk = self.d.blocks[name].block
        values = np.zeros(width)
        if port in blk.input_defaults:
            values[:] = np.broadcast_to(np.asarray(blk.input_defaults[port], dtype=float).ravel(), (width,))
        ends = [(c.src_elements if c.src_elements is not None else tuple(range(self.d.width(c.src))),
                 c.dst_elements if c.dst_elements is not None else tuple(range(width))) for _, c in conns]
        for (_, c), (_, dst) in zip(conns, ends):
            if c.initial is not None:
                values[list(dst)] = np.broadcast_to(np.asarray(c.initial, dtype=float), (len(dst),))
        offset = self.place(width, values)
        for (i, c), (src, dst) in zip(conns, ends):
            at = self.port_offset[c.src_block, c.src_port]
            copies = [self.copy(offset + b, at + a, n, f"{c.src_text} -> {c.dst_text}" + (
                " (delay 1)" if c.delay else "") + f", {_span(a, n)} -> {_span(b, n)}")
                for a, b, n in paired_runs(src, dst)]
            if c.delay:
                self.sampled[i] = copies
            else:
                self.forwards[c.src_block] += [(c.src_port, copy) for copy in copies]
        return offset

    def copy(self, dst: int, src: int, width: int, what: str) -> int:
        self.copies.append([dst, src, width])
        self.copy_names.append(what)
        return len(self.copies) - 1

    def lay_out_logs(self):
        """The log table, a block's entries side by side (so an op logs a range of them)."""
        d, s = self.d, self.s
        if not self.logs:
            return [], (), (), {}
        order = sorted(range(len(d.log)), key=lambda j: self.index[d.log[j].block])
        rows, block_logs = [], {}
        for j in order:
            e = d.log[j]
            outputs = d.blocks[e.block].block.outputs
            column = self.port_offset[e.block, e.port] - self.out[e.block]
            first, end = block_logs.get(e.block, (len(rows), len(rows)))
            block_logs[e.block] = (first, end + 1)
            rows.append([self.index[e.block], column, outputs[e.port], e.decimate,
                         -(-s.hit_count(e.block, s.n_ticks) // e.decimate)])
        return rows, tuple(d.log[j].signal for j in order), tuple(order), block_logs

    def block_rows(self, inputs: list, block_logs: dict) -> list[list[int]]:
        d, s = self.d, self.s
        ticks = s.event_ticks
        if len(ticks):  # from t = 0 to the first event, between events, around the hyperperiod
            longest = int(np.diff(np.concatenate(([0], ticks, [s.hyperperiod + ticks[0]]))).max())
        else:  # no events: one span from t = 0 to the end, or the parts a stepped run takes
            longest = max(s.n_ticks if self.span is None else self.span, 1)
        rows, first_input, first_port = [], 0, 0
        for name in self.names:
            blk = d.blocks[name].block
            width = sum(blk.outputs.values())
            period = s.period_ticks[name] or 0
            rows_at = capacity = 0
            if name in s.advanced:
                capacity = max(1, min(ADVANCE_CHUNK, -(-longest // period)))
                rows_at = self.place(capacity * width)
            rows.append([self.out[name], width, first_input, len(blk.inputs), period, rows_at, capacity,
                         first_port, len(blk.outputs)])
            first_input += len(blk.inputs)
            first_port += len(blk.outputs)
        return rows

    def selection(self, name: str, ports: tuple[str, ...] | None) -> int:
        if ports is None:
            return -1
        outputs = list(self.d.blocks[name].block.outputs)
        self.selections += [len(ports), *(outputs.index(p) for p in ports)]
        return len(self.selections) - 1 - len(ports)

    def emit(self, program: EventProgram) -> None:
        """A program's steps as ops: outputs in order (each block logged at its last step),
        updates, the samples of delayed connections, the advances; each output or advance
        followed by the copies into inputs that hold a default until it first fires."""
        ops, b = self.ops, self.index
        last_step = {name: i for i, (name, _) in enumerate(program.evaluate)}
        for i, (name, ports) in enumerate(program.evaluate):
            first, end = self.block_logs.get(name, (0, 0)) if name in program.firing and last_step[name] == i \
                else (0, 0)
            ops.append([OUTPUT, b[name], first, end, self.selection(name, ports)])
            ops += [[COPY, c, 0, 0, 0] for port, c in self.forwards[name] if ports is None or port in ports]
        ops += [[UPDATE, b[name], 0, 0, 0] for name in program.update]
        ops += [[COPY, copy, 0, 0, 0] for i in program.sample for copy in self.sampled[i]]
        for name in program.advance:
            first, end = self.block_logs.get(name, (0, 0))
            ops.append([ADVANCE, b[name], first, end, int(name == program.advance[-1])])
            ops += [[COPY, c, 0, 0, 0] for _, c in self.forwards[name]]


def _value(value: Any, width: int) -> np.ndarray | None:
    """An input default as the arena holds it: its values when it has the port's width
    (one of another width only a Python block meets, through its input mapping)."""
    if value is None:
        return None
    array = np.asarray(value, dtype=float)
    return array if array.shape == (width,) else None


def _span(first: int, length: int) -> str:
    """Elements ``first`` .. ``first + length - 1`` as the op table's text names them."""
    return f"[{first}]" if length == 1 else f"[{first}:{first + length}]"
