"""The clocks and model partitions of a scheduled-execution export (FMI 3.0).

Every rate of the diagram's periodic blocks (period and offset) is a constant periodic
input clock, its priority rate-monotonic (the shortest period 0, the highest priority, as
the standard recommends). At each instant of one hyperperiod, the native program of that
instant is cut into one program per clock that ticks there, in priority order: a clock
takes the ops of its blocks and every op of the instant they depend on that an earlier
clock did not take (an op depends on an earlier one when it reads what that one writes,
or writes what it reads or writes: arena values, or a block's state); the ops left over
(blocks of several clocks, delayed-connection samples) go with the last clock. Run in
priority order, the partitions run the native program's ops in an order its dependencies
allow, hence compute the same values (``blocks/csrc/export_scheduled.h``).

A block belongs to a clock when every hit it has comes from that clock: its own period,
or for a block without one, the blocks feeding it all belong to it. The FMU's inputs and
outputs that only blocks of one clock read or compute carry that clock (``clocks=``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from fractions import Fraction

import numpy as np

from blocks.engine.optable import (
    B_FIRST_INPUT, B_N_INPUTS, B_OUT, B_WIDTH, C_DST, C_SRC, C_WIDTH, COPY, E_PROGRAM, E_TICK, H_HYPERPERIOD,
    H_INITIAL, I_OFFSET, I_WIDTH, OP_A, OP_CODE, OUTPUT, PR_END, PR_FIRST, UPDATE, OpTable,
)
from blocks.timebase import format_duration
from ..issues import DiagramError
from .plan import Plan


@dataclass(frozen=True)
class Clock:
    """An input clock: every ``period`` base ticks from ``offset`` on."""

    name: str
    vr: int
    period: int
    offset: int
    priority: int
    initial: int
    """Its program at tick 0 (-1: none)."""
    hits: tuple[int, ...]
    """Its program at each of its hits in one hyperperiod (-1: none)."""

    def seconds(self, base_tick: Fraction) -> tuple[Fraction, Fraction]:
        """Its interval and shift in seconds."""
        return self.period * base_tick, self.offset * base_tick


@dataclass(frozen=True)
class Partitions:
    table: OpTable
    """The plan's table with the partitions' programs after its own."""
    clocks: tuple[Clock, ...]
    """In priority order."""
    owner: dict[str, int | None]
    """Per block, the clock (its index) it belongs to; None: several or none."""


def clock_name(period: Fraction, offset: Fraction) -> str:
    """``clock_1ms``, ``clock_10ms_2ms`` (an offset of 2 ms)."""
    text = "clock_" + format_duration(period).replace(" ", "")
    if offset:
        text += "_" + format_duration(offset).replace(" ", "")
    return text.replace(".", "p")


def partitions(plan: Plan, first_vr: int) -> Partitions:
    """The clocks of ``plan`` (value references from ``first_vr`` on) and their programs;
    DiagramError for a diagram that cannot run as partitions."""
    d, s, table = plan.diagram, plan.schedule, plan.table
    if s.advanced:
        raise ValueError("a scheduled-execution plan advances no block over spans (plan_export(advance=False))")
    rates = sorted({(s.period_ticks[n], s.offset_ticks[n]) for n in d.blocks if s.period_ticks[n]})
    if not rates:
        raise DiagramError([d.issue(None, "the diagram has no block with a period: it has no clocks to schedule",
                                    "give its blocks periods, or export it for co-simulation")])
    late = [(p, o) for p, o in rates if o >= p]
    if late:
        p, o = late[0]
        raise DiagramError([d.issue(None, f"an offset of {format_duration(o * s.base_tick)} is not shorter than its "
                                    f"period {format_duration(p * s.base_tick)}: no clock of scheduled execution has "
                                    "one", "use an offset shorter than the period")])
    owner = _owners(plan, rates)
    hyper = int(table.header[H_HYPERPERIOD])
    lazy_ops = [] if plan.lazy < 0 else list(range(int(table.programs[plan.lazy, PR_FIRST]),
                                                   int(table.programs[plan.lazy, PR_END])))
    cut = _Cutter(_Ops(table), owner)
    at: dict[int, dict[int, int]] = {c: {} for c in range(len(rates))}
    initial: dict[int, int] = {}
    instants = [(True, 0, int(table.header[H_INITIAL]))] + [(False, int(r[E_TICK]), int(r[E_PROGRAM]))
                                                             for r in table.events]
    for first, tick, program in instants:
        listed = list(range(int(table.programs[program, PR_FIRST]), int(table.programs[program, PR_END])))
        listed += [i for i in lazy_ops if _fires(s, table.names.blocks[int(table.ops[i, OP_A])], tick, first)]
        ticking = [c for c, (p, o) in enumerate(rates) if tick >= o and (tick - o) % p == 0]
        if not ticking:
            if listed:
                raise DiagramError([d.issue(None, "blocks run at t = 0 but no clock ticks there (every periodic "
                                            "block has an offset)", "give one rate no offset")])
            continue
        for c, p in zip(ticking, cut.programs(listed, ticking)):
            if first:
                initial[c] = p
            else:
                at[c][tick] = p
    clocks = []
    for c, (p, o) in enumerate(rates):
        hits = tuple(at[c].get(o + j * p, -1) for j in range(hyper // p))
        clocks.append(Clock(clock_name(p * s.base_tick, o * s.base_tick), first_vr + c, p, o, c,
                            initial.get(c, -1), hits))
    return Partitions(cut.table(), tuple(clocks), owner)


def _fires(s, block: str, tick: int, first: bool) -> bool:
    return bool(s.masks[block][tick]) or (first and s.fires_at_zero[block])


def _owners(plan: Plan, rates: list[tuple[int, int]]) -> dict[str, int | None]:
    """Per block, the clock whose ticks are all its hits (module docstring), or None."""
    d, s = plan.diagram, plan.schedule
    index = {rate: c for c, rate in enumerate(rates)}
    sets = {n: {index[s.period_ticks[n], s.offset_ticks[n]]} if s.period_ticks[n] else set() for n in d.blocks}
    sources: dict[str, set[str]] = {n: set() for n in d.blocks}
    for c in d.connections:
        sources[c.dst_block].add(c.src_block)
    inherited = [n for n in d.blocks if not s.period_ticks[n]]
    changed = True
    while changed:  # the clock sets only grow: a fixed point in at most one pass per block
        changed = False
        for n in inherited:
            grown = sets[n].union(*(sets[src] for src in sources[n]))
            if grown != sets[n]:
                sets[n], changed = grown, True
    return {n: next(iter(c)) if len(c) == 1 else None for n, c in sets.items()}


class _Ops:
    """What each op of a table reads and writes: arena offsets, and ("state", block)."""

    def __init__(self, table: OpTable):
        self.t = table
        self.cache: dict[int, tuple[frozenset, frozenset]] = {}

    def block_inputs(self, b: int) -> set:
        t = self.t
        first, n = int(t.blocks[b, B_FIRST_INPUT]), int(t.blocks[b, B_N_INPUTS])
        return {o for row in t.inputs[first:first + n] for o in range(int(row[I_OFFSET]),
                                                                       int(row[I_OFFSET] + row[I_WIDTH]))}

    def access(self, i: int) -> tuple[frozenset, frozenset]:
        if i not in self.cache:
            t, op = self.t, self.t.ops[i]
            code, a = int(op[OP_CODE]), int(op[OP_A])
            if code == COPY:
                c = t.copies[a]
                reads = set(range(int(c[C_SRC]), int(c[C_SRC] + c[C_WIDTH])))
                writes = set(range(int(c[C_DST]), int(c[C_DST] + c[C_WIDTH])))
            elif code in (OUTPUT, UPDATE):
                reads = self.block_inputs(a) | {("state", a)}
                writes = ({("state", a)} if code == UPDATE
                          else set(range(int(t.blocks[a, B_OUT]), int(t.blocks[a, B_OUT] + t.blocks[a, B_WIDTH]))))
            else:
                raise ValueError("a scheduled-execution table has no advances")
            self.cache[i] = frozenset(reads), frozenset(writes)
        return self.cache[i]

    def owner(self, i: int, owner: dict[str, int | None]) -> int | None:
        op = self.t.ops[i]
        return None if int(op[OP_CODE]) == COPY else owner[self.t.names.blocks[int(op[OP_A])]]


class _Cutter:
    """Cuts the ops of instants into partitions' programs, appended after the table's own."""

    def __init__(self, ops: _Ops, owner: dict[str, int | None]):
        self.ops, self.owner = ops, owner
        self.new_ops: list[np.ndarray] = []
        self.new_programs: list[list[int]] = []
        self.cache: dict[tuple, list[int]] = {}

    def programs(self, listed: list[int], ticking: list[int]) -> list[int]:
        """One program per clock of ``ticking`` (in priority order) for the ops ``listed``
        (in the native order); -1 for a clock with nothing to run."""
        key = (tuple(listed), tuple(ticking))
        if key not in self.cache:
            access = [self.ops.access(i) for i in listed]
            parents = [[i for i in range(j) if access[i][1] & access[j][0] or access[i][0] & access[j][1]
                        or access[i][1] & access[j][1]] for j in range(len(listed))]
            taken = [False] * len(listed)
            out = []
            for k, c in enumerate(ticking):
                need = set()
                stack = [j for j in range(len(listed)) if not taken[j] and self.ops.owner(listed[j], self.owner) == c]
                if k == len(ticking) - 1:
                    stack = [j for j in range(len(listed)) if not taken[j]]
                while stack:
                    j = stack.pop()
                    if j in need or taken[j]:
                        continue
                    need.add(j)
                    stack.extend(parents[j])
                for j in need:
                    taken[j] = True
                out.append(self.emit([listed[j] for j in sorted(need)]))
            self.cache[key] = out
        return self.cache[key]

    def emit(self, ops: list[int]) -> int:
        if not ops:
            return -1
        t = self.ops.t
        first = len(t.ops) + len(self.new_ops)
        self.new_ops.extend(t.ops[i] for i in ops)
        self.new_programs.append([first, first + len(ops), -1])
        return len(t.programs) + len(self.new_programs) - 1

    def table(self) -> OpTable:
        t = self.ops.t
        if not self.new_programs:
            return t
        ops = np.vstack([t.ops, np.array(self.new_ops, dtype=np.int64)])
        programs = np.vstack([t.programs, np.array(self.new_programs, dtype=np.int64)])
        for a in (ops, programs):
            a.setflags(write=False)
        names = replace(t.names, programs=t.names.programs + tuple(f"partition {k}" for k in
                                                                   range(len(self.new_programs))))
        return replace(t, ops=ops, programs=programs, names=names)


def variable_clocks(partitions_: Partitions, table: OpTable, inputs, outputs) -> dict[int, int]:
    """Value reference -> its clock's, for the inputs only blocks of one clock read and the
    outputs a block of one clock computes."""
    names, t = table.names.blocks, table
    out: dict[int, int] = {}
    readers: dict[int, set] = {}
    ops = _Ops(table)
    for b, name in enumerate(names):
        for offset in ops.block_inputs(b):
            readers.setdefault(offset, set()).add(partitions_.owner[name])
    for v in inputs:
        found = set().union(*(readers.get(o, {None}) for o in v.offsets))
        if len(found) == 1 and None not in found:
            out[v.vr] = partitions_.clocks[found.pop()].vr
    for v in outputs:
        b = next(b for b in range(len(names))
                 if t.blocks[b, B_OUT] <= v.offsets[0] < t.blocks[b, B_OUT] + t.blocks[b, B_WIDTH])
        c = partitions_.owner[names[b]]
        if c is not None:
            out[v.vr] = partitions_.clocks[c].vr
    return out


def clocks_resource(p: Partitions, hyperperiod: int, magic: int, version: int) -> bytes:
    """``clocks.bin`` (``BLK_SCHEDULED_RESOURCE``): the clocks and their programs."""
    words = [magic, version, hyperperiod, len(p.clocks)]
    for c in p.clocks:
        words += [c.vr, c.period, c.offset, c.priority, c.initial, *c.hits]
    words.append(magic)
    return np.array(words, dtype="<i8").tobytes()
