"""The executor: ``simulate(diagram)`` runs a Diagram's plan and returns Results.

A run is the interpretation of one op table (``blocks.engine.optable``: the plan as plain
arrays) over the blocks of the diagram: compiled blocks through their kernels, the others
through their Python methods, as ops of the same table (``blocks.engine.compiled`` decides
which, per run). Two interpreters run a table: the C core (``blocks/csrc/core.c``, the
whole run in one C call, ``blocks.engine.native_run``) and the reference loop in plain Python
(``blocks.engine.reference_loop``), which states the semantics readably and runs where the C core
cannot (no compiled extension, tick times not exact in double). Time is always
``k * base_tick`` from the integer tick ``k``.

A block ends a run early by raising ``EndRun`` from its ``update`` at tick k: the tick
is finished, the ticks up to the block's next hit run as usual, and that hit (or t_end,
if earlier) becomes the end: outputs only, logged, as at a normal end time. The run is
complete; ``info["ended_by"]`` says which block asked, when, why, and where it ended.
"""

from __future__ import annotations

import time
from fractions import Fraction
from typing import Any, Callable

from blocks.engine.binding import Binding
from blocks.block import Block
from blocks.engine import compiled
from blocks.builder.api_args import boolean, diagram_argument
from blocks.builder.diagram import Diagram
from blocks.engine.native_run import run_native
from blocks.issues import DiagramError
from blocks.engine.optable import OpTable, op_table
from blocks.engine.outcome import Failure, Outcome
from blocks.engine.reference_loop import ReferenceLoop
from blocks.results.signals import Results
from blocks.results.record import PortInfoFailure, StopRequest, port_info, results_of
from blocks.engine.schedule import build_schedule
from blocks.timebase import DurationError, format_duration, positive_duration

__all__ = ["ENGINES", "MAX_LOG_BYTES", "ProgressCallback", "SimulationError", "StopRequest", "simulate"]

MAX_LOG_BYTES = 4 * 2**30
"""A run refuses to start if its logs would need more memory than this."""

ENGINES = ("native", "reference")
"""The interpreters of a run's op table: the C core, and the plain Python reference loop."""

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


def simulate(diagram: Diagram, t_end: Any = None, progress: ProgressCallback | None = None,
             raise_on_failure: bool = False, engine: str | None = None, check_finite: bool = True) -> Results:
    """Run ``diagram`` to ``t_end`` (default: the diagram's ``time.t_end``).

    A block failure does not lose the run: the returned Results carry the signals up to
    the failure and ``status`` 'failed at t=...: ...' (or raise ``SimulationError``
    holding them when ``raise_on_failure``). A block that raises ``EndRun`` ends the run
    at its next hit; the Results are complete, with ``ended_by`` set when that was
    before ``t_end``. ``engine``: 'native' (the C core, the default where it is built and
    the run's tick times are exact in double) or 'reference' (the plain Python loop);
    both give the same samples. An output that is not finite (NaN, an infinity) fails
    the run at its first hit, naming block, port, element and time (``blocks.engine.finite``),
    unless ``check_finite`` is False.
    """
    diagram_argument(diagram)
    boolean("raise_on_failure", raise_on_failure)
    try:
        t_end = run_end_time(diagram, t_end)
    except DurationError as exc:
        raise DiagramError([diagram.issue(None, str(exc))]) from None
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
    table = op_table(diagram, schedule)
    run = _engine(engine, table)
    wall0 = time.perf_counter()
    binding = Binding(diagram, table, check_finite)
    total = schedule.n_ticks

    def report(tick: int) -> None:
        progress(tick / total, time.perf_counter() - wall0)

    labels: dict = {}
    units: dict = {}
    try:
        if binding.failure is not None:
            name, exc = binding.failure
            outcome = Outcome(None, 0, Failure(name, "kernel", 0, exc))
        else:
            labels, units = port_info(diagram)
            outcome = run(binding, None if progress is None else report)
    except PortInfoFailure as exc:
        outcome = Outcome(None, 0, exc.failure)
    except KeyboardInterrupt as exc:
        outcome = Outcome(None, 0, interrupt=exc)
    outcome = _finish(binding, outcome)
    wall = time.perf_counter() - wall0
    if progress is not None and outcome.end is not None:
        progress(outcome.end / total, wall)
    results = results_of(diagram, schedule, t_end, binding, outcome, wall, labels, units)
    if outcome.failure is not None and raise_on_failure:
        f = outcome.failure
        raise SimulationError(results.status, results, f.block, float(f.tick * schedule.base_tick),
                              getattr(f.error, "port", None))
    return results


def _finish(binding: Binding, outcome: Outcome) -> Outcome:
    """Each block's ``finish`` after the run; the first that fails fails a complete run at
    its end tick, and a stop request there makes it interrupted there."""
    for name, blk, state in zip(binding.table.names.blocks, binding.blocks, binding.states):
        if type(blk).finish is Block.finish:
            continue
        try:
            blk.finish(state)
        except (Exception, KeyboardInterrupt) as exc:
            if outcome.end is None:
                continue  # the run has failed or stopped already; that is what it reports
            if isinstance(exc, KeyboardInterrupt):
                outcome = Outcome(None, outcome.end, interrupt=exc, end_request=outcome.end_request)
            else:
                outcome = Outcome(None, outcome.end, Failure(name, "finish", outcome.end, exc),
                                  end_request=outcome.end_request)
    return outcome


def run_end_time(diagram: Diagram, t_end: Any = None, what: str = "t_end") -> Fraction:
    """The end time of a run of ``diagram``: ``t_end`` (given as ``what``: ``t_end`` to
    ``simulate``, ``--t-end``), else the diagram's own ``time.t_end``. DiagramError when
    there is neither; DurationError when ``t_end`` is not a positive duration."""
    if t_end is None:
        if diagram.t_end is None:
            raise DiagramError([diagram.issue(None, "no end time",
                                              f"add time: {{t_end: 1 s}} to the diagram or pass {what}")])
        return diagram.t_end
    return positive_duration(t_end, what)


def _engine(engine: str | None, table: OpTable) -> Callable[[Binding, Callable[[int], None] | None], Outcome]:
    """The interpreter that runs ``table``: ``run(binding, progress) -> Outcome``."""
    if engine is None:
        engine = "native" if compiled.native() is not None and table.exact_in_double else "reference"
    if engine == "reference":
        return lambda binding, progress: ReferenceLoop(binding, progress).run()
    if engine != "native":
        raise ValueError(f"engine must be one of {', '.join(ENGINES)}, not {engine!r}")
    if compiled.native() is None:
        raise ValueError("engine 'native' needs the compiled extension blocks._native (pip install -e .)")
    if not table.exact_in_double:
        raise ValueError("the tick times of this run are not exact in double, so only engine 'reference' runs it")
    return run_native
