"""Running a sweep on Dask: a new LocalCluster of single-threaded worker processes, or the
workers of a running scheduler, through the same code.

This process submits tasks of one or more points (``chunks.ChunkSizer`` chooses how many),
keeps a few of them in flight per worker, takes them ``as_completed`` and hands every run
to ``record``, so it is the only writer of sweep.csv. When a worker dies under a task,
Dask retries the task elsewhere and finally fails it, and it also fails tasks that only
waited on that worker. So the points of a lost task are run again one at a time, with
nothing else in flight, and only a point that is lost even then is recorded as failed:
the point that kills its worker, not its neighbours.

The diagram goes to the workers as content (``bundle``): a worker plugin gives every
worker, and any that joins or is restarted, the files once; each task carries the
bundle's manifest only. Connecting to a running scheduler checks first that the client,
the scheduler and the workers run the same versions of Dask and of the packages the runs
need (``check_versions``).

``warm_up`` has run the diagram briefly in this process before the cluster starts
(modules imported, FMUs unpacked), and LocalCluster workers are forked from it where the
platform can fork (``start_method``), so they start with all of that done.
"""

from __future__ import annotations

import logging
import signal
import threading
import time
import uuid
from collections import deque
from contextlib import ExitStack, contextmanager
from dataclasses import replace
from typing import Any

from .chunks import ChunkSizer
from .errors import SweepError
from .points import Point
from .queue import PointQueue, SharedQueue
from .runner import Outcome, Record, SweepJob, SweepReport, default_workers, one_line, run_points
from .store import FAILED, OK

WORKER_WAIT_S = 30.0
"""How long to wait for a remote scheduler to have at least one worker."""

LOCAL_CLUSTER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "1s",
}
"""Dask settings for the LocalCluster a sweep starts. The workers' statistical profiler
(a stack sample every 10 ms, read only by the dashboard, which a sweep does not start)
and their fast monitoring ticks take the GIL from the running simulation: with them,
every 10 s re-grasp run took about 5 % longer on 2 cores."""

KEEP_LOST_WORKERS = {"distributed.deploy.lost-worker-timeout": "36500 days"}
"""Held while a sweep's LocalCluster runs (it reads the setting when a worker leaves): by
default the cluster closes a worker's nanny for good when its worker has not come back
within 15 s. A nanny restarts a worker whose process died (a point that kills it), and on
a busy machine that restart can take longer; the cluster then had no workers left and the
sweep waited forever. Its nannies are kept for as long as it runs."""


def start_method(requested: str | None = None, source: str = "start_method") -> str:
    """How LocalCluster starts its worker processes: ``requested`` (fork, spawn, forkserver)
    if given, else forked where the platform can fork.

    A forked worker starts with this process's modules imported and the diagram already
    run once by ``warm_up``: about 0.1 s for two workers here, against about a second for
    spawned ones that import everything again, which is longer than a whole sweep of
    short runs. ``source`` names where ``requested`` came from, for the message when this
    platform cannot start processes that way.
    """
    import multiprocessing

    if requested:
        if requested not in multiprocessing.get_all_start_methods():
            raise SweepError(f"{source}={requested}: this platform starts processes with "
                             f"{', '.join(multiprocessing.get_all_start_methods())}")
        return requested
    return "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"


@contextmanager
def _children_ignore_ctrl_c():
    """Start processes with SIGINT ignored.

    Ctrl-C in a terminal reaches the whole process group, workers included. This process
    answers it (cancel, close the cluster, keep the CSV whole); workers that took it too
    would each print a traceback while being shut down.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def connect(scheduler: str, timeout: float = 20.0):
    """A client of the running scheduler at ``scheduler`` with at least one worker whose
    versions match this process's; a one-line SweepError otherwise."""
    import warnings

    from distributed import Client

    try:
        with warnings.catch_warnings():  # Dask's own table of mismatched versions: check_versions says it
            warnings.filterwarnings("ignore", message="Mismatched versions found")
            client = Client(scheduler, timeout=timeout)
    except (OSError, TimeoutError) as exc:
        raise SweepError(f"--scheduler {scheduler}: cannot connect: {one_line(exc)}") from None
    except (ValueError, TypeError) as exc:
        raise SweepError(f"--scheduler {scheduler!r}: not a scheduler's address ({one_line(exc)}) "
                         "(hint: tcp://HOST:PORT, as the scheduler prints it)") from None
    try:
        client.wait_for_workers(1, timeout=WORKER_WAIT_S)
        check_versions(client, scheduler)
    except TimeoutError:
        client.close()
        raise SweepError(f"--scheduler {scheduler}: no workers after {WORKER_WAIT_S:g} s") from None
    except SweepError:
        client.close()
        raise
    return client


CHECKED_PACKAGES = ("numpy", "pyyaml", "fmpy")
"""Packages whose versions must agree beyond Dask's own (``distributed.versions``): what
the runs compute with. The distribution that provides ``blocks`` is checked too."""
SCHEDULER_PACKAGES = ("python", "dask", "distributed", "cloudpickle", "tornado", "toolz")
"""The packages the scheduler's versions are checked for (it runs no simulation)."""


def _own_distribution() -> list[str]:
    try:
        from importlib.metadata import packages_distributions

        return sorted(set(packages_distributions().get("blocks", [])))
    except Exception:  # no metadata (run from a source tree): nothing more to check
        return []


def version_mismatches(versions: dict[str, Any]) -> list[str]:
    """``package: VERSION here, VERSION on the scheduler, VERSION on N worker(s)`` for every
    package whose version differs, from ``Client.get_versions()``'s answer."""
    def packages(info: Any) -> dict[str, Any]:
        return (info or {}).get("packages") or {} if isinstance(info, dict) else {}

    here = packages(versions.get("client"))
    scheduler = packages(versions.get("scheduler"))
    workers = {address: packages(info) for address, info in (versions.get("workers") or {}).items()}
    names = sorted(set(here) | set(scheduler) | {n for w in workers.values() for n in w})
    lines = []
    for name in names:
        mine = here.get(name) or "missing"
        found: list[tuple[str, str]] = []
        if name in SCHEDULER_PACKAGES:
            found.append(("the scheduler", scheduler.get(name) or "missing"))
        counts: dict[str, int] = {}
        for w in workers.values():
            counts[w.get(name) or "missing"] = counts.get(w.get(name) or "missing", 0) + 1
        found += [(f"{n} worker(s)", v) for v, n in sorted(counts.items())]
        if any(v != mine for _, v in found):
            lines.append(f"{name} {mine} here, " + ", ".join(f"{v} on {where}" for where, v in found))
    return lines


def check_versions(client, scheduler: str) -> None:
    """Raise SweepError (one line, with a hint) when this process, the scheduler and the
    workers do not run the same versions of Dask, Python and the packages the runs use:
    Dask only warns, and a sweep would then fail in its tasks, or worse, differ."""
    from distributed.versions import optional_packages, required_packages

    extra = [*CHECKED_PACKAGES, *_own_distribution()]
    versions = client.get_versions(packages=extra)
    checked = {"python", *required_packages, *optional_packages, *extra}
    for part in (versions.get("client"), versions.get("scheduler"), *(versions.get("workers") or {}).values()):
        if isinstance(part, dict) and isinstance(part.get("packages"), dict):
            part["packages"] = {k: v for k, v in part["packages"].items() if k in checked}
    mismatches = version_mismatches(versions)
    if mismatches:
        raise SweepError(f"--scheduler {scheduler}: versions differ between this process, the scheduler and "
                         f"the workers: {'; '.join(mismatches)} (hint: install the same versions on every "
                         "machine, e.g. from one lock file or environment, and restart the scheduler and "
                         "workers)")


def _local_cluster(workers: int | None, method: str | None):
    import dask
    from distributed import LocalCluster

    from blocks.process import scratch
    from blocks.process.forked import own_std_streams_after_fork
    from .worker_plugin import IgnoreCtrlC

    own_std_streams_after_fork()  # workers are forked from a thread while others may be writing

    settings = {**LOCAL_CLUSTER_CONFIG, "distributed.worker.multiprocessing-method": start_method(method),
                "temporary-directory": str(scratch.folder("dask-"))}  # the scheduler's and workers' folders
    with dask.config.set(settings), _children_ignore_ctrl_c():
        return LocalCluster(n_workers=workers or default_workers(), threads_per_worker=1, processes=True,
                            host="127.0.0.1", dashboard_address=None, silence_logs=logging.CRITICAL,
                            plugins={IgnoreCtrlC()}, scheduler_kwargs={"dashboard_address": "127.0.0.1:0"})
        # without a dashboard the scheduler still serves HTTP, by default on port 8787: a free port
        # instead, so that another program on 8787 gets no warning printed


def run_dask(job: SweepJob, todo: list[tuple[str, Point]] | PointQueue | SharedQueue, record: Record,
             workers: int | None = None, scheduler: str | None = None, connect_timeout: float = 20.0,
             method: str | None = None, client: Any = None, beside: Any = None) -> SweepReport:
    """Run the points on a new LocalCluster (``workers`` processes, started by ``method``:
    see ``start_method``), at ``scheduler``, or through ``client`` (from ``connect``; this
    call closes it).

    Runs are recorded as their tasks complete. On any exit (Ctrl-C included) the tasks in
    flight are cancelled, their points left to a later resume, and the client and the
    cluster this call started are closed. ``beside`` is a local runner taking points from
    the same ``todo`` queue while the cluster starts (``local``): once the cluster is
    ready it is told to stop, its run times size the first tasks, and what it sends is
    recorded as tasks complete (``local.LocalRunner``: ``stop()``, ``collect()``, ``walls``).
    """
    import dask
    from distributed import Client, as_completed

    from .worker_plugin import DiagramFiles

    report = SweepReport()
    t0 = time.perf_counter()
    cluster = plugin = None
    held = ExitStack()
    in_flight: dict[Any, list[tuple[str, Point]]] = {}
    try:
        if client is not None:
            pass
        elif scheduler:
            client = connect(scheduler, connect_timeout)
        else:
            held.enter_context(dask.config.set(KEEP_LOST_WORKERS))
            cluster = _local_cluster(workers, method)
            client = Client(cluster)
        if job.bundle is not None:  # the files once per worker; each task carries the manifest only
            plugin = DiagramFiles(job.bundle, uuid.uuid4().hex[:8])
            client.register_plugin(plugin, name=plugin.name)
            job = replace(job, bundle=job.bundle.manifest())
        workers_info = client.scheduler_info()["workers"]
        threads = sum(w["nthreads"] for w in workers_info.values())
        report.workers = len(workers_info)
        report.startup_s = time.perf_counter() - t0

        sizer = ChunkSizer(threads)
        if beside is not None:
            beside.stop()
            beside.collect()
            for wall in beside.walls:
                sizer.observe(wall)
        queue = todo if isinstance(todo, (PointQueue, SharedQueue)) else PointQueue(todo)
        suspects: deque = deque()
        isolated: set[Any] = set()
        token, submitted = uuid.uuid4().hex[:8], 0
        finished = as_completed()

        def submit(chunk: list[tuple[str, Point]]) -> Any:
            nonlocal submitted
            future = client.submit(run_points, job, [p for _, p in chunk], key=f"sweep-{token}-{submitted}")
            submitted += 1
            in_flight[future] = chunk
            finished.add(future)
            return future

        def top_up() -> None:
            if suspects:  # one at a time, nothing else in flight: each is judged on its own
                if not in_flight:
                    isolated.add(submit([suspects.popleft()]))
                return
            while len(in_flight) < sizer.in_flight and (chunk := queue.take(sizer.size(len(queue)))):
                submit(chunk)

        top_up()
        for future in finished:
            chunk = in_flight.pop(future)
            try:
                outcomes = future.result()
            except Exception as exc:  # the task itself was lost: a worker died under it, ...
                if future not in isolated:
                    suspects.extend(chunk)
                    top_up()
                    continue
                outcomes = [Outcome(FAILED, one_line(f"{type(exc).__name__}: {exc}"))]
            for (h, point), outcome in zip(chunk, outcomes):
                record(h, point, outcome)
                sizer.observe(outcome.wall_s)
                report.ran += 1
                report.failed += outcome.status != OK
            if beside is not None:
                beside.collect()
            top_up()
        report.run_s = time.perf_counter() - t0 - report.startup_s
    finally:
        if client is not None:
            if in_flight:
                client.cancel(list(in_flight))
            if plugin is not None and scheduler:  # a LocalCluster's workers go with it
                try:
                    client.unregister_worker_plugin(plugin.name)
                except Exception:  # the copies are removed when the workers stop
                    pass
            client.close()
        if cluster is not None:
            cluster.close()
        held.close()
    report.wall_s = time.perf_counter() - t0
    return report
