"""Sweep: 16 points of diagrams/regrasp.yaml in this process against the default LocalCluster.

The grid is suppress.S_b over 4 values times suppress.S_a over 4 values, metric
separation_time, run from empty folders: serially in this process, then on the default
LocalCluster (one single-threaded worker process per core). Reports both wall times and
the speed-up for the whole sweep (cluster start, worker set-up and shutdown included) and
for the run phase alone (from the first submitted point to the last recorded row).

As a reference it also runs the same points on a bare process pool forked from this
process (multiprocessing, no Dask, no CSV): the most that 2 processes get out of this
machine for this work, so the gap to it is what Dask costs.

It does this twice: at the diagram's own end time (1 s, about 30 ms per run, so the
whole sweep is half a second of work and the cluster's fixed cost of about 0.1 s weighs
heavily) and at 10 s per run, the length where a sweep is worth sending to a cluster.

    python benchmarks/sweep.py [--t-end 1 --t-end 10] [--workers N] [--repeat 3]
"""

from __future__ import annotations

import argparse
import multiprocessing
import statistics
import tempfile
import time
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

from blocks.sweep.cluster import start_method
from blocks.sweep.metrics import parse_metrics
from blocks.sweep.plan import SweepPlan, execute, prepare
from blocks.sweep.points import grid_points
from blocks.sweep.runner import default_workers, run_point

ROOT = Path(__file__).resolve().parent.parent
REGRASP = ROOT / "diagrams" / "regrasp.yaml"
GRID = {"suppress.S_b": [0.05, 0.1, 0.15, 0.2], "suppress.S_a": [50, 100, 200, 800]}
TARGET = 1.7


@dataclass
class Timings:
    """Wall times of each repeat, per mode."""

    serial: list[float] = field(default_factory=list)
    serial_runs: list[float] = field(default_factory=list)
    dask: list[float] = field(default_factory=list)
    dask_runs: list[float] = field(default_factory=list)
    dask_startup: list[float] = field(default_factory=list)
    pool: list[float] = field(default_factory=list)
    failed: int = 0
    workers: int = 0


def pool_sweep(plan: SweepPlan, workers: int) -> float:
    """Seconds to run the plan's points on a fresh forked process pool, results discarded."""
    t0 = time.perf_counter()
    with multiprocessing.get_context("fork").Pool(workers) as pool:
        outcomes = pool.map(partial(run_point, plan.job), [p for _, p in plan.points], chunksize=1)
    assert all(o.status == "ok" for o in outcomes), [o.error for o in outcomes if o.status != "ok"]
    return time.perf_counter() - t0


def measure(plan: SweepPlan, workers: int | None, repeat: int, tmp: Path) -> Timings:
    timings = Timings()
    can_fork = "fork" in multiprocessing.get_all_start_methods()
    for i in range(repeat):
        t0 = time.perf_counter()
        serial, _, failed_serial = execute(plan, tmp / f"serial{i}", serial=True, progress=False)
        timings.serial.append(time.perf_counter() - t0)
        timings.serial_runs.append(serial.wall_s)
        t0 = time.perf_counter()
        dask, _, failed_dask = execute(plan, tmp / f"dask{i}", workers=workers, progress=False)
        timings.dask.append(time.perf_counter() - t0)
        timings.dask_runs.append(dask.run_s)
        timings.dask_startup.append(dask.startup_s)
        if can_fork:
            timings.pool.append(pool_sweep(plan, dask.workers))
        timings.failed += failed_serial + failed_dask
        timings.workers = dask.workers
    return timings


def report(t_end: str, timings: Timings) -> None:
    med = statistics.median
    serial, dask = med(timings.serial), med(timings.dask)
    speedup = serial / dask
    print(f"t_end {t_end}:")
    print(f"  serial, in process:            {serial:7.3f} s  (runs {med(timings.serial_runs):.3f} s)")
    print(f"  LocalCluster, {timings.workers} worker(s):     {dask:7.3f} s  (cluster start "
          f"{med(timings.dask_startup):.3f} s, runs {med(timings.dask_runs):.3f} s)")
    if timings.pool:
        print(f"  forked process pool, no Dask:  {med(timings.pool):7.3f} s  (reference: the machine's ceiling)")
    print(f"  failed runs: {timings.failed}")
    print(f"  speed-up, whole sweep:         {speedup:7.2f}x  "
          f"(target >= {TARGET}x: {'met' if speedup >= TARGET else 'NOT met'})")
    print(f"  speed-up, run phase:           {med(timings.serial_runs) / med(timings.dask_runs):7.2f}x")
    if timings.pool:
        print(f"  speed-up, forked process pool: {serial / med(timings.pool):7.2f}x")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", action="append", default=None,
                        help="end time of every run in seconds, repeatable (default: 1 and 10)")
    parser.add_argument("--workers", type=int, default=None, help="LocalCluster workers (default: one per core)")
    parser.add_argument("--repeat", type=int, default=3, help="sweeps per mode (median)")
    args = parser.parse_args()
    print(f"regrasp sweep, {len(grid_points(GRID))} points, {default_workers()} core(s), start method "
          f"{start_method()}, median of {args.repeat} sweeps per mode")
    for t_end in args.t_end or ["1", "10"]:
        plan = prepare(REGRASP, grid_points(GRID), parse_metrics(["sep=separation_time"]), t_end=f"{t_end} s",
                       axes={"grid": GRID})
        with tempfile.TemporaryDirectory() as tmp:
            report(f"{t_end} s", measure(plan, args.workers, args.repeat, Path(tmp)))


if __name__ == "__main__":
    main()
