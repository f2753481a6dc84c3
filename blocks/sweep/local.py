"""A sweep's head start: a process forked from this one runs points at once, while Dask is
imported and the cluster starts, and runs them all when a cluster would not pay off.

A cluster costs a fixed time before its first run (importing distributed, starting the
workers: about 0.3 s on 2 cores) and a little to stop; a sweep of less work than that is
faster without one. So a sweep that is free to choose (no ``--workers``, ``--scheduler``
or ``--serial``) starts a ``LocalRunner`` first, judges the remaining work from the run
times it reports, and starts the cluster only when the estimate says it pays off
(``cluster_pays_off``); the runner goes on meanwhile and stops once the cluster is
ready. Runs happen in a forked process, never in this one, so a point that kills its
process is recorded as failed and the sweep goes on, as on the cluster.
"""

from __future__ import annotations

import multiprocessing
import pickle
import signal
import statistics
import time
from typing import Any, Callable

from .errors import SweepError
from .queue import SharedQueue
from .runner import Outcome, Record, SweepJob, SweepReport, default_workers, one_line, run_point
from .store import FAILED, OK

CLUSTER_START_S = 0.3
"""Seconds from deciding on a LocalCluster to its first run, measured on 2 cores:
importing distributed 0.14 s, starting two forked workers and connecting to them 0.15 s."""

CLUSTER_STOP_S = 0.03
"""Seconds to stop a LocalCluster of two workers (0.02 s measured) and collect the last results."""

Keep = Callable[[str, Outcome], None]
"""Saves a kept run's results by its point hash and drops them from the outcome."""

FIRST_RUN_SLOWER = 2.0
"""At most how much longer a local runner's first run takes than its later ones (1.6x
measured for a re-grasp), taken on the safe side."""

WORKER_EFFICIENCY = 0.875
"""How much of one process's speed each LocalCluster worker gives: two workers on 2 cores
run a re-grasp sweep 1.75x faster than one process (the scheduler and the client share
the cores with them)."""


def cluster_pays_off(typical_run_s: float, remaining: int, workers: int) -> bool:
    """Whether starting a LocalCluster of ``workers`` now finishes ``remaining`` runs of
    about ``typical_run_s`` each sooner than the local process alone, which keeps running
    while the cluster starts: (work - start) x (1 - 1 / speed-up) must exceed the stop."""
    speedup = WORKER_EFFICIENCY * workers
    work = typical_run_s * remaining
    return speedup > 1 and (work - CLUSTER_START_S) * (1 - 1 / speedup) > CLUSTER_STOP_S


def can_run_locally(method: str | None = None) -> bool:
    """A local runner needs a platform that forks (a spawned one would import everything
    again, which takes longer than the work it is there for), and no request to start
    processes another way (``method``, the sweep's start method: a user who asks for spawn
    keeps this process from forking)."""
    return method in (None, "fork") and "fork" in multiprocessing.get_all_start_methods()


def _died(process: Any) -> str:
    code = process.exitcode
    if code is not None and code < 0:
        try:
            return f"killed by signal {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exit code {code}"


def _serve(job: SweepJob, queue: SharedQueue, stop: Any, conn: Any, keep: Keep | None) -> None:
    """The runner process: take one point at a time until none is left or ``stop`` is set;
    say which point it starts and send its outcome when done. A kept run's results are
    saved here by ``keep`` (a folder per point, written before its row), so that only the
    small outcome goes through the pipe; if saving fails, they go too and the sweep's
    process saves them, or says why it cannot."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is answered by the sweep's process
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        while not stop.is_set():
            taken = queue.take_indices(1)
            if not taken:
                break
            index = taken[0]
            point_hash, point = queue.items[index]
            conn.send(("start", index))
            outcome = run_point(job, point)
            if keep is not None:
                try:
                    keep(point_hash, outcome)
                except Exception:  # the sweep's process tries again, and reports it
                    pass
            try:
                conn.send(("done", index, outcome))
            except (pickle.PicklingError, TypeError, AttributeError) as exc:  # as a Dask task's result would fail
                conn.send(("done", index, Outcome(FAILED, one_line(f"the run's outcome cannot be sent back: "
                                                                   f"{type(exc).__name__}: {exc}"), outcome.wall_s)))
    except (BrokenPipeError, EOFError, KeyboardInterrupt):  # the sweep's process has gone
        pass
    finally:
        conn.close()


class LocalRunner:
    """One forked process running points of a ``SharedQueue``; ``collect`` hands each
    outcome to ``record(index, outcome)`` as it arrives, a point the process died under
    as failed. After such a death ``start`` forks a new one for the points left."""

    def __init__(self, job: SweepJob, queue: SharedQueue, record: Callable[[int, Outcome], None],
                 keep: Keep | None = None):
        self.job, self.queue, self.record, self.keep = job, queue, record, keep
        self.context = multiprocessing.get_context("fork")
        self.stop_flag = self.context.Event()
        self.process: Any = None
        self.conn: Any = None
        self.current: tuple[int, float] | None = None
        """The point the process is running and when it started (for its failure if it dies)."""
        self.began = False
        """Whether the latest process took a point (one that dies before is not restarted)."""
        self.walls: list[float] = []
        """Wall times of the runs this runner finished (or died under), one per point."""

    @property
    def alive(self) -> bool:
        """Whether the process may still send outcomes (it has not closed its end)."""
        return self.conn is not None

    def start(self) -> None:
        receive, send = self.context.Pipe(duplex=False)
        self.process = self.context.Process(target=_serve, args=(self.job, self.queue, self.stop_flag, send, self.keep),
                                            name="sweep-local-runner", daemon=True)
        self.process.start()
        send.close()
        self.conn = receive
        self.began = False

    def stop(self) -> None:
        """Finish the point in hand and take no more (the cluster has the rest)."""
        self.stop_flag.set()

    def collect(self, timeout: float | None = 0.0) -> None:
        """Record what has arrived, waiting up to ``timeout`` seconds for the first message
        (None: until one arrives or the process ends)."""
        while self.conn is not None and self.conn.poll(timeout):
            timeout = 0.0
            try:
                message = self.conn.recv()
            except EOFError:
                self._ended()
                return
            if message[0] == "start":
                self.current = (message[1], time.perf_counter())
                self.began = True
            else:
                self.current = None
                self._take(message[1], message[2])

    def typical_run_s(self) -> float | None:
        """The median wall time of its runs, the first left out once there are others: a new
        process's first run pays its warm-up (copy-on-write page faults after the fork),
        14.8 ms against 9 ms for a re-grasp. Until a second run is in, the first counts for
        half its time, an estimate on the low side, so that only a sweep clearly worth a
        cluster starts one at once. None before any run."""
        if len(self.walls) < 2:
            return self.walls[0] / FIRST_RUN_SLOWER if self.walls else None
        return statistics.median(self.walls[1:])

    def _take(self, index: int, outcome: Outcome) -> None:
        self.walls.append(outcome.wall_s)
        self.record(index, outcome)

    def _ended(self) -> None:
        """The process closed its end: wait for it, and record the point it died under."""
        self.conn.close()
        self.conn = None
        self.process.join()
        if self.current is not None:
            index, started = self.current
            self.current = None
            self._take(index, Outcome(FAILED, f"the process running this point died ({_died(self.process)})",
                                      time.perf_counter() - started))

    def close(self) -> None:
        """Stop the process now (Ctrl-C, an error): what it had not sent is left to a resume."""
        if self.process is not None and self.process.is_alive():
            self.process.kill()
            self.process.join()
        if self.conn is not None:
            self.conn.close()
            self.conn = None


def run_local_first(job: SweepJob, todo: list[tuple[str, Any]], record: Record, workers: int | None = None,
                    method: str | None = None, keep: Keep | None = None) -> SweepReport:
    """Run the points in a local runner, and on a new LocalCluster of ``workers`` (default:
    one per core) as soon as the runs left are worth one (``cluster_pays_off``, judged
    after every local run). The report's ``local`` counts the points the runner ran.
    ``keep(point hash, outcome)`` saves a kept run's results in the runner's process."""
    from .cluster import run_dask

    workers = workers or default_workers()
    queue = SharedQueue(todo, multiprocessing.get_context("fork"))
    report = SweepReport()

    def take(index: int, outcome: Outcome) -> None:
        record(*todo[index], outcome)
        report.ran += 1
        report.failed += outcome.status != OK

    t0 = time.perf_counter()
    runner = LocalRunner(job, queue, take, keep)
    try:
        runner.start()
        while True:
            runner.collect(timeout=None)
            if not runner.alive:
                if not len(queue):
                    break
                if not runner.began:
                    raise SweepError(f"the local process of the sweep ended before its first point "
                                     f"({_died(runner.process)}) (hint: --workers N runs the points on a "
                                     "LocalCluster from the start, --serial in this process)")
                runner.start()  # it died under a point, now recorded: a new one runs the rest
            elif (typical := runner.typical_run_s()) is not None and cluster_pays_off(typical, len(queue), workers):
                cluster = run_dask(job, queue, record, workers=workers, method=method, beside=runner)
                report.ran += cluster.ran
                report.failed += cluster.failed
                report.workers, report.startup_s = cluster.workers, cluster.startup_s
                while runner.alive:
                    runner.collect(timeout=None)
                break
    finally:
        runner.close()
    report.local = len(runner.walls)
    report.wall_s = report.run_s = time.perf_counter() - t0
    return report
