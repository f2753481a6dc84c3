"""Rates to an integer tick plan: firing table, evaluation order and algebraic-loop check.

Everything that can be decided before a run is decided here, once:

- the base tick (gcd of all periods and offsets) and the hyperperiod (lcm of periods);
- which blocks fire at each tick of the hyperperiod; inherited periods are the union of
  the blocks feeding them;
- *lazy* blocks: stateless pure functions with an inherited period and no delayed input.
  Their output only changes when an input changes, so they are evaluated on demand at
  the ticks where a firing block reads them, which gives the same values as evaluating
  them at every source hit while keeping them from forcing extra events;
- *advanced* blocks: blocks with a fast ``advance`` and no feedthrough whose hits include
  every event tick (and more). Between two events nothing else fires, so they are
  stepped over the whole span in one call;
- for each distinct firing pattern, an ``EventProgram``: the output phase in feedthrough
  order, the update phase, delayed-connection sampling and the advances;
- the initial program (tick 0) orders outputs by ``initial_reads``. A dependency a block
  has only at tick 0 (its ``initial_feedthrough``) is *soft*: every soft dependency that
  lies on a cycle of the tick-0 graph is dropped, so that input holds its initial value at
  t = 0 (``Schedule.initial_held``), where a loop of ordinary dependencies is an error.
"""

from __future__ import annotations

import heapq
import math
import weakref
from collections import deque
from dataclasses import dataclass, field
from fractions import Fraction
from functools import reduce
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from blocks.builder.api_args import diagram_argument
from blocks.builder.diagram import Connection, Diagram
from blocks.issues import DiagramError, Issue
from blocks.timebase import format_duration, fraction_gcd, positive_duration

if TYPE_CHECKING:
    import networkx as nx

MAX_HYPERPERIOD_TICKS = 10_000_000

Steps = tuple[tuple[str, tuple[str, ...] | None], ...]
"""An output phase: (block, the ports to compute or None for all of them), in order."""


class HeldInput(NamedTuple):
    """An input that holds its initial value (its default) when its block's outputs are
    computed at t = 0, because the block's initial feedthrough from it would close ``loop``
    (the port chain from the block's output back to this input)."""

    block: str
    port: str
    loop: str


@dataclass(frozen=True)
class EventProgram:
    """What the executor does at one kind of event tick, in order."""

    firing: frozenset[str]
    evaluate: Steps
    update: tuple[str, ...]
    sample: tuple[int, ...]
    advance: tuple[str, ...]
    final: bool = False
    held: tuple[HeldInput, ...] = ()
    """Initial-feedthrough inputs this (initial) program evaluates before their source."""

    def describe(self) -> str:
        def step(b: str, ports: tuple[str, ...] | None) -> str:
            return b if ports is None else f"{b}[{','.join(ports)}]"

        parts = [f"outputs: {', '.join(step(b, p) for b, p in self.evaluate) or '-'}"]
        if not self.final:
            parts.append(f"updates: {', '.join(self.update) or '-'}")
            if self.advance:
                parts.append(f"advance to next event: {', '.join(self.advance)}")
        return "; ".join(parts)


@dataclass
class Schedule:
    """The tick plan of a diagram for a run of ``n_ticks`` base ticks (None: unknown yet)."""

    base_tick: Fraction
    hyperperiod: int
    n_ticks: int | None
    period_ticks: dict[str, int | None]
    offset_ticks: dict[str, int]
    masks: dict[str, np.ndarray]
    fires_at_zero: dict[str, bool]
    lazy: frozenset[str]
    advanced: frozenset[str]
    event_ticks: np.ndarray
    event_programs: list[int]
    programs: list[EventProgram]
    initial: EventProgram
    delayed: list[Connection] = field(default_factory=list)
    final: EventProgram | None = None

    @property
    def initial_held(self) -> tuple[HeldInput, ...]:
        """The inputs that hold their initial value at t = 0 although their block's initial
        outputs read them: their dependency was dropped to break a loop at tick 0."""
        return self.initial.held

    def hits(self, block: str, n_ticks: int) -> np.ndarray:
        """All ticks in [0, n_ticks] at which ``block`` fires (its sample times / base tick)."""
        return self.nth_hits(block, np.arange(self.hit_count(block, n_ticks)))

    def nth_hits(self, block: str, indices: np.ndarray) -> np.ndarray:
        """The ticks of the block's hits numbered ``indices`` (0: its first hit), in closed form.

        Decimated logs ask for every n-th hit only, so a long run never lists all of them.
        """
        indices = np.asarray(indices, dtype=np.int64)
        mask = self.masks[block]
        rel = np.flatnonzero(mask)
        extra_zero = self.fires_at_zero[block] and not mask[0]
        if rel.size == 0:
            return np.zeros(indices.shape, dtype=np.int64)
        j = indices - 1 if extra_zero else indices
        ticks = rel[j % rel.size] + self.hyperperiod * (j // rel.size)
        return np.where(j < 0, 0, ticks).astype(np.int64)

    def sample_times(self, block: str, count: int, decimate: int = 1) -> np.ndarray:
        """The times in seconds of the block's hits numbered 0, decimate, 2 decimate, ...
        (``count`` of them): ``tick * num / den`` of each hit's tick, as float64. A block
        whose hits are evenly spaced gets them without listing its ticks as integers
        (the same values: each ``tick * num`` is exact in double, run lengths keep it so)."""
        num, den = self.base_tick.numerator, self.base_tick.denominator
        spacing = self._spacing(block)
        if spacing is None:
            return self.nth_hits(block, np.arange(count) * decimate) * num / den
        first, step = spacing
        times = np.arange(count, dtype=np.float64)
        times *= step * decimate * num
        if first:
            times += first * num
        times /= den
        return times

    def _spacing(self, block: str) -> tuple[int, int] | None:
        """(first, step) when the block's hits are the ticks first + step * i, i >= 0."""
        mask = self.masks[block]
        rel = np.flatnonzero(mask)
        if rel.size == 0:
            return None
        step = self.hyperperiod // rel.size
        if step * rel.size != self.hyperperiod or np.any(rel != rel[0] + step * np.arange(rel.size)):
            return None
        if self.fires_at_zero[block] and not mask[0]:
            return (0, step) if rel[0] == step else None
        return int(rel[0]), step

    def hit_count(self, block: str, n_ticks: int) -> int:
        """How many ticks in [0, n_ticks] ``block`` fires at, without listing them."""
        mask = self.masks[block]
        cycles, rest = divmod(n_ticks, self.hyperperiod)
        count = cycles * int(mask.sum()) + int(mask[:rest + 1].sum())
        return count + (1 if self.fires_at_zero[block] and not mask[0] else 0)

    def next_hit(self, block: str, tick: int) -> int | None:
        """The first tick after ``tick`` at which ``block`` fires; None if it never fires again."""
        if not self.masks[block].any():
            return None
        return int(self.nth_hits(block, np.array([self.hit_count(block, tick)]))[0])

    def rate_text(self, block: str) -> str:
        p = self.period_ticks[block]
        if p is not None:
            text = format_duration(p * self.base_tick)
            if self.offset_ticks[block]:
                text += f" + {format_duration(self.offset_ticks[block] * self.base_tick)}"
            return text
        if not self.masks[block].any():
            return "t = 0 only (inherited)"
        return "inherited" + (", lazy" if block in self.lazy else "")


_plans: dict[int, dict[Fraction | None, Schedule]] = {}
"""Schedules already built: by diagram (its id, while it lives), then by end time."""


def build_schedule(diagram: Diagram, t_end: Fraction | None, *, advance: bool = True) -> Schedule:
    """Plan a run of ``diagram`` to ``t_end`` (None: check everything that does not need it);
    ``advance=False``: no block is advanced over spans (every hit an event of its own, as a
    scheduled-execution FMU runs it; such a plan is not kept).

    A Diagram is not changed after loading, so a plan once built is kept for the next
    call with the same end time (loading plans a diagram, then ``simulate``, ``validate``
    and sweeps ask again). The plans are held here, not on the Diagram, which stays pure
    data; they go when their diagram is garbage collected.
    """
    diagram_argument(diagram)
    if t_end is not None:
        t_end = positive_duration(t_end, "t_end")
    if not advance:
        return _Planner(diagram).plan(t_end, advance=False)
    plans = _plans.get(id(diagram))
    if plans is None:
        plans = _plans[id(diagram)] = {}
        weakref.finalize(diagram, _plans.pop, id(diagram), None)
    plan = plans.get(t_end)
    if plan is None:
        plan = plans[t_end] = _Planner(diagram).plan(t_end)
    return plan


def final_program(diagram: Diagram, schedule: Schedule, tick: int) -> EventProgram:
    """The last program of a run that ends at ``tick`` rather than at ``schedule.n_ticks``
    (a block ended it): the outputs of the blocks that fire there, no updates."""
    firing = _firing_at(schedule.masks, schedule.lazy, tick)
    return _Planner(diagram).program(firing, schedule.lazy, schedule.advanced, final=True)


def initial_outputs_program(diagram: Diagram, schedule: Schedule) -> EventProgram:
    """The outputs at t = 0 alone, without the initial program's updates: what an exported
    FMU's outputs are before its first step."""
    firing0 = frozenset(n for n in diagram.blocks
                        if n not in schedule.lazy and (schedule.masks[n][0] or schedule.fires_at_zero[n]))
    return _Planner(diagram).program(firing0, schedule.lazy, schedule.advanced, final=True, initial=True)


def between_program(diagram: Diagram, schedule: Schedule) -> EventProgram:
    """The outputs at a tick between events where every advanced block has a hit (their
    advances stop and start again there, as a communication point of an exported FMU):
    the lazy blocks those read."""
    return _Planner(diagram).program(schedule.advanced, schedule.lazy, schedule.advanced, final=True)


def lazy_outputs_program(diagram: Diagram, schedule: Schedule, blocks: set[str]) -> EventProgram:
    """The outputs of the lazy blocks among ``blocks`` and of the lazy blocks they read:
    their values at any tick, computed when something outside the diagram reads them."""
    planner = _Planner(diagram)
    demanded: set[str] = set()
    stack = [b for b in blocks if b in schedule.lazy]
    while stack:
        b = stack.pop()
        if b not in demanded:
            demanded.add(b)
            stack.extend(s for s in planner.sources[b] if s in schedule.lazy)
    evaluate, _ = planner.order_outputs(demanded)
    return EventProgram(frozenset(), evaluate, (), (), (), final=True)


def _firing_at(masks: dict[str, np.ndarray], lazy: frozenset[str], tick: int) -> frozenset[str]:
    """The blocks other than lazy ones whose periodic firing includes ``tick`` (so not the
    blocks that fire at t = 0 only)."""
    return frozenset(n for n, mask in masks.items() if n not in lazy and mask[tick % mask.size])


class _Planner:
    def __init__(self, diagram: Diagram):
        self.d = diagram
        self.order = {name: i for i, name in enumerate(diagram.blocks)}
        self.sources: dict[str, set[str]] = {b: set() for b in diagram.blocks}
        for c in diagram.connections:
            self.sources[c.dst_block].add(c.src_block)
        self.inherit_to: dict[str, dict[str, None]] = {b: {} for b in diagram.blocks}
        """For each block, the blocks without a period that read it (in connection order)."""
        for c in diagram.connections:
            if diagram.blocks[c.dst_block].period is None:
                self.inherit_to[c.src_block][c.dst_block] = None

    def fail(self, line: int | None, message: str, hint: str = "", file: str | None = None) -> None:
        raise DiagramError([Issue(file or self.d.file, line, message, hint)])

    def plan(self, t_end: Fraction | None, advance: bool = True) -> Schedule:
        d = self.d
        explicit = {n: s for n, s in d.blocks.items() if s.period is not None}
        for name, spec in d.blocks.items():
            if spec.period is None and spec.block.time_varying and not self.sources[name]:
                self.fail(spec.line, f"block '{name}' ({spec.type_name}) changes with time and has no "
                          "inputs to inherit a period from", f"give block '{name}' a period", spec.file)
        times = [s.period for s in explicit.values()] + [s.offset for s in explicit.values() if s.offset]
        if times:
            base = fraction_gcd(times)
        else:
            base = t_end if t_end else Fraction(1)
        period_ticks = {n: (int(s.period / base) if s.period is not None else None) for n, s in d.blocks.items()}
        offset_ticks = {n: int(s.offset / base) for n, s in d.blocks.items()}
        hyper = reduce(math.lcm, (p for p in period_ticks.values() if p), 1)
        if hyper > MAX_HYPERPERIOD_TICKS:
            self.fail(None, f"the hyperperiod is {hyper} base ticks of {format_duration(base)}: the "
                      "periods are too incommensurate", "choose periods that are simple multiples of "
                      "each other (e.g. 0.1 ms, 1 ms, 10 ms)")
        n_ticks = None
        if t_end is not None:
            ratio = t_end / base
            if ratio.denominator != 1:
                self.fail(d.t_end_line, f"t_end = {format_duration(t_end)} is not a multiple of the base "
                          f"tick {format_duration(base)}",
                          f"use a multiple of {format_duration(base)}, e.g. "
                          f"{format_duration(math.ceil(ratio) * base)}")
            n_ticks = int(ratio)
        masks, at_zero = self.fire_sets(period_ticks, offset_ticks, hyper)
        logged = {e.block for e in d.log}
        delayed_into = {c.dst_block for c in d.connections if c.delay}
        lazy = frozenset(
            n for n, s in d.blocks.items()
            if s.period is None and not s.block.is_stateful() and not s.block.time_varying
            and n not in delayed_into and n not in logged and masks[n].any())
        advanced = (self.advanced_blocks(masks, period_ticks, offset_ticks, lazy, delayed_into, n_ticks)
                    if advance else frozenset())
        events = np.zeros(hyper, dtype=bool)
        for n in d.blocks:
            if n not in lazy and n not in advanced:
                events |= masks[n]
        event_ticks = np.flatnonzero(events)
        programs: list[EventProgram] = []
        index: dict[frozenset[str], int] = {}
        event_programs = []
        for r in event_ticks:
            firing = _firing_at(masks, lazy, r)
            if firing not in index:
                index[firing] = len(programs)
                programs.append(self.program(firing, lazy, advanced, final=False))
            event_programs.append(index[firing])
        self.check_loops(masks, at_zero, lazy)
        firing0 = frozenset(n for n in d.blocks if n not in lazy and (masks[n][0] or at_zero[n]))
        initial = self.program(firing0, lazy, advanced, final=n_ticks == 0, initial=True)
        final = None
        if n_ticks:
            final = self.program(_firing_at(masks, lazy, n_ticks), lazy, advanced, final=True)
        return Schedule(base, hyper, n_ticks, period_ticks, offset_ticks, masks, at_zero, lazy,
                        advanced, event_ticks, event_programs, programs, initial,
                        [c for c in d.connections if c.delay], final)

    def check_loops(self, masks, at_zero, lazy) -> None:
        """Reject algebraic loops among all blocks that fire together, lazy ones included
        (a loop of lazy blocks nobody reads is never evaluated, but is still an error);
        at tick 0 through the blocks' initial dependencies."""
        if not lazy:
            return
        patterns = {frozenset(n for n in self.d.blocks if masks[n][r])
                    for r in np.flatnonzero(reduce(np.logical_or, (masks[n] for n in lazy)))}
        for together in patterns:
            self.order_outputs(set(together))
        self.order_outputs({n for n in self.d.blocks if masks[n][0] or at_zero[n]}, initial=True)

    def fire_sets(self, period_ticks, offset_ticks, hyper):
        """Periodic firing mask over one hyperperiod, and 'fires at t = 0', for every block.

        An inherited block fires when any of its sources does, so its mask is the union of
        theirs and it fires at t = 0 if one of them does. Both are propagated along the
        wires with a work list, which touches each wire once per change of its source
        instead of sweeping every block until nothing changes (quadratic on a long chain).
        """
        masks: dict[str, np.ndarray] = {}
        at_zero: dict[str, bool] = {}
        for n in self.d.blocks:
            mask = np.zeros(hyper, dtype=bool)
            if period_ticks[n] is not None:
                mask[offset_ticks[n]::period_ticks[n]] = True
                at_zero[n] = offset_ticks[n] == 0
            else:
                at_zero[n] = True
            masks[n] = mask
        work = deque(n for n in self.d.blocks if masks[n].any())
        while work:
            s = work.popleft()
            for n in self.inherit_to[s]:
                mask = masks[n] | masks[s]
                if not np.array_equal(mask, masks[n]):
                    masks[n] = mask
                    work.append(n)
        # an inherited block with sources misses t = 0 once all of them do
        waiting = {n: len(self.sources[n]) for n in self.d.blocks if period_ticks[n] is None}
        work = deque(n for n in self.d.blocks if not at_zero[n])
        while work:
            s = work.popleft()
            for n in self.inherit_to[s]:
                waiting[n] -= 1
                if not waiting[n]:
                    at_zero[n] = False
                    work.append(n)
        return masks, at_zero

    def advanced_blocks(self, masks, period_ticks, offset_ticks, lazy, delayed_into, n_ticks):
        d = self.d
        candidates = [
            n for n, s in d.blocks.items()
            if s.block.has_fast_advance() and not s.block.has_feedthrough() and period_ticks[n]
            and offset_ticks[n] == 0 and s.block.is_stateful() and n not in delayed_into
            and (n_ticks is None or n_ticks % period_ticks[n] == 0)]
        upstream = {n: self.upstream_through(n, lazy) for n in candidates}
        chosen: dict[str, None] = {}
        feeding_chosen: set[str] = set()
        for n in candidates:
            if n in upstream[n] or n in feeding_chosen or any(u in chosen for u in upstream[n]):
                continue
            chosen[n] = None
            feeding_chosen |= upstream[n]
        while True:
            events = np.zeros_like(next(iter(masks.values())))
            for n in d.blocks:
                if n not in lazy and n not in chosen:
                    events |= masks[n]
            bad = {n for n in chosen if np.any(events & ~masks[n])}
            if not bad:
                return frozenset(n for n in chosen if not np.array_equal(events, masks[n]))
            chosen = {n: None for n in chosen if n not in bad}

    def upstream_through(self, block: str, lazy: frozenset[str]) -> set[str]:
        """Non-lazy blocks whose outputs reach ``block``'s inputs directly or via lazy blocks."""
        seen: set[str] = set()
        stack = list(self.sources[block])
        out: set[str] = set()
        while stack:
            s = stack.pop()
            if s in seen:
                continue
            seen.add(s)
            if s in lazy:
                stack.extend(self.sources[s])
            else:
                out.add(s)
        return out

    def program(self, firing: frozenset[str], lazy, advanced, final: bool,
                initial: bool = False) -> EventProgram:
        d = self.d
        stepped = firing - advanced if not initial else firing
        readers = firing if final else firing | advanced
        demanded: set[str] = set()
        stack = [s for r in readers for s in self.sources[r]]
        while stack:
            s = stack.pop()
            if s in lazy and s not in demanded:
                demanded.add(s)
                stack.extend(self.sources[s])
        evaluate, held = self.order_outputs(set(stepped) | demanded, initial)
        by_order = sorted(firing, key=self.order.get)
        if final:
            return EventProgram(firing, evaluate, (), (), (), final=True, held=held)
        update = tuple(n for n in by_order if n not in advanced and d.blocks[n].block.is_stateful())
        sample = tuple(i for i, c in enumerate(d.connections) if c.delay and c.dst_block in firing)
        sample = tuple(sorted(sample))
        adv = tuple(n for n in by_order if n in advanced)
        return EventProgram(firing, evaluate, update, sample, adv, held=held)

    def feeds(self, nodes: set[str], initial: bool = False):
        """Same-tick dependencies among ``nodes``: the connections whose destination reads its
        source at the same tick (at tick 0 when ``initial``)."""
        for c in self.d.connections:
            if c.delay or c.src_block not in nodes or c.dst_block not in nodes:
                continue
            dst = self.d.blocks[c.dst_block].block
            reads = dst.initial_reads if initial else dst.reads
            if any(c.dst_port in reads(p) for p in dst.outputs):
                yield c

    def order_outputs(self, nodes: set[str], initial: bool = False) -> tuple[Steps, tuple[HeldInput, ...]]:
        """Evaluation steps for ``nodes`` (block, ports or None for all) and the inputs held
        to break loops at tick 0 (``initial``); an algebraic loop is a DiagramError."""
        edges = {(c.src_block, c.dst_block) for c in self.feeds(nodes, initial)}
        order = self.topological_order(nodes, edges)
        if order is not None:
            return tuple((n, None) for n in order), ()
        return self.order_ports(nodes, initial)

    def topological_order(self, nodes: set[str], edges: set[tuple[str, str]]) -> list[str] | None:
        """``nodes`` in dependency order, among the ready ones always the first in diagram
        order (as ``networkx.lexicographical_topological_sort`` keyed by it); None when
        ``edges`` close a cycle."""
        waiting = dict.fromkeys(nodes, 0)
        after: dict[str, list[str]] = {}
        for src, dst in edges:
            waiting[dst] += 1
            after.setdefault(src, []).append(dst)
        rank = self.order
        ready = [(rank[n], n) for n, count in waiting.items() if count == 0]
        heapq.heapify(ready)
        order = []
        while ready:
            _, n = heapq.heappop(ready)
            order.append(n)
            for m in after.get(n, ()):
                waiting[m] -= 1
                if waiting[m] == 0:
                    heapq.heappush(ready, (rank[m], m))
        return order if len(order) == len(waiting) else None

    def order_ports(self, nodes: set[str], initial: bool) -> tuple[Steps, tuple[HeldInput, ...]]:
        """Port-level order for blocks whose outputs have different feedthrough, dropping
        the soft (initial-only) dependencies that lie on a cycle when ``initial``. Rare
        (most diagrams order by blocks, ``topological_order``), so networkx, a tenth of a
        second to import, is imported here."""
        import networkx as nx

        graph = nx.DiGraph()
        wires: dict[tuple, Connection] = {}
        soft: list[tuple] = []
        for n in sorted(nodes, key=self.order.get):
            blk = self.d.blocks[n].block
            for p in blk.outputs:
                graph.add_node(("o", n, p))
                hard = blk.reads(p)
                for q in sorted(blk.initial_reads(p) if initial else hard):
                    graph.add_edge(("i", n, q), ("o", n, p))
                    if q not in hard:
                        soft.append((("i", n, q), ("o", n, p)))
        for c in self.d.connections:
            if not c.delay and c.src_block in nodes and c.dst_block in nodes:
                edge = (("o", c.src_block, c.src_port), ("i", c.dst_block, c.dst_port))
                graph.add_edge(*edge)
                wires[edge] = c
        held = self.drop_soft_cycles(graph, soft) if soft else ()
        try:
            cycle = nx.find_cycle(graph)
        except nx.NetworkXNoCycle:
            cycle = None
        if cycle:
            start = min((i for i, e in enumerate(cycle) if e[0][0] == "o"),
                        key=lambda i: (self.order[cycle[i][0][1]], cycle[i][0][2]))
            cycle = cycle[start:] + cycle[:start]
            wire = next((wires[e] for e in cycle if e in wires), None)
            on_loop = dict.fromkeys(v[1] for _, v in cycle)
            remedies = [r for n in on_loop if (r := self.d.blocks[n].block.loop_remedy(n))]
            self.fail(wire.line if wire else None, f"algebraic loop: {_chain([cycle[0][0]] + [v for _, v in cycle])}",
                      "; ".join(["break it with a block without feedthrough (e.g. UnitDelay) or add "
                                 "'delay: 1' to one connection", *remedies]), wire.file if wire else None)
        out_nodes = [v for v in nx.lexicographical_topological_sort(
            graph, key=lambda v: (self.order[v[1]], v[0] == "o", v[2])) if v[0] == "o"]
        steps: list[tuple[str, list[str]]] = []
        for _, n, p in out_nodes:
            if steps and steps[-1][0] == n:
                steps[-1][1].append(p)
            else:
                steps.append((n, [p]))
        return tuple((n, tuple(ps)) for n, ps in steps), held

    def drop_soft_cycles(self, graph: nx.DiGraph, soft: list[tuple]) -> tuple[HeldInput, ...]:
        """Remove from ``graph`` every soft edge on a cycle (both ends in one strongly
        connected component), which leaves only cycles of hard edges; one ``HeldInput`` per
        block input that loses a dependency, with the loop it closed, in block order."""
        import networkx as nx

        component = {v: i for i, c in enumerate(nx.strongly_connected_components(graph)) for v in c}
        cut = [(u, v) for u, v in soft if component[u] == component[v]]
        held: dict[tuple[str, str], str] = {}
        for u, v in cut:
            if (u[1], u[2]) not in held:
                held[u[1], u[2]] = _chain(nx.shortest_path(graph, v, u))
        graph.remove_edges_from(cut)
        return tuple(HeldInput(b, q, loop) for (b, q), loop in held.items())


def _chain(ports) -> str:
    """A path of port nodes as text: ``a.y -> b.u -> b.y``."""
    return " -> ".join(f"{n}.{p}" for _, n, p in ports)
