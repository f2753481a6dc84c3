"""``sweep`` and ``sweep-plot``: run a diagram at many parameter points, and plot the result.

The options become a call of ``blocks.sweep.run_sweep``: the points from ``--grid``,
``--random`` or ``--points``, the metrics from ``--metric``. The environment variable
``PREFIX_SWEEP_START`` (``Program.env``) chooses how a LocalCluster starts its workers
(fork, spawn, forkserver; ``blocks.sweep.cluster.start_method``); any but fork also keeps
the sweep from forking its local head-start process (``blocks.sweep.local``).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from .options import end_time, picture_output, trust_arg
from .program import EXIT_FAILED, EXIT_OK, Command, UsageError

TYPE_CHECKING = False  # typing's constant without importing typing (blocks.cli.program says why)
if TYPE_CHECKING:
    from typing import Any

REDUCERS_HELP = ("a column per run (repeatable): REDUCER(BLOCK.PORT[e]) with final, max, min, mean, "
                 "first_time_above(BLOCK.PORT[e], X), first_time_below(BLOCK.PORT[e], X); the element e by its "
                 "label (an FMU's q[1]) or 0-based index, as plot -s reads it")
MEASURES_HELP = "a measure registered under the 'blocks.measures' entry-point group: MEASURE[(ARGS)]"


def command(measures_help: str = MEASURES_HELP) -> Command:
    """The ``sweep`` command; ``measures_help`` describes the measures ``--metric`` may name
    besides the reducers (an application lists its own)."""
    def add(sub, program) -> argparse.ArgumentParser:
        sweep = sub.add_parser("sweep", help="run a diagram at many parameter points (Dask), one CSV row each",
                               description="Run DIAGRAM at every point of a grid, random samples or a points "
                                           "file, on a Dask LocalCluster of single-threaded worker processes "
                                           "or a running scheduler, appending one row per "
                                           "finished run to OUTPUT/sweep.csv. Re-running the same command "
                                           "resumes: points already in the file are skipped. The diagram and "
                                           "every file it reads are sent to the workers, which need only the "
                                           "installed packages (same versions). By default the points start "
                                           "at once in a local process, and a LocalCluster of one worker per "
                                           "core takes over when the runs left are worth starting one.")
        sweep.add_argument("diagram", type=Path, metavar="DIAGRAM",
                           help="YAML diagram file, or an SSP (.ssp archive, or a folder with SystemStructure.ssd)")
        sweep.add_argument("--step", metavar="T",
                           help="SSP only: the communication step of the components whose SSD gives none")
        sweep.add_argument("-o", "--output", type=Path, required=True, metavar="DIR",
                           help="sweep folder: sweep.csv and sweep.json (and runs/ with --keep-results)")
        sweep.add_argument("--grid", action="append", default=[], metavar="BLOCK.PARAM=V1,V2,...",
                           help="grid axis, values read as YAML (repeatable: cartesian product), "
                                "e.g. --grid prop.k=1,2,4")
        sweep.add_argument("--random", action="append", default=[], metavar="BLOCK.PARAM=DIST",
                           help="random axis, DIST uniform(a,b) or normal(mean,std) (repeatable; "
                                "crossed with --grid if both are given)")
        sweep.add_argument("--samples", type=int, default=10, metavar="N", help="random samples (default: 10)")
        sweep.add_argument("--seed", type=int, default=0, metavar="S", help="random seed (default: 0)")
        sweep.add_argument("--points", type=Path, metavar="FILE.csv",
                           help="points file: header of BLOCK.PARAM columns, one point per row")
        sweep.add_argument("--metric", action="append", default=[], dest="metrics", metavar="NAME=EXPR",
                           help=f"{REDUCERS_HELP}; or {measures_help}")
        where = sweep.add_mutually_exclusive_group()
        where.add_argument("--workers", type=int, metavar="N",
                           help="run on a LocalCluster of N worker processes from the start (default: start "
                                "locally, then one worker per core if the work is worth it; 0 = in this process)")
        where.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                           help="use the workers of a running scheduler")
        where.add_argument("--serial", action="store_true", help="run the points in this process, one by one")
        sweep.add_argument("--t-end", "--stop-time", dest="t_end", metavar="T",
                           help="end time of every run (default: the diagram's time.t_end)")
        sweep.add_argument("--keep-results", action="store_true",
                           help="also keep every run's signals.npz and run.json, in DIR/runs/<point hash>/ "
                                "(written by this process; a failed run's partial results too)")
        trust_arg(sweep)
        sweep.add_argument("-q", "--quiet", action="store_true", help="no progress line or summary")
        sweep.set_defaults(handler=cmd_sweep)
        return sweep
    return add


def plot(sub, program) -> argparse.ArgumentParser:
    """The ``sweep-plot`` command."""
    splot = sub.add_parser("sweep-plot", help="plot a metric of a sweep against one or two parameters",
                           description="A line plot of METRIC over PARAM (one line per combination of the "
                                       "other parameters, or their mean when there are many), or a heat "
                                       "map over two parameters (other parameters averaged).")
    splot.add_argument("sweep_dir", type=Path, metavar="DIR", help=f"sweep folder of '{program.name} sweep'")
    splot.add_argument("--x", required=True, metavar="PARAM", help="parameter on the x axis, e.g. prop.k")
    splot.add_argument("--y", metavar="PARAM", help="second parameter: draws a heat map")
    splot.add_argument("--metric", required=True, metavar="NAME", help="metric column to plot")
    splot.add_argument("-o", "--output", type=Path, required=True, metavar="FILE.png", help="PNG file to write")
    splot.set_defaults(handler=cmd_sweep_plot)
    return splot


def sweep_points(args: argparse.Namespace) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """The points the options give, and the axes that sweep.json records."""
    from blocks.sweep.points import combine, csv_points, grid_points, parse_grid, parse_random, random_points

    axes: dict[str, Any] = {}
    if args.points is not None:
        axes["points_file"] = str(args.points)
        return csv_points(args.points), axes
    grid, dists = parse_grid(args.grid), parse_random(args.random)
    sampled = random_points(dists, args.samples, args.seed) if dists else []
    if grid:
        axes["grid"] = grid
    if dists:
        axes["random"] = {k: f"{kind}({a:g}, {b:g})" for k, (kind, a, b) in dists.items()}
        axes.update(samples=args.samples, seed=args.seed)
    return combine(grid_points(grid) if grid else [], sampled), axes


def cmd_sweep(args: argparse.Namespace) -> int:
    """Check everything, run the missing points, and report; exit 1 if any point failed."""
    from blocks import load_diagram
    from blocks.sweep import SweepError, SweepInterrupted, parse_metrics, run_sweep
    from blocks.sweep.cluster import start_method
    from blocks.sweep.points import origins

    prog, start_variable = args.program.name, args.program.env("SWEEP_START")
    serial = args.serial or args.workers == 0
    method = os.environ.get(start_variable) or None
    try:
        if args.points is not None and (args.grid or args.random):
            raise SweepError("--points cannot be combined with --grid or --random")
        if args.workers is not None and args.workers < 0:
            raise SweepError(f"--workers must be 0 or more, got {args.workers}")
        metrics = parse_metrics(args.metrics)
        points, axes = sweep_points(args)
        if args.t_end is not None:
            end_time(args, load_diagram(args.diagram, trust=args.trust, step=args.step))
        if method and not serial and args.scheduler is None:
            start_method(method, start_variable)
        try:
            summary = run_sweep(args.diagram, points, metrics, args.output, t_end=args.t_end, workers=args.workers,
                                scheduler=args.scheduler, serial=serial, trust=args.trust, progress=not args.quiet,
                                axes=axes, origins=origins(args.grid, args.random, args.points, points),
                                start_method=method, keep_results=args.keep_results, step=args.step)
        except SweepInterrupted as stop:
            from blocks.process.stop import exit_code

            print(f"{prog}: sweep interrupted: {stop.stored} of {stop.total} points are in {stop.csv} "
                  "(hint: run the same command again to run the rest)", file=sys.stderr)
            return exit_code(stop)
    except SweepError as exc:
        raise UsageError(str(exc)) from None
    report = summary.report
    if not args.quiet:
        print(f"sweep: {summary.points} points: {report.ran} run{where_ran(report)} ({report.failed} failed), "
              f"{summary.skipped} already in {summary.csv}; {summary.wall_s:.3g} s")
    if summary.failed:
        print(f"{prog}: {summary.failed} point(s) failed; see the status and error columns of "
              f"{summary.csv}", file=sys.stderr)
        return EXIT_FAILED
    return EXIT_OK


def where_ran(report) -> str:
    """Where a sweep's points ran, as the summary line says it: in this process, in a local
    process, on the cluster's workers, or split between the local process and the cluster."""
    def workers(n: int) -> str:
        return f"{n} Dask worker{'s' if n != 1 else ''}"

    if report.ran == 0:
        return ""
    if not report.workers:
        return (" in a local process (too little work for a cluster to pay off)" if report.local
                else " in this process")
    on_cluster = report.ran - report.local
    if not report.local:
        return f" on {workers(report.workers)}"
    if not on_cluster:
        return f" in a local process, all before the cluster of {workers(report.workers)} was ready"
    return (f": {on_cluster} on {workers(report.workers)}, {report.local} in a local process "
            "while the cluster started")


def cmd_sweep_plot(args: argparse.Namespace) -> int:
    """Plot one metric of a finished sweep to a PNG file."""
    from blocks.sweep import SweepError
    from blocks.sweep.plot import plot_sweep
    from blocks.sweep.store import NotASweep

    picture_output(args.output)
    try:
        written = plot_sweep(args.sweep_dir, args.x, args.metric, args.output, y=args.y)
    except NotASweep as exc:
        raise UsageError(str(NotASweep(exc.directory, f"the -o folder of '{args.program.name} sweep'"))) from None
    except SweepError as exc:
        raise UsageError(str(exc)) from None
    print(f"wrote {written}")
    return EXIT_OK

