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
import tempfile
import time
from pathlib import Path

from hierhand.sweep.metrics import parse_metrics
from hierhand.sweep.plan import execute, prepare
from hierhand.sweep.points import grid_points
from hierhand.sweep.runner import default_workers

ROOT = Path(__file__).resolve().parent.parent
REGRASP = ROOT / "diagrams" / "regrasp.yaml"
GRID = {"suppress.S_b": [0.05, 0.1, 0.15, 0.2], "suppress.S_a": [50, 100, 200, 800]}
TARGET = 1.7


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", default=None, help="end time of every run (default: the diagram's, 1 s)")
    parser.add_argument("--workers", type=int, default=None, help="LocalCluster workers (default: one per core)")
    args = parser.parse_args()
    plan = prepare(REGRASP, grid_points(GRID), parse_metrics(["sep=separation_time"]), t_end=args.t_end,
                   axes={"grid": GRID})
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        serial, _, failed_serial = execute(plan, Path(tmp) / "serial", serial=True, progress=False)
        serial_total = time.perf_counter() - t0
        t0 = time.perf_counter()
        dask, _, failed_dask = execute(plan, Path(tmp) / "dask", workers=args.workers, progress=False)
        dask_total = time.perf_counter() - t0
    run_phase = dask.wall_s - dask.startup_s
    t_end = args.t_end or "the diagram's (1 s)"
    print(f"regrasp sweep, {len(plan.points)} points, t_end {t_end}, "
          f"{default_workers()} core(s)")
    print(f"  serial, in process:        {serial_total:7.3f} s  (runs {serial.wall_s:.3f} s, {failed_serial} failed)")
    print(f"  LocalCluster, {dask.workers} worker(s): {dask_total:7.3f} s  (cluster start + worker warm-up "
          f"{dask.startup_s:.3f} s, runs {run_phase:.3f} s, {failed_dask} failed; worker numba cache misses: "
          f"{dask.worker_cache_misses})")
    print(f"  speed-up, whole sweep:     {serial_total / dask_total:7.2f}x")
    print(f"  speed-up, run phase:       {serial.wall_s / run_phase:7.2f}x  (target >= {TARGET}x)")


if __name__ == "__main__":
    main()
