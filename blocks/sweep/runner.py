"""Running a sweep's points: the unit of work, and the serial loop in this process.

``run_point`` loads the diagram with the point's overrides, simulates and computes the
metrics. It never raises for a bad point: an invalid value, a block failure or incomplete
results come back as a failed outcome with a one-line error, so one bad point cannot stop
the sweep. Only Ctrl-C stops it: an interrupted run is not a result and is left to be run
again. ``warm_up`` runs the diagram briefly first, so that imports and one-time set-up
(an FMU's unpacking, a block's first call) happen once, before any point is timed. The
Dask execution is in ``cluster``.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any, Callable

from .bundle import DiagramBundle
from .metrics import Metric
from .points import Point
from .store import FAILED, OK

WARM_UP_TIME = Fraction(1, 100)
"""Seconds simulated by a warm-up run: enough to call every block's compiled code once."""


@dataclass(frozen=True)
class SweepJob:
    """What every point runs: the diagram file, the metrics, the end time, trust, and how
    the user gave each parameter (``points.origins``, as pairs) for the messages of a point
    that fails to load.

    ``bundle`` is the diagram as content (``bundle.DiagramBundle``): with it a point loads
    the diagram from the bundle's copy of its files, never from ``diagram``, the path as
    the user gave it (without it, from that path: a run in this process). ``keep_results``:
    each outcome carries its run's results, to be saved by the sweep's process.
    """

    diagram: str
    metrics: tuple[Metric, ...] = ()
    t_end: str | None = None
    trust: bool = False
    origins: tuple[tuple[str, str], ...] = ()
    bundle: DiagramBundle | None = None
    keep_results: bool = False

    def load(self, point: Point, origins: bool = True):
        """The diagram with the point's overrides, from the bundle if there is one."""
        given = dict(self.origins) if origins else None
        if self.bundle is not None:
            return self.bundle.load(overrides=point, trust=self.trust, origins=given)
        from blocks import load_diagram

        return load_diagram(self.diagram, overrides=point, trust=self.trust, origins=given)


@dataclass
class Outcome:
    """One finished run: status 'ok' or 'failed', its one-line error, wall time, metric values."""

    status: str
    error: str = ""
    wall_s: float = 0.0
    values: dict[str, Any] = field(default_factory=dict)
    results: Any = None
    """The run's ``Results`` when the job keeps them (None if the point did not get to run)."""


@dataclass
class SweepReport:
    """What an execution did: runs recorded, failures, wall time, the cluster's set-up time
    and its number of workers (0: none was started)."""

    ran: int = 0
    failed: int = 0
    wall_s: float = 0.0
    startup_s: float = 0.0
    run_s: float = 0.0
    workers: int = 0
    local: int = 0
    """Points run by a local runner process (``local``), beside or instead of the workers."""


def one_line(text: str) -> str:
    """Any message as one line: an error cell of sweep.csv, or a line on the terminal."""
    return " ".join(str(text).split())


def run_point(job: SweepJob, point: Point) -> Outcome:
    """Load, simulate and measure one point; failures are returned, not raised."""
    from blocks import DiagramError, simulate

    t0 = time.perf_counter()
    results = None
    try:
        diagram = job.load(point)
        results = simulate(diagram, t_end=job.t_end)
        if results.interrupted:
            raise KeyboardInterrupt  # the user's Ctrl-C stops the sweep; this point stays to be run
        if not results.complete:
            outcome = Outcome(FAILED, one_line(results.status), time.perf_counter() - t0)
        else:
            values = {m.name: m.evaluate(results, diagram) for m in job.metrics}
            outcome = Outcome(OK, "", time.perf_counter() - t0, values)
    except DiagramError as exc:
        outcome = Outcome(FAILED, one_line("; ".join(str(i) for i in exc.issues)), time.perf_counter() - t0)
    except Exception as exc:  # a block's or a metric's own error: this point fails, the sweep goes on
        outcome = Outcome(FAILED, one_line(f"{type(exc).__name__}: {exc}"), time.perf_counter() - t0)
    if job.keep_results and results is not None:
        results.info["sweep"] = {"point": point, "status": outcome.status, "error": outcome.error,
                                 "metrics": outcome.values,
                                 "bundle_hash": job.bundle.hash if job.bundle is not None else None}
        outcome.results = results
    return outcome


def run_points(job: SweepJob, points: list[Point]) -> list[Outcome]:
    """Run several points one after the other: the work of one Dask task."""
    return [run_point(job, point) for point in points]


def warm_up(job: SweepJob, point: Point) -> None:
    """Run the diagram for WARM_UP_TIME so its compiled kernels are compiled or loaded from cache.

    A point that cannot run is not an error here: the sweep records it when it runs.
    """
    from blocks import simulate
    from blocks.timebase import parse_duration

    try:
        diagram = job.load(point, origins=False)
        t_end = diagram.t_end if job.t_end is None else job.t_end
        simulate(diagram, t_end=min(parse_duration(t_end), WARM_UP_TIME) if t_end is not None else WARM_UP_TIME)
    except Exception:  # the point's own failure shows up in its row
        pass


def default_workers() -> int:
    """One worker per core this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


Record = Callable[[str, Point, Outcome], None]


def run_serial(job: SweepJob, todo: list[tuple[str, Point]], record: Record) -> SweepReport:
    """Run the points one after the other in this process (debugging, benchmark baseline)."""
    report = SweepReport(workers=0)
    t0 = time.perf_counter()
    for h, point in todo:
        outcome = run_point(job, point)
        record(h, point, outcome)
        report.ran += 1
        report.failed += outcome.status != OK
    report.wall_s = time.perf_counter() - t0
    return report
