"""Sweep: 16 points of diagrams/regrasp.yaml in this process against the default LocalCluster.

The grid is suppress.S_b over 4 values times suppress.S_a over 4 values, metric
separation_time, run twice from empty folders: serially in this process, then on the
default LocalCluster (one single-threaded worker process per core). Reports both wall
times and the speed-up, for the whole sweep (cluster start and worker warm-up included)
and for the run phase alone (from the first submitted point to the last recorded row),
plus the numba cache misses of the workers' warm-up (0: nothing was recompiled).

A 1 s re-grasp run takes about 30 ms, so at the diagram's own end time the cluster's
start-up (seconds) outweighs the work; --t-end lengthens every run to show the regime a
real sweep is in.

    python benchmarks/sweep.py [--t-end 1] [--workers N]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from hierhand.sweep.metrics import parse_metrics
from hierhand.sweep.plan import execute, prepare
from hierhand.sweep.points import grid_points
from hierhand.sweep.runner import default_workers, start_method

ROOT = Path(__file__).resolve().parent.parent
REGRASP = ROOT / "diagrams" / "regrasp.yaml"
GRID = {"suppress.S_b": [0.05, 0.1, 0.15, 0.2], "suppress.S_a": [50, 100, 200, 800]}
TARGET = 1.7


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", default=None, help="end time of every run (default: the diagram's, 1 s)")
    parser.add_argument("--workers", type=int, default=None, help="LocalCluster workers (default: one per core)")
    parser.add_argument("--repeat", type=int, default=3, help="sweeps per mode (median)")
    args = parser.parse_args()
    plan = prepare(REGRASP, grid_points(GRID), parse_metrics(["sep=separation_time"]), t_end=args.t_end,
                   axes={"grid": GRID})
    serial_totals, serial_runs, dask_totals, dask_runs, startups = [], [], [], [], []
    failed = workers = misses = 0
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.repeat):
            t0 = time.perf_counter()
            serial, _, failed_serial = execute(plan, Path(tmp) / f"serial{i}", serial=True, progress=False)
            serial_totals.append(time.perf_counter() - t0)
            serial_runs.append(serial.wall_s)
            t0 = time.perf_counter()
            dask, _, failed_dask = execute(plan, Path(tmp) / f"dask{i}", workers=args.workers, progress=False)
            dask_totals.append(time.perf_counter() - t0)
            dask_runs.append(dask.run_s)
            startups.append(dask.startup_s)
            failed += failed_serial + failed_dask
            workers, misses = dask.workers, misses + dask.worker_cache_misses
    serial_total, dask_total = statistics.median(serial_totals), statistics.median(dask_totals)
    t_end = args.t_end or "the diagram's (1 s)"
    print(f"regrasp sweep, {len(plan.points)} points, t_end {t_end}, {default_workers()} core(s), "
          f"median of {args.repeat} sweeps per mode; start method {start_method()}")
    print(f"  serial, in process:        {serial_total:7.3f} s  (runs {statistics.median(serial_runs):.3f} s)")
    print(f"  LocalCluster, {workers} worker(s): {dask_total:7.3f} s  (cluster start + worker warm-up "
          f"{statistics.median(startups):.3f} s, runs {statistics.median(dask_runs):.3f} s)")
    print(f"  failed runs: {failed}; worker numba cache misses: {misses}")
    speedup = serial_total / dask_total
    print(f"  speed-up, whole sweep:     {speedup:7.2f}x  (target >= {TARGET}x: {'met' if speedup >= TARGET else 'NOT met'})")
    print(f"  speed-up, run phase:       {statistics.median(serial_runs) / statistics.median(dask_runs):7.2f}x")


if __name__ == "__main__":
    main()
