"""The multirate executor: runs a Diagram's Schedule and returns Results.

Per event tick the executor runs a precompiled program: outputs of the firing blocks in
feedthrough order, then their updates, then the sampling of delayed connections, then
the advanced blocks stepped to the next event, each program written out as one Python
function (``_ProgramCode``). Blocks with compiled kernels run in C (``blocks.compiled``):
each stretch of their steps is one call, and consecutive events made only of such steps
are one call together. Outputs are passed by reference from a block's return value
into the persistent input mappings of the blocks it feeds (no per-tick dictionaries or
copies); between hits values hold. Time is ``k * base_tick`` from the integer tick ``k``.

A block ends a run early by raising ``EndRun`` from its ``update`` at tick k: the tick
is finished, the ticks up to the block's next hit run as usual, and that hit (or t_end,
if earlier) becomes the end: outputs only, logged, as at a normal end time. The run is
complete; ``info["ended_by"]`` says which block asked, when, why, and where it ended.
"""

from __future__ import annotations

import functools
import platform
import time
from fractions import Fraction
from importlib import metadata
from typing import Any, Callable, NamedTuple

import numpy as np

from .block import BlockError, EndRun, checked_units
from .compiled import CompiledSide, Runner
from .diagram import Diagram
from .issues import DiagramError
from .results import Results
from .schedule import EventProgram, Schedule, build_schedule, final_program
from .timebase import DurationError, format_duration, parse_duration

ADVANCE_CHUNK = 4096
"""At most this many hits per ``advance`` call, so output buffers stay small."""

MAX_LOG_BYTES = 4 * 2**30
"""A run refuses to start if its logs would need more memory than this."""

ProgressCallback = Callable[[float, float], None]
"""Called as ``progress(fraction_done, elapsed_wall_seconds)`` during a run."""


class SimulationError(Exception):
    """A block failed during a run; ``results`` holds everything computed before."""

    def __init__(self, message: str, results: Results, block: str, time: float, port: str | None):
        super().__init__(message)
        self.results = results
        self.block = block
        self.time = time
        self.port = port


class StopRequest(KeyboardInterrupt):
    """A request to stop a run early, like Ctrl-C, with a ``reason`` for the status
    (a program that turns SIGTERM into a stop raises ``StopRequest("SIGTERM")``)."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


class _StepFailure(Exception):
    def __init__(self, block: str, phase: str, tick: int, error: BaseException):
        super().__init__(str(error))
        self.block, self.phase, self.tick, self.error = block, phase, tick, error


def simulate(diagram: Diagram, t_end: Any = None, progress: ProgressCallback | None = None,
             raise_on_failure: bool = False) -> Results:
    """Run ``diagram`` to ``t_end`` (default: the diagram's ``time.t_end``).

    A block failure does not lose the run: the returned Results carry the signals up to
    the failure and ``status`` 'failed at t=...: ...' (or raise ``SimulationError``
    holding them when ``raise_on_failure``). A block that raises ``EndRun`` ends the run
    at its next hit; the Results are complete, with ``ended_by`` set when that was
    before ``t_end``.
    """
    if t_end is None:
        t_end = diagram.t_end
        if t_end is None:
            raise DiagramError([diagram.issue(None, "no end time given",
                                              "set time: {t_end: 1 s} in the diagram or pass t_end")])
    else:
        try:
            t_end = parse_duration(t_end)
        except DurationError as exc:
            raise DiagramError([diagram.issue(None, f"t_end: {exc}")]) from None
        if t_end <= 0:
            raise DiagramError([diagram.issue(None, f"t_end must be positive, got {t_end}")])
    refused = diagram.open_issue()
    if refused is not None:
        raise DiagramError([refused])
    schedule = build_schedule(diagram, t_end)
    log_bytes = sum(8 * diagram.width(e.signal) * -(-schedule.hit_count(e.block, schedule.n_ticks) // e.decimate)
                    for e in diagram.log)
    if log_bytes > MAX_LOG_BYTES:
        raise DiagramError([diagram.issue(None, f"the logged signals would take {log_bytes / 2**30:.3g} GiB "
                                          f"over t_end = {format_duration(t_end)}",
                                          "log fewer signals, add 'decimate: N' to log entries or "
                                          "shorten t_end")])
    results, failure = _Run(diagram, schedule, t_end).execute(progress)
    if failure is not None and raise_on_failure:
        raise failure
    return results


class _Logger:
    """Preallocated samples of one logged signal, honouring its decimation.

    Rows from ``advance`` are queued and copied in batches: one concatenation per
    ``BATCH`` advances costs far less than a slice assignment per advance.
    """

    BATCH = 64
    __slots__ = ("name", "buf", "pos", "hits", "decimate", "pending")

    def __init__(self, name: str, width: int, count: int, decimate: int):
        self.name = name
        self.buf = np.empty((count, width))
        self.pos = 0
        self.hits = 0
        self.decimate = decimate
        self.pending: list[np.ndarray] = []

    def add_source(self, code: _ProgramCode, value: str) -> list[str]:
        """Source lines of a generated program that log the output ``value`` (the name of
        a variable there): queued rows first, then every ``decimate``-th hit."""
        v = code.bind
        lg = v(self)
        store = [f"{v(self.buf)}[{lg}.pos] = {value}", f"{lg}.pos += 1"]
        if self.decimate != 1:
            store = [f"if {lg}.hits % {v(self.decimate)} == 0:", *("    " + line for line in store)]
        return [f"if {v(self.pending)}:", f"    {lg}.flush()", *store, f"{lg}.hits += 1"]

    def add_rows(self, rows: np.ndarray) -> None:
        pending = self.pending
        pending.append(rows)
        if len(pending) >= self.BATCH:
            self.flush()

    def add_rows_source(self, code: _ProgramCode, rows: str) -> list[str]:
        """Source lines of a generated program that do ``add_rows(rows)``."""
        v = code.bind
        pending = v(self.pending)
        return [f"{pending}.append({rows})", f"if len({pending}) >= {v(self.BATCH)}:",
                f"    {v(self)}.flush()"]

    def flush(self) -> None:
        """Copy the queued rows into the buffer."""
        rows = self.pending[0] if len(self.pending) == 1 else np.concatenate(self.pending)
        self.pending.clear()
        n, d, pos = rows.shape[0], self.decimate, self.pos
        first = -self.hits % d
        picked = rows[first::d] if d > 1 else rows
        self.buf[pos:pos + len(picked)] = picked
        self.pos = pos + len(picked)
        self.hits += n


class _ProgramCode:
    """An event program written out as Python functions ``run(k, next_k)``.

    Each step (a block's outputs, an update, a sample, an advance) is a few lines of
    source with its own ``try``, which costs nothing unless something is raised, so a
    failure is reported with its block, phase and tick. The source names no object and
    holds no text from the diagram: every block method, mapping, port name and block
    name is a variable ``vN`` of an enclosing factory, called with the objects
    themselves. Source of the same shape is compiled once (``_factory``): the programs of
    repeated runs, and the segments of a long program (``SEGMENT`` steps each, so a
    program of many blocks never makes one huge function), share their code.
    """

    SEGMENT = 64

    def __init__(self, base_tick: Fraction):
        self.tick = (base_tick.numerator, base_tick.denominator)
        self.segments: list[tuple[list[str], list[Any]]] = []
        self.count = 0
        self.start_segment()

    def start_segment(self) -> None:
        """Bind from now on into a new segment, whose variables count from v0."""
        self.lines: list[str] = []
        self.objects: list[Any] = []
        self.ids: dict[int, str] = {}
        self.segments.append((self.lines, self.objects))
        num, den = (self.bind(x) for x in self.tick)
        self.lines.append(f"t = k * {num} / {den}")

    def bind(self, obj: Any) -> str:
        """The variable that holds ``obj`` in the current segment's source."""
        key = id(obj)
        name = self.ids.get(key)
        if name is None:
            name = self.ids[key] = f"v{len(self.objects)}"
            self.objects.append(obj)
        return name

    def step(self, *lines: str, handlers: tuple[str, ...] = (), setup: tuple[str, ...] = ()) -> None:
        """One step: ``setup``, then ``lines`` in a ``try`` with ``handlers`` (except
        clauses) if given. The variables it uses must be bound before."""
        if handlers:
            lines = ("try:", *("    " + line for line in lines), *handlers)
        self.lines += setup + lines
        self.count += 1
        if self.count % self.SEGMENT == 0:
            self.start_segment()

    def function(self) -> Callable[[int, int], None]:
        segments = [self.compiled(lines, objects) for lines, objects in self.segments if len(lines) > 1]
        if len(segments) <= 1:
            return segments[0] if segments else self.compiled(*self.segments[0])

        def run(k: int, next_k: int) -> None:
            for segment in segments:
                segment(k, next_k)

        return run

    @staticmethod
    def compiled(lines: list[str], objects: list[Any]) -> Callable[[int, int], None]:
        source = (f"def factory({', '.join(f'v{j}' for j in range(len(objects)))}):\n"
                  "    def run(k, next_k):\n        " + "\n        ".join(lines) + "\n    return run\n")
        return _factory(source)(*objects)


@functools.lru_cache(maxsize=1024)
def _factory(source: str) -> Callable[..., Callable[[int, int], None]]:
    """Compile a ``_ProgramCode`` segment's source (generated, never from a user) once."""
    namespace: dict[str, Any] = {}
    exec(compile(source, "<event program>", "exec"), namespace)
    return namespace["factory"]


class _Compiled(NamedTuple):
    """An event program ready to run: ``function(k, next_k)``, and when every step of it
    is a compiled block's, those steps as ``(op, (block, phase))`` for fusing with the
    programs of the following events into one C call."""

    function: Callable[[int, int], None]
    kernel_steps: list[tuple[list[int], tuple[str, str]]] | None


class _Run:
    """The mutable side of one run: states, input mappings, held outputs and logs."""

    def __init__(self, diagram: Diagram, schedule: Schedule, t_end: Fraction):
        self.d = diagram
        self.s = schedule
        self.t_end = t_end
        self.n_ticks = schedule.n_ticks
        self.names = list(diagram.blocks)
        self.index = {n: i for i, n in enumerate(self.names)}
        self.states: list[Any] = [diagram.blocks[n].block.initial_state() for n in self.names]
        self.held: dict[str, dict[str, np.ndarray]] = {
            n: {p: np.zeros(w) for p, w in diagram.blocks[n].block.outputs.items()} for n in self.names}
        self.inputs: dict[str, dict[str, np.ndarray]] = {}
        for n in self.names:
            blk = diagram.blocks[n].block
            self.inputs[n] = {p: np.array(blk.input_defaults[p], dtype=float) if p in blk.input_defaults
                              else np.zeros(w) for p, w in blk.inputs.items()}
        self.fanout: dict[str, list[tuple[dict, str, str]]] = {n: [] for n in self.names}
        self.sampled: dict[str, set[str]] = {n: set() for n in self.names}
        for c in diagram.connections:
            if c.delay:
                self.sampled[c.src_block].add(c.src_port)
                width = diagram.blocks[c.dst_block].block.inputs[c.dst_port]
                init = np.zeros(width) if c.initial is None else np.broadcast_to(
                    np.asarray(c.initial, dtype=float), (width,)).copy()
                self.inputs[c.dst_block][c.dst_port] = init
            else:
                self.fanout[c.src_block].append((self.inputs[c.dst_block], c.dst_port, c.src_port))
        self.loggers: dict[str, list[_Logger]] = {n: [] for n in self.names}
        self.all_loggers: list[_Logger] = []
        for e in diagram.log:
            count = -(-schedule.hit_count(e.block, self.n_ticks) // e.decimate)
            lg = _Logger(e.signal, diagram.blocks[e.block].block.outputs[e.port], count, e.decimate)
            self.loggers[e.block].append(lg)
            self.all_loggers.append(lg)
        self.owner = {id(self.inputs[n]): n for n in self.names}
        """The block whose input mapping a fan-out target is (held outputs are no block's)."""
        self.compiled = CompiledSide(diagram, schedule, self.states, self.index, self.inputs, self.loggers,
                                     ADVANCE_CHUNK)
        self.python_readers: dict[str, list[tuple[dict, str, np.ndarray]]] = {n: [] for n in self.compiled.blocks}
        """Per compiled block, the inputs of Python blocks it feeds: (mapping, port, its buffer's view)."""
        for c in diagram.connections:
            if c.src_block in self.compiled.blocks and c.dst_block not in self.compiled.blocks and not c.delay:
                self.python_readers[c.src_block].append(
                    (self.inputs[c.dst_block], c.dst_port, self.compiled.blocks[c.src_block].views[c.src_port]))
        self.checked: set[str] = set()
        self.reached: int | None = None
        """The tick an interrupted advance span had logged, when the interrupt came in one."""
        self.end_tick = self.n_ticks
        """Where the run ends: t_end's tick, or earlier once a block has raised EndRun."""
        self.end_request: tuple[str, str, int] | None = None
        """The first EndRun: (block, reason, tick of the update that raised it)."""

    # -- building the per-event programs ------------------------------------------------

    def compile(self, program: EventProgram) -> _Compiled:
        """The program as one function ``run(k, next_k)``: its steps written out as Python
        source (``_ProgramCode``), each stretch of compiled blocks' steps one C call."""
        code = _ProgramCode(self.s.base_tick)
        kernel = self.compiled.blocks
        last_step = {b: i for i, (b, _) in enumerate(program.evaluate)}
        last = program.advance[-1] if program.advance else None
        pending: list[tuple[list[int], tuple[str, str]]] = []
        python = False

        def flush() -> None:
            if pending:
                ops, steps = [op for op, _ in pending], [step for _, step in pending]
                self.runner_step(code, self.compiled.runner([(0, ops, steps)], self.kernel_end),
                                 last in {b for b, _ in steps})
                pending.clear()

        for i, (b, ports) in enumerate(program.evaluate):
            log = b in program.firing and last_step[b] == i
            if b in kernel:
                pending.append((self.compiled.output_op(b, log), (b, "output")))
                pending.extend(self.compiled.forward_ops(b))
            else:
                flush()
                python = True
                self.output_step(code, b, ports, log)
        for b in program.update:
            if b in kernel:
                pending.append((self.compiled.update_op(b), (b, "update")))
            else:
                flush()
                python = True
                self.update_step(code, b)
        for i in program.sample:
            c = self.d.connections[i]
            if c.src_block in kernel and c.dst_block in kernel:
                pending.append((self.compiled.copy_op(c), (c.dst_block, "sample")))
            else:
                flush()
                python = True
                self.sample_step(code, c)
        for b in program.advance:
            if b in kernel:
                pending.append((self.compiled.advance_op(b), (b, "advance")))
                pending.extend(self.compiled.forward_ops(b))
            else:
                flush()
                python = True
                self.advance_step(code, b, last=b == last)
        steps = None if python else list(pending)
        flush()
        return _Compiled(code.function(), steps)

    def runner_step(self, code: _ProgramCode, runner: Runner, has_last_advance: bool) -> None:
        """One C call running a stretch of compiled steps; a failure raises its step's
        ``_StepFailure``. With the event's last advance in it, an interrupt records how far
        it got. Then the Python blocks that read the outputs computed there get copies of
        them (a copy: the buffers change in place, and a block may keep what it is given)."""
        v = code.bind
        handlers = ("except KeyboardInterrupt:", f"    {v(self.interrupted_in_runner)}({v(runner)}, k)",
                    "    raise") if has_last_advance else ()
        code.step(f"r = {v(runner.run)}(k, next_k)", handlers=handlers)
        code.step("if r is not None:", f"    raise {v(self.kernel_failure)}({v(runner)}, r)")
        computed = dict.fromkeys(b for b, phase in runner.steps if phase in ("output", "advance"))
        copies = [f"{v(d)}[{v(dp)}] = {v(view)}.copy()" for b in computed for d, dp, view in self.python_readers[b]]
        if copies:
            code.step(*copies)

    def kernel_failure(self, runner: Runner, result) -> _StepFailure:
        """The failure a C call returned; an interrupt a kernel raised is raised here, the
        run having reached its tick."""
        name, phase, tick, error = runner.failure(result)
        if isinstance(error, KeyboardInterrupt):
            self.reached = tick
            raise error
        return _StepFailure(name, phase, tick, error)

    def kernel_end(self, name: str, end: BaseException, tick: int) -> int:
        """A compiled update's request to end the run (``request_end``); returns where the
        run now ends. A kernel whose error factory gives no EndRun fails its update."""
        if not isinstance(end, EndRun):
            raise _StepFailure(name, "update", tick, end)
        self.request_end(name, end.reason, tick)
        return self.end_tick

    def interrupted_in_runner(self, runner: Runner, k: int) -> None:
        """An interrupt came during or right after a C call holding an event's last advance."""
        reached = runner.native.reached
        if reached >= k:
            self.reached = reached

    def target_line(self, code: _ProgramCode, d: dict, dp: str, value: str) -> str:
        """Pass ``value`` to input ``dp`` of the mapping ``d``: by reference to a Python
        block, copied into the input buffer of a compiled one."""
        v = code.bind
        owner = self.owner.get(id(d))
        if owner in self.compiled.blocks:
            return f"{v(self.compiled.buffers[owner, dp])}[:] = {value}"
        return f"{v(d)}[{v(dp)}] = {value}"

    def output_step(self, code: _ProgramCode, name: str, ports: tuple[str, ...] | None, log: bool) -> None:
        """Compute ``name``'s outputs (``ports``, or all), check them the first time, pass
        them by reference to their readers and log them when ``log``."""
        blk = self.d.blocks[name].block
        publish = tuple(blk.outputs) if ports is None else ports
        targets = self.hold_targets(name, publish) + [f for f in self.fanout[name] if f[2] in publish]
        loggers = [(lg, lg.name.rsplit(".", 1)[1]) for lg in self.loggers[name]] if log else []
        v = code.bind
        block = v(name)
        value: dict[str, str] = {}
        lines = [f"out = {v(blk.output)}(t, {v(self.states)}[{v(self.index[name])}], {v(self.inputs[name])})",
                 f"if {block} not in {v(self.checked)}:",
                 f"    {v(self.check_outputs)}({block}, out, {v(publish)})"]
        for port in [sp for _, _, sp in targets] + [p for _, p in loggers]:
            if port not in value:
                value[port] = f"o{len(value)}"
                lines.append(f"{value[port]} = out[{v(port)}]")
        lines += [self.target_line(code, d, dp, value[sp]) for d, dp, sp in targets]
        for lg, p in loggers:
            lines += lg.add_source(code, value[p])
        code.step(*lines, handlers=("except Exception as exc:",
                                    f"    raise {v(_StepFailure)}({block}, 'output', k, exc) from exc"))

    def hold_targets(self, name: str, ports) -> list[tuple[dict, str, str]]:
        """Where a block's new outputs must also be kept: only the ports that delayed
        connections sample (everything else reaches its readers through the fan-out)."""
        sampled = self.sampled[name]
        return [(self.held[name], p, p) for p in ports if p in sampled]

    def update_step(self, code: _ProgramCode, name: str) -> None:
        """Update ``name``'s state; an ``EndRun`` asks for the end and the tick goes on."""
        v = code.bind
        state = f"{v(self.states)}[{v(self.index[name])}]"
        update = f"{v(self.d.blocks[name].block.update)}(t, {state}, {v(self.inputs[name])})"
        code.step(f"{state} = {update}",
                  handlers=(f"except {v(EndRun)} as end:",
                            "    if end.has_state:",
                            f"        {state} = end.state",
                            f"    {v(self.request_end)}({v(name)}, end.reason, k)",
                            "except Exception as exc:",
                            f"    raise {v(_StepFailure)}({v(name)}, 'update', k, exc) from exc"))

    def request_end(self, name: str, reason: str, k: int) -> None:
        """Record a block's EndRun at tick ``k``: the run ends at the block's next hit, or
        t_end if that comes first. When several blocks ask, the first one asking is the
        one reported and the earliest of their ends is the end."""
        if self.end_request is None:
            self.end_request = (name, reason, k)
        nxt = self.s.next_hit(name, k)
        if nxt is not None and nxt < self.end_tick:
            self.end_tick = nxt

    def sample_step(self, code: _ProgramCode, c) -> None:
        """A delayed connection takes the value its source holds now (a copy, from a
        compiled block's buffer)."""
        v = code.bind
        compiled = self.compiled.blocks
        if c.src_block in compiled:
            source = f"{v(compiled[c.src_block].views[c.src_port])}.copy()"
        else:
            source = f"{v(self.held[c.src_block])}[{v(c.src_port)}]"
        code.step(self.target_line(code, self.inputs[c.dst_block], c.dst_port, source))

    def advance_step(self, code: _ProgramCode, name: str, last: bool) -> None:
        """Steps ``name`` to the next event in chunks, each from the time of its first
        tick (``tick * base_tick``, as at events, never a sum of periods), logging each
        chunk's rows (queued as ``_Logger.add_rows`` does) and passing on the last row.
        An interrupt in the span records how far the last advanced block of the event got
        (the earlier ones are further, the later ones still at the event): every block was
        computed up to there."""
        blk = self.d.blocks[name].block
        v = code.bind
        period = v(self.s.period_ticks[name])
        num, den = (v(x) for x in code.tick)
        state = f"{v(self.states)}[{v(self.index[name])}]"
        ports = tuple(blk.outputs)
        by_port: dict[str, list[tuple[dict, str]]] = {}
        for d, dp, sp in self.hold_targets(name, ports) + self.fanout[name]:
            by_port.setdefault(sp, []).append((d, dp))
        loggers = [(lg.add_rows, lg.name.rsplit(".", 1)[1]) for lg in self.loggers[name]]
        lines = ["while n > 0:",
                 f"    m = n if n <= {v(ADVANCE_CHUNK)} else {v(ADVANCE_CHUNK)}",
                 f"    {state}, rows = {v(blk.advance)}((k + done * {period}) * {num} / {den}, {state}, "
                 f"{v(self.inputs[name])}, m)",
                 f"    if {v(name + ':advance')} not in {v(self.checked)}:",
                 f"        {v(self.check_rows)}({v(name)}, rows, {v(ports)}, m)"]
        for lg in self.loggers[name]:
            rows = f"rows[{v(lg.name.split('.', 1)[1])}]"
            lines += ["    " + line for line in lg.add_rows_source(code, rows)]
        lines += ["    n -= m", "    done += m"]
        for p, dests in by_port.items():
            lines.append(f"value = rows[{v(p)}][-1]")
            lines += [self.target_line(code, d, dp, "value") for d, dp in dests]
        code.step(*lines, setup=(f"n = (next_k - k) // {period}", "done = 0"),
                  handlers=(
            "except KeyboardInterrupt:",
            *([f"    {v(self.interrupted_in_span)}({v(name)}, k + done * {period})"] if last else []),
            "    raise",
            "except Exception as exc:",
            f"    done += {v(self.log_partial_rows)}({v(name)}, exc, {v(ports)}, {v(loggers)})",
            f"    raise {v(_StepFailure)}({v(name)}, 'advance', k + done * {period}, exc) from exc"))

    def interrupted_in_span(self, name: str, counted: int) -> None:
        """An interrupt came while the event's last advanced block stepped its span."""
        self.reached = self.logged_tick(name, counted)

    def logged_tick(self, name: str, counted: int) -> int:
        """The tick of the last hit of ``name`` that its logs hold, which is where its data
        reach even when an interrupt fell between logging a chunk and counting it;
        ``counted`` when nothing of it is logged."""
        hits = max((lg.hits + sum(len(rows) for rows in lg.pending) for lg in self.loggers[name]), default=0)
        return int(self.s.nth_hits(name, np.array([hits - 1]))[0]) if hits else counted

    def check_outputs(self, name: str, out: Any, ports: tuple[str, ...]) -> None:
        blk = self.d.blocks[name].block
        if not isinstance(out, dict):
            raise BlockError(f"output() returned {type(out).__name__}, expected a dict of port arrays")
        for p in ports:
            v = out.get(p)
            if not (isinstance(v, np.ndarray) and v.shape == (blk.outputs[p],) and v.dtype == np.float64):
                got = f"shape {v.shape} {v.dtype}" if isinstance(v, np.ndarray) else repr(type(v).__name__)
                raise BlockError(f"output '{p}' must be a float64 array of shape ({blk.outputs[p]},), got {got}",
                                 port=p)
        self.checked.add(name)

    def log_partial_rows(self, name: str, exc: Exception, ports: tuple[str, ...], loggers) -> int:
        """Log the rows a failing ``advance`` completed (``BlockError.rows``); returns how many."""
        rows = exc.rows if isinstance(exc, BlockError) else None
        if not isinstance(rows, dict) or not ports or not isinstance(rows.get(ports[0]), np.ndarray):
            return 0
        m = rows[ports[0]].shape[0]
        try:
            self.check_rows(name, rows, ports, m)
        except BlockError:
            return 0
        for add, p in loggers:
            add(rows[p])
        return m

    def check_rows(self, name: str, rows: Any, ports: tuple[str, ...], n: int) -> None:
        blk = self.d.blocks[name].block
        for p in ports:
            v = rows.get(p) if isinstance(rows, dict) else None
            if not (isinstance(v, np.ndarray) and v.shape == (n, blk.outputs[p])):
                raise BlockError(f"advance() output '{p}' must have shape ({n}, {blk.outputs[p]})", port=p)
        self.checked.add(name + ":advance")

    # -- running ----------------------------------------------------------------------

    def spans(self) -> list[tuple[int, int, Callable[[int, int], None]]]:
        """The events of one hyperperiod after tick 0 as ``(k, next_k, program)``: each
        event's tick, the next event's tick and its compiled program; those of later
        hyperperiods are these shifted by whole hyperperiods."""
        ticks = [int(x) for x in self.s.event_ticks]
        if not ticks:
            return []
        compiled = [self.compile(p) for p in self.s.programs]
        progs = [compiled[j] for j in self.s.event_programs]
        hyper = self.s.hyperperiod
        pairs = list(zip(ticks, progs))
        if ticks[0] == 0:
            pairs = pairs[1:] + [(ticks[0] + hyper, progs[0])]
        following = [k for k, _ in pairs[1:]] + [pairs[0][0] + hyper]
        spans = []
        i = 0
        while i < len(pairs):
            j = i + 1
            if pairs[i][1].kernel_steps is not None:
                while j < len(pairs) and pairs[j][1].kernel_steps is not None:
                    j += 1
            if j - i > 1:
                spans.append((pairs[i][0], following[j - 1], self.fused(pairs[i:j])))
            else:
                spans.append((pairs[i][0], following[i], pairs[i][1].function))
            i = j
        return spans

    def fused(self, pairs: list[tuple[int, _Compiled]]) -> Callable[[int, int], None]:
        """Consecutive events whose steps are all compiled, as one C call from the first
        event's tick: each event at its offset, its advances stepping to the next one."""
        first = pairs[0][0]
        events = [(k - first, [op for op, _ in c.kernel_steps], [step for _, step in c.kernel_steps])
                  for k, c in pairs]
        code = _ProgramCode(self.s.base_tick)
        self.runner_step(code, self.compiled.runner(events, self.kernel_end), has_last_advance=True)
        return code.function()

    def execute(self, progress: ProgressCallback | None) -> tuple[Results, SimulationError | None]:
        """Run ticks 0 .. end. Progress is the fraction of t_end reached, so a run that a
        block ends early stops short of 1."""
        n = total = self.n_ticks
        wall0 = time.perf_counter()
        failure: _StepFailure | None = None
        interrupted: KeyboardInterrupt | None = None
        labels: dict[str, list[str]] = {}
        units: dict[str, str | list[str]] = {}
        k = 0
        initial = self.compile(self.s.initial).function
        try:
            if self.compiled.failure is not None:
                name, exc = self.compiled.failure
                raise _StepFailure(name, "kernel", 0, exc)
            labels = self.element_labels()
            units = self.port_units()
            spans = self.spans()
            initial(0, min(spans[0][0], n) if spans else n)
            n = self.end_tick
            count = base = 0
            running = bool(spans)
            while running:
                for first, following, prog in spans:
                    k = base + first
                    if k >= n:
                        running = False
                        break
                    nk = base + following
                    prog(k, nk if nk < n else n)
                    n = self.end_tick
                    count += 1
                    if progress is not None and count & 255 == 0:
                        progress(k / total, time.perf_counter() - wall0)
                base += self.s.hyperperiod
            k = n
            final = self.s.final if n == total else final_program(self.d, self.s, n)
            self.compile(final).function(n, n)
        except _StepFailure as exc:
            failure = exc
        except KeyboardInterrupt as exc:
            interrupted = exc
            self.compiled.sync_logs()
            if self.reached is not None:
                k = max(k, self.reached)
        self.compiled.sync_logs()
        wall = time.perf_counter() - wall0
        if progress is not None and failure is None and interrupted is None:
            progress(n / total, wall)
        t_fail = float((failure.tick if failure is not None else k) * self.s.base_tick)
        ended_by = None
        if failure is not None:
            status = self.failure_status(failure, t_fail)
        elif interrupted is not None:
            by = f" by {interrupted.reason}" if isinstance(interrupted, StopRequest) else ""
            status = f"interrupted at t={t_fail:.9g} s{by}"
        else:
            status = "complete"
            if n < total:
                ended_by = self.ended_by(n)
        if status != "complete":
            t_stop = t_fail
        else:
            t_stop = None if ended_by is None else ended_by["time"]
        info = self.info(status, wall, t_stop, ended_by, labels, units)
        results = Results(self.collect_through_interrupt(), info)
        if failure is not None:
            return results, SimulationError(status, results, failure.block, t_fail,
                                            getattr(failure.error, "port", None))
        return results, None

    def failure_status(self, failure: _StepFailure, t_fail: float) -> str:
        """'failed at t=...: block 'b' (Type), signal b.y phase: message'."""
        err = failure.error
        port = getattr(err, "port", None)
        spec = self.d.blocks[failure.block]
        signal = f", signal {failure.block}.{port}" if port else ""
        message = (f"EndRun must be raised from update, not {failure.phase} ({err.reason})"
                   if isinstance(err, EndRun) else err)
        return (f"failed at t={t_fail:.9g} s: block '{failure.block}' ({spec.type_name}){signal} "
                f"{failure.phase}: {message}")

    def ended_by(self, end: int) -> dict[str, Any]:
        """run.json's record of the EndRun that ended the run at tick ``end``."""
        name, reason, asked = self.end_request
        tick = self.s.base_tick
        return {"block": name, "type": self.d.blocks[name].type_name, "time": float(end * tick),
                "tick_time": float(asked * tick), "reason": reason}

    def element_labels(self) -> dict[str, list[str]]:
        """The element names of the logged signals whose blocks name them
        (``Block.element_labels``), checked once at the start: one label per element."""
        return self.logged_port_info("element_labels", _labels_of)

    def port_units(self) -> dict[str, str | list[str]]:
        """The units of the logged signals whose blocks know them (``Block.port_units``),
        checked once at the start: a string, or one string per element."""
        return self.logged_port_info("port_units", _units_of)

    def logged_port_info(self, phase: str, read: Callable[[Any, Any], Any]) -> dict[str, Any]:
        """What ``read(block, log_entry)`` says of each logged signal (None: nothing), asked
        once at the start; what it raises fails the run at t = 0 in that block's ``phase``."""
        found = {}
        for e in self.d.log:
            try:
                value = read(self.d.blocks[e.block].block, e)
            except Exception as exc:
                raise _StepFailure(e.block, phase, 0, exc) from exc
            if value is not None:
                found[e.signal] = value
        return found

    def collect_through_interrupt(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """``collect``, once more if an interrupt cuts it short: the signals are all there
        is of the run (a program that defers later interrupts lets the second try finish)."""
        try:
            return self.collect()
        except KeyboardInterrupt:
            return self.collect()

    def collect(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        for lg in self.all_loggers:
            if lg.pending:
                lg.flush()
        tick = self.s.base_tick
        signals = {}
        for e, lg in zip(self.d.log, self.all_loggers):
            ticks = self.s.nth_hits(e.block, np.arange(lg.pos) * e.decimate)
            signals[e.signal] = (ticks * tick.numerator / tick.denominator, lg.buf[:lg.pos].copy())
        return signals

    def info(self, status: str, wall: float, t_stop: float | None, ended_by: dict | None,
             labels: dict[str, list[str]], units: dict[str, str | list[str]]) -> dict:
        """run.json's record of the run (``element_labels`` only when a block names elements,
        ``units`` only when a block knows the units of a logged signal)."""
        simulated = float(self.t_end) if t_stop is None else t_stop
        info = {
            "diagram": self.d.name,
            "diagram_file": self.d.file,
            "diagram_hash": self.d.source_hash,
            "status": status,
            "t_end": float(self.t_end),
            "t_end_exact": str(self.t_end),
            "base_tick": format_duration(self.s.base_tick),
            "wall_time_s": wall,
            "real_time_factor": simulated / wall if wall > 0 else None,
            "t_stop": t_stop,
            "ended_by": ended_by,
            "block_types": {name: spec.type_name for name, spec in self.d.blocks.items()},
            "parameters": self.d.parameters(),
            "versions": dict(package_versions()),
        }
        if self.d.subsystems:
            info["subsystems"] = self.d.composition()
        if labels:
            info["element_labels"] = labels
        if units:
            info["units"] = units
        return info


def _labels_of(blk, e) -> list[str] | None:
    """A logged signal's element labels, one per element, or None."""
    labels = blk.element_labels(e.port)
    if labels is None:
        return None
    labels = [str(label) for label in labels]
    width = blk.outputs[e.port]
    if len(labels) != width:
        raise BlockError(f"{len(labels)} labels for the {width} elements of '{e.port}'", port=e.port)
    return labels


def _units_of(blk, e) -> str | list[str] | None:
    """A logged signal's units, checked against its width, or None."""
    units = blk.port_units(e.port)
    try:
        return checked_units(units, blk.outputs[e.port], e.port)
    except ValueError as exc:
        raise BlockError(str(exc), port=e.port) from None


@functools.cache
def package_versions() -> dict[str, str]:
    """Versions of Python and the packages that shape a run's numbers."""
    versions = {"python": platform.python_version()}
    for dist in ("hierhand", "numpy", "networkx", "control", "fmpy"):
        try:
            versions[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            pass
    return versions
