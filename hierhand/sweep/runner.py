"""Running a sweep's points: in this process, or one task per point on a Dask cluster.

``run_point`` is the unit of work: load the diagram with the point's overrides, simulate,
compute the metrics. It never raises for a bad point: an invalid value, a block failure
or incomplete results come back as a failed outcome with a one-line error, so one bad
point cannot stop the sweep.

On Dask (a ``distributed.LocalCluster`` of single-threaded worker processes, or a running
scheduler's workers) the code path is the same either way: a ``Client``, one task per
point, results taken ``as_completed`` and handed to ``record`` in this process, which is
the only writer of sweep.csv. The compiled numba kernels are never compiled per task:
``warm_up`` runs the diagram briefly in this process first (writing the on-disk cache of
the ``cache=True`` kernels once), and LocalCluster workers are forked from this process
where the platform can fork (``start_method``), so they start with the kernels loaded.
``warm_up`` then runs on every worker before any point, so spawned workers, and workers
of a remote scheduler that share the code and the cache folder, load the kernels from
the cache instead of compiling them.
"""

from __future__ import annotations

import logging
import os
import sys
import time
import uuid
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any, Callable

from .errors import SweepError
from .metrics import Metric
from .points import Point
from .store import FAILED, OK

WARM_UP_TIME = Fraction(1, 100)
"""Seconds simulated by a warm-up run: enough to call every block's compiled code once."""

WORKER_WAIT_S = 30.0
"""How long to wait for a remote scheduler to have at least one worker."""


@dataclass(frozen=True)
class SweepJob:
    """What every point runs: the diagram file, the metrics, the end time, trust."""

    diagram: str
    metrics: tuple[Metric, ...] = ()
    t_end: str | None = None
    trust: bool = False


@dataclass
class Outcome:
    """One finished run: status 'ok' or 'failed', its one-line error, wall time, metric values."""

    status: str
    error: str = ""
    wall_s: float = 0.0
    values: dict[str, Any] = field(default_factory=dict)


@dataclass
class SweepReport:
    """What an execution did: runs recorded, failures, wall time, and the cluster's set-up time."""

    ran: int = 0
    failed: int = 0
    wall_s: float = 0.0
    startup_s: float = 0.0
    run_s: float = 0.0
    workers: int = 0
    worker_cache_misses: int = 0


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def run_point(job: SweepJob, point: Point) -> Outcome:
    """Load, simulate and measure one point; failures are returned, not raised."""
    from blocks import DiagramError, load_diagram, simulate

    t0 = time.perf_counter()
    try:
        diagram = load_diagram(job.diagram, overrides=point, trust=job.trust)
        results = simulate(diagram, t_end=job.t_end)
        if not results.complete:
            return Outcome(FAILED, _one_line(results.status), time.perf_counter() - t0)
        values = {m.name: m.evaluate(results, diagram) for m in job.metrics}
    except DiagramError as exc:
        return Outcome(FAILED, _one_line("; ".join(str(i) for i in exc.issues)), time.perf_counter() - t0)
    except Exception as exc:  # a block's or a metric's own error: this point fails, the sweep goes on
        return Outcome(FAILED, _one_line(f"{type(exc).__name__}: {exc}"), time.perf_counter() - t0)
    return Outcome(OK, "", time.perf_counter() - t0, values)


def numba_cache_stats() -> tuple[int, int]:
    """(hits, misses) of the on-disk cache over the numba functions of blocks and hierhand loaded here."""
    try:
        from numba.core.dispatcher import Dispatcher
    except ImportError:
        return 0, 0
    hits = misses = 0
    seen: set[int] = set()
    for name, module in list(sys.modules.items()):
        if not (name.startswith("hierhand.") or name.startswith("blocks.")) or module is None:
            continue
        for value in list(vars(module).values()):
            if isinstance(value, Dispatcher) and id(value) not in seen:
                seen.add(id(value))
                stats = value.stats
                hits += sum(stats.cache_hits.values())
                misses += sum(stats.cache_misses.values())
    return hits, misses


def warm_up(job: SweepJob, point: Point) -> dict[str, Any]:
    """Run the diagram for WARM_UP_TIME so its compiled kernels are compiled or loaded from cache.

    Returns the seconds taken and the numba cache hits and misses of this process. A point
    that cannot run is not an error here: the sweep records it when it runs.
    """
    from blocks import load_diagram, simulate

    t0 = time.perf_counter()
    try:
        diagram = load_diagram(job.diagram, overrides=point, trust=job.trust)
        t_end = diagram.t_end if job.t_end is None else job.t_end
        from blocks.timebase import parse_duration

        simulate(diagram, t_end=min(parse_duration(t_end), WARM_UP_TIME) if t_end is not None else WARM_UP_TIME)
    except Exception:  # the point's own failure shows up in its row
        pass
    hits, misses = numba_cache_stats()
    return {"seconds": time.perf_counter() - t0, "cache_hits": hits, "cache_misses": misses}


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


def start_method() -> str:
    """How LocalCluster starts its worker processes: forked where the platform can fork.

    A forked worker starts with this process's modules imported and the kernels already
    loaded by ``warm_up``: about 0.1 s for two workers here, against over a second for
    spawned ones that import everything and load the numba cache again, which is longer
    than a whole sweep of short runs. ``HIERHAND_SWEEP_START`` (fork, spawn, forkserver)
    overrides the choice.
    """
    import multiprocessing

    chosen = os.environ.get("HIERHAND_SWEEP_START")
    if chosen:
        if chosen not in multiprocessing.get_all_start_methods():
            raise SweepError(f"HIERHAND_SWEEP_START={chosen}: this platform starts processes with "
                             f"{', '.join(multiprocessing.get_all_start_methods())}")
        return chosen
    return "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"


def run_dask(job: SweepJob, todo: list[tuple[str, Point]], record: Record, workers: int | None = None,
             scheduler: str | None = None, connect_timeout: float = 20.0) -> SweepReport:
    """Run one Dask task per point on a new LocalCluster (``workers`` processes) or at ``scheduler``.

    Results are recorded as they complete. On any exit (Ctrl-C included) the pending
    futures are cancelled and the client and the cluster this call started are closed.
    """
    import dask
    from distributed import Client, LocalCluster, as_completed

    report = SweepReport()
    t0 = time.perf_counter()
    cluster = client = None
    futures: dict[Any, tuple[str, Point]] = {}
    try:
        if scheduler:
            try:
                client = Client(scheduler, timeout=connect_timeout)
            except (OSError, TimeoutError) as exc:
                raise SweepError(f"--scheduler {scheduler}: cannot connect: {_one_line(exc)}") from None
            try:
                client.wait_for_workers(1, timeout=WORKER_WAIT_S)
            except TimeoutError:
                raise SweepError(f"--scheduler {scheduler}: no workers after {WORKER_WAIT_S:g} s") from None
        else:
            env = {"NUMBA_CACHE_DIR": os.environ["NUMBA_CACHE_DIR"]} if os.environ.get("NUMBA_CACHE_DIR") else {}
            with dask.config.set({"distributed.worker.multiprocessing-method": start_method()}):
                cluster = LocalCluster(n_workers=workers or default_workers(), threads_per_worker=1,
                                       processes=True, host="127.0.0.1", dashboard_address=None,
                                       silence_logs=logging.ERROR, env=env)
            client = Client(cluster)
        first = todo[0][1] if todo else {}
        warm = client.run(warm_up, job, first)
        report.workers = len(warm)
        report.worker_cache_misses = sum(w["cache_misses"] for w in warm.values())
        report.startup_s = time.perf_counter() - t0
        token = uuid.uuid4().hex[:8]
        for h, point in todo:
            futures[client.submit(run_point, job, point, key=f"sweep-{token}-{h[:16]}")] = (h, point)
        for future in as_completed(list(futures)):
            h, point = futures.pop(future)
            try:
                outcome = future.result()
            except Exception as exc:  # the task itself was lost (a worker died, ...)
                outcome = Outcome(FAILED, _one_line(f"{type(exc).__name__}: {exc}"))
            record(h, point, outcome)
            report.ran += 1
            report.failed += outcome.status != OK
        report.run_s = time.perf_counter() - t0 - report.startup_s
    finally:
        if client is not None:
            if futures:
                client.cancel(list(futures))
            client.close()
        if cluster is not None:
            cluster.close()
    report.wall_s = time.perf_counter() - t0
    return report
