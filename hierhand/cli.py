"""The ``hierhand`` command line: run, validate, graph, plot, sweep and list blocks.

Exit codes: 0 ok, 2 bad input (a one-line message per problem, no traceback), 1 a failure
during a simulation (the message names block, time and signal; partial results are kept)
or results that could not be saved where asked, 130 Ctrl-C and 143 SIGTERM (a run saves
what it computed, marked interrupted).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Any, Sequence

import yaml

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2
EXIT_INTERRUPTED = 130


class UsageError(Exception):
    """Bad command-line input, reported as one line with exit code 2."""


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    from blocks import DiagramError, ResultsError

    try:
        return args.handler(args)
    except DiagramError as exc:
        for issue in exc.issues:
            print(str(issue), file=sys.stderr)
        return EXIT_BAD_INPUT
    except (UsageError, ResultsError) as exc:
        print(f"hierhand: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as exc:
        from hierhand.stop_signals import exit_code

        print("hierhand: interrupted", file=sys.stderr)
        return exit_code(exc)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="hierhand",
        description="Multirate block-diagram co-simulation: run YAML diagrams, inspect and plot them.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    run = sub.add_parser("run", help="simulate a diagram and write its results",
                         description="Simulate DIAGRAM and write signals.npz and run.json to the output folder.")
    _diagram_args(run)
    run.add_argument("-o", "--output", type=Path,
                     help="results folder (default: runs/<diagram name>, the name made one safe folder name)")
    run.add_argument("--csv", action="store_true", help="also write signals.csv")
    run.add_argument("--plot", action="store_true", help="also plot the logged signals to <output>/plots/")
    run.add_argument("-q", "--quiet", action="store_true", help="no progress bar or summary line")
    run.set_defaults(handler=cmd_run)

    validate = sub.add_parser("validate", help="check a diagram and print its schedule",
                              description="Check DIAGRAM and print blocks, periods, base tick, "
                                          "hyperperiod and execution order.")
    _diagram_args(validate)
    validate.set_defaults(handler=cmd_validate)

    graph = sub.add_parser("graph", help="draw the wiring of a diagram (DOT, SVG or PNG)")
    _diagram_args(graph)
    graph.add_argument("-o", "--output", type=Path,
                       help="file to write: .dot, .svg or .png (default: DOT text on stdout)")
    graph.set_defaults(handler=cmd_graph)

    plot = sub.add_parser("plot", help="plot logged signals of a run",
                          description="Plot signals of a results folder, one axis per signal.")
    plot.add_argument("run_dir", type=Path, metavar="RUN_DIR", help="results folder of 'hierhand run'")
    plot.add_argument("-s", "--signal", action="append", dest="signals", metavar="BLOCK.PORT",
                      help="signal to plot (repeatable; default: all logged signals)")
    plot.add_argument("-o", "--output", type=Path, help="PNG file (default: RUN_DIR/plots/signals.png)")
    plot.set_defaults(handler=cmd_plot)

    animate = sub.add_parser("animate", help="animate the hand, object and contact forces of a run (GIF)",
                             description="Write a GIF of the hand, the object and the contact force arrows "
                                         "over time from a results folder (needs PLANT.q and PLANT.obj logged; "
                                         "arrows need PLANT.fn, PLANT.ft and PLANT.normal).")
    animate.add_argument("run_dir", type=Path, metavar="RUN_DIR", help="results folder of 'hierhand run'")
    animate.add_argument("-o", "--output", type=Path, required=True, metavar="FILE.gif", help="GIF file to write")
    animate.add_argument("--fps", type=float, default=25.0, help="GIF frames per second (default: 25)")
    timing = animate.add_mutually_exclusive_group()
    timing.add_argument("--speed", type=float, default=1.0,
                        help="simulated seconds per second of GIF (default: 1; 0.1 = ten times slower)")
    timing.add_argument("--every", type=int, metavar="N",
                        help="instead of --speed: a frame at every N-th logged sample of PLANT.q")
    animate.add_argument("--plant", metavar="NAME", help="the HandPlant block (needed if the run has several)")
    animate.set_defaults(handler=cmd_animate)

    rep = sub.add_parser("reproduce", help="run the paper's three tasks: figures, summary.json, report.md",
                         description="Run the grasp, manipulation and re-grasp tasks (with and without "
                                     "suppresser) and write fig09.png ... fig14.png, summary.json and report.md.")
    rep.add_argument("-o", "--output", type=Path, default=Path("runs/reproduce"),
                     help="output folder (default: runs/reproduce)")
    rep.add_argument("--diagrams", type=Path, default=None,
                     help="folder of the task diagrams (default: the repository's diagrams/)")
    rep.set_defaults(handler=cmd_reproduce)

    fmu = sub.add_parser("fmu", help="export the hand plant as an FMU, or describe an FMU")
    fmu_sub = fmu.add_subparsers(dest="fmu_command", required=True, metavar="FMU_COMMAND")
    export = fmu_sub.add_parser("export", help="package the hand plant as an FMI co-simulation FMU",
                                description="Package the HandPlant as an FMI 2.0 or 3.0 co-simulation FMU: "
                                            "the plant's C core as a native binary (Linux, no Python needed "
                                            "at the importer) plus its C sources. Its parameters are the "
                                            "hand file's values.")
    export.add_argument("--fmi", type=int, choices=(2, 3), default=2, help="FMI version (default: 2)")
    export.add_argument("--hand", type=Path, metavar="FILE", help="hand file (default: the shipped hand)")
    export.add_argument("-o", "--output", type=Path, metavar="PATH",
                        help="FMU file or folder to write (default: fmu/)")
    export.set_defaults(handler=cmd_fmu_export)
    info = fmu_sub.add_parser("info", help="variables, causality, default experiment, interface types")
    info.add_argument("path", type=Path, metavar="PATH", help="FMU file")
    info.set_defaults(handler=cmd_fmu_info)

    sweep = sub.add_parser("sweep", help="run a diagram at many parameter points (Dask), one CSV row each",
                           description="Run DIAGRAM at every point of a grid, random samples or a points "
                                       "file, on a Dask LocalCluster (default: one single-threaded worker "
                                       "process per core) or a running scheduler, appending one row per "
                                       "finished run to OUTPUT/sweep.csv. Re-running the same command "
                                       "resumes: points already in the file are skipped.")
    sweep.add_argument("diagram", type=Path, metavar="DIAGRAM", help="YAML diagram file")
    sweep.add_argument("-o", "--output", type=Path, required=True, metavar="DIR",
                       help="sweep folder: sweep.csv and sweep.json")
    sweep.add_argument("--grid", action="append", default=[], metavar="BLOCK.PARAM=V1,V2,...",
                       help="grid axis, values read as YAML (repeatable: cartesian product), "
                            "e.g. --grid suppress.S_b=0.05,0.1,0.2")
    sweep.add_argument("--random", action="append", default=[], metavar="BLOCK.PARAM=DIST",
                       help="random axis, DIST uniform(a,b) or normal(mean,std) (repeatable; "
                            "crossed with --grid if both are given)")
    sweep.add_argument("--samples", type=int, default=10, metavar="N", help="random samples (default: 10)")
    sweep.add_argument("--seed", type=int, default=0, metavar="S", help="random seed (default: 0)")
    sweep.add_argument("--points", type=Path, metavar="FILE.csv",
                       help="points file: header of BLOCK.PARAM columns, one point per row")
    sweep.add_argument("--metric", action="append", default=[], dest="metrics", metavar="NAME=EXPR",
                       help="a column per run (repeatable): REDUCER(BLOCK.PORT[i]) with final, max, min, "
                            "mean, first_time_above(BLOCK.PORT[i], X), first_time_below(BLOCK.PORT[i], X); "
                            "or a hand task measure: separation_time, object_dropped, peak_ratio[(T)], "
                            "recovery_time[(T)]")
    where = sweep.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, metavar="N",
                       help="LocalCluster worker processes (default: one per core; 0 = in this process)")
    where.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="use the workers of a running scheduler")
    where.add_argument("--serial", action="store_true", help="run the points in this process, one by one")
    sweep.add_argument("--t-end", "--stop-time", dest="t_end", metavar="T",
                       help="end time of every run (default: the diagram's time.t_end)")
    sweep.add_argument("--trust", action="store_true",
                       help="allow 'python:module:Class' block types, which import code named in the diagram")
    sweep.add_argument("-q", "--quiet", action="store_true", help="no progress line or summary")
    sweep.set_defaults(handler=cmd_sweep)

    splot = sub.add_parser("sweep-plot", help="plot a metric of a sweep against one or two parameters",
                           description="A line plot of METRIC over PARAM (one line per combination of the "
                                       "other parameters, or their mean when there are many), or a heat "
                                       "map over two parameters (other parameters averaged).")
    splot.add_argument("sweep_dir", type=Path, metavar="DIR", help="sweep folder of 'hierhand sweep'")
    splot.add_argument("--x", required=True, metavar="PARAM", help="parameter on the x axis, e.g. suppress.S_b")
    splot.add_argument("--y", metavar="PARAM", help="second parameter: draws a heat map")
    splot.add_argument("--metric", required=True, metavar="NAME", help="metric column to plot")
    splot.add_argument("-o", "--output", type=Path, required=True, metavar="FILE.png", help="PNG file to write")
    splot.set_defaults(handler=cmd_sweep_plot)

    types = sub.add_parser("blocks", help="list block types with their ports and parameters")
    types.add_argument("types", nargs="*", metavar="TYPE", help="only these types")
    types.set_defaults(handler=cmd_blocks)
    return parser


def _diagram_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("diagram", type=Path, metavar="DIAGRAM", help="YAML diagram file")
    p.add_argument("--set", action="append", default=[], dest="overrides", metavar="BLOCK.PARAM=VALUE",
                   help="override a parameter (value read as YAML; repeatable), e.g. --set prop.k=2")
    p.add_argument("--t-end", "--stop-time", dest="t_end", metavar="T",
                   help="end time, e.g. 2, '0.5 s' or '300 ms' (default: the diagram's time.t_end)")
    p.add_argument("--trust", action="store_true",
                   help="allow 'python:module:Class' block types, which import code named in the diagram")


def _version() -> str:
    from importlib import metadata

    try:
        return metadata.version("hierhand")
    except metadata.PackageNotFoundError:
        return "(not installed)"


def parse_overrides(items: Sequence[str]) -> dict[str, Any]:
    """``["plant.k=2", "ctrl.gains=[1, 2]"]`` -> {"plant.k": 2, "ctrl.gains": [1, 2]}."""
    overrides: dict[str, Any] = {}
    for item in items:
        key, eq, text = item.partition("=")
        key = key.strip()
        if not eq or "." not in key or not all(key.split(".")):
            raise UsageError(f"--set {item!r}: expected BLOCK.PARAM=VALUE, e.g. --set prop.k=2")
        try:
            overrides[key] = yaml.safe_load(text) if text.strip() else None
        except yaml.YAMLError as exc:
            first = str(exc).splitlines()[0]
            raise UsageError(f"--set {item!r}: the value is not valid YAML ({first})") from None
        if overrides[key] is None:
            raise UsageError(f"--set {item!r}: no value after '='")
    return overrides


def load(args: argparse.Namespace):
    from blocks import load_diagram

    return load_diagram(args.diagram, overrides=parse_overrides(args.overrides), trust=args.trust)


def end_time(args: argparse.Namespace, diagram):
    from blocks import DiagramError
    from blocks.timebase import DurationError, parse_duration

    if args.t_end is None:
        if diagram.t_end is None:
            raise DiagramError([diagram.issue(None, "no end time", "add time: {t_end: 1 s} to the "
                                              "diagram or pass --t-end")])
        return diagram.t_end
    try:
        t_end = parse_duration(args.t_end)
    except DurationError as exc:
        raise UsageError(f"--t-end: {exc}") from None
    if t_end <= 0:
        raise UsageError(f"--t-end must be positive, got {args.t_end!r}")
    return t_end


class ProgressBar:
    """The run's progress on stderr: only on a terminal, and only once a run takes a second."""

    def __init__(self, t_end: float, enabled: bool):
        from hierhand.status_line import StatusLine

        self.t_end = t_end
        self.line = StatusLine(enabled)

    def __call__(self, fraction: float, elapsed: float) -> None:
        if elapsed < 1.0 and not self.line.shown:
            return
        width = 30
        filled = int(width * fraction)
        eta = elapsed * (1 - fraction) / fraction if fraction > 0 else float("nan")
        self.line.show(f"[{'#' * filled}{'.' * (width - filled)}] {100 * fraction:5.1f}%  "
                       f"t = {fraction * self.t_end:.4g} / {self.t_end:.4g} s  eta {eta:5.1f} s")

    def close(self) -> None:
        self.line.close()


def cmd_run(args: argparse.Namespace) -> int:
    """Simulate and save. The output folder is checked before the run; Ctrl-C or SIGTERM
    stops the run and its results so far are saved, and no signal cuts the saving short
    (``stop_signals``); after an interrupt the plots are skipped, to stop soon. A run that
    a block ends early (``EndRun``) is complete: it says where and why, even with -q."""
    from blocks import DiagramError, simulate
    from blocks.results_folder import OutputFolderError
    from blocks.safepath import folder_name
    from hierhand.run_output import check_output, remove_if_empty, save_run
    from hierhand.stop_signals import StopSignals, exit_code

    diagram = load(args)
    t_end = end_time(args, diagram)
    out = args.output or Path("runs") / folder_name(diagram.name)
    try:
        created = check_output(out)
    except OutputFolderError as exc:
        raise UsageError(f"output folder {exc}") from None
    bar = ProgressBar(float(t_end), enabled=not args.quiet)
    with StopSignals() as stops:
        try:
            results = simulate(diagram, t_end=t_end, progress=bar)
        except (DiagramError, KeyboardInterrupt):  # refused, or stopped, before it started
            if created:
                remove_if_empty(out)
            raise
        finally:
            bar.close()
        with stops.held():
            saved = save_run(results, out, csv=args.csv, plot=args.plot and not results.interrupted)
    if not results.complete:
        print(f"hierhand: {diagram.file}: {results.status}", file=sys.stderr)
    if saved.problem:
        print(f"hierhand: {saved.problem}", file=sys.stderr)
        return EXIT_FAILED
    if not results.complete:
        skipped = (f"; plots skipped after the interrupt ('hierhand plot {out}' draws them)"
                   if args.plot and results.interrupted else "")
        print(f"hierhand: partial results (marked incomplete) saved in {out}{skipped}", file=sys.stderr)
        return exit_code(stops.received) if results.interrupted else EXIT_FAILED
    if results.ended_by is not None:
        print(f"{diagram.name}: {results.end_note}")
    if not args.quiet:
        info = results.info
        rtf = info.get("real_time_factor")
        simulated = results.stop_time if results.ended_by is not None else float(t_end)
        print(f"{diagram.name}: {simulated:g} s simulated in {info['wall_time_s']:.3g} s"
              + (f" ({rtf:.3g}x real time)" if rtf else "") + f"; results in {out}"
              + (f", plots: {', '.join(str(p) for p in saved.plots)}" if saved.plots else ""))
    return EXIT_OK


def cmd_validate(args: argparse.Namespace) -> int:
    from blocks import build_schedule
    from blocks.timebase import format_duration

    diagram = load(args)
    t_end = end_time(args, diagram) if (args.t_end or diagram.t_end) else None
    s = build_schedule(diagram, t_end)
    print(f"diagram {diagram.name!r} ({diagram.file}): valid")
    if diagram.description:
        print(f"  {diagram.description}")
    print(f"base tick: {format_duration(s.base_tick)}; hyperperiod: {s.hyperperiod} ticks "
          f"({format_duration(s.hyperperiod * s.base_tick)})"
          + (f"; t_end: {format_duration(t_end)} = {s.n_ticks} ticks" if t_end else ""))
    print("blocks:")
    wn = max(len(n) for n in diagram.blocks)
    wt = max(len(b.type_name) for b in diagram.blocks.values())
    for name, spec in diagram.blocks.items():
        blk = spec.block
        ins = ", ".join(f"{p}[{w}]" for p, w in blk.inputs.items()) or "-"
        outs = ", ".join(f"{p}[{w}]" for p, w in blk.outputs.items()) or "-"
        notes = []
        if name in s.advanced:
            notes.append("advanced between events")
        if blk.has_feedthrough():
            notes.append("feedthrough")
        if any(blk.initial_reads(p) != blk.reads(p) for p in blk.outputs):
            initial = sorted(set().union(*(blk.initial_reads(p) for p in blk.outputs)))
            notes.append(f"feedthrough at t = 0 from {', '.join(initial)}" if initial
                         else "no feedthrough at t = 0")
        print(f"  {name:<{wn}}  {spec.type_name:<{wt}}  {s.rate_text(name):<22} in: {ins}  out: {outs}"
              + (f"  ({', '.join(notes)})" if notes else ""))
    print_references_and_notes(diagram)
    print("execution order:")
    print(f"  t = 0: {s.initial.describe()}")
    for held in s.initial_held:
        print(f"    {held.block}.{held.port} holds its initial value at t = 0: {held.block} is computed "
              f"before its source, which depends on it ({held.loop})")
    seen: dict[int, list[int]] = {}
    for r, j in zip(s.event_ticks, s.event_programs):
        seen.setdefault(j, []).append(int(r))
    for j, ticks in seen.items():
        at = ", ".join(format_duration(r * s.base_tick) for r in ticks[:6]) + (", ..." if len(ticks) > 6 else "")
        print(f"  at {at} (mod {format_duration(s.hyperperiod * s.base_tick)}): {s.programs[j].describe()}")
    if not s.event_ticks.size and s.advanced:
        print(f"  no other events: {', '.join(sorted(s.advanced))} advanced from t = 0 to t_end")
    return EXIT_OK


def print_references_and_notes(diagram) -> None:
    """``validate``'s block references (``reflex.hand -> plant``) and, per block, where its
    configuration comes from: its params_file, its own ``describe()``, who refers to it."""
    references = diagram.references()
    if references:
        print("references:")
        for ref in references:
            print(f"  {ref}")
    notes = []
    for name, spec in diagram.blocks.items():
        users = [f"{r.block}.{r.param}" for r in references if r.target == name]
        parts = [f"params_file {spec.params_file}" if spec.params_file else "", spec.block.describe(),
                 f"referenced by {', '.join(users)}" if users else ""]
        if any(parts):
            notes.append(f"  {name}: {'; '.join(p for p in parts if p)}")
    if notes:
        print("notes:")
        print("\n".join(notes))
    conversions = diagram.conversions()
    if conversions:
        print("conversions (connections between ports of different types):")
        for conversion in conversions:
            print(f"  {conversion}")


def cmd_graph(args: argparse.Namespace) -> int:
    from blocks import build_schedule
    from blocks.graph import render, to_dot

    diagram = load(args)
    schedule = build_schedule(diagram, None)
    out = args.output
    if out is None:
        sys.stdout.write(to_dot(diagram, schedule))
        return EXIT_OK
    suffix = out.suffix.lower()
    if suffix in (".dot", ".gv"):
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(to_dot(diagram, schedule), encoding="utf-8")
    elif suffix in (".svg", ".png", ".pdf"):
        render(diagram, schedule, out)
    else:
        raise UsageError(f"-o {out}: unknown format {suffix or '(none)'!r}; use .dot, .svg or .png")
    print(f"wrote {out}")
    return EXIT_OK


def cmd_plot(args: argparse.Namespace) -> int:
    from blocks import Results
    from blocks.plot import plot_signals

    results = Results.load(args.run_dir)
    out = args.output or args.run_dir / "plots" / "signals.png"
    try:
        written = plot_signals(results, out, args.signals)
    except (KeyError, ValueError) as exc:
        raise UsageError(str(exc).strip("'\"")) from None
    for path in written:
        print(f"wrote {path}")
    return EXIT_OK


def cmd_animate(args: argparse.Namespace) -> int:
    from blocks import Results
    from hierhand.animation import AnimationError, animate_run

    results = Results.load(args.run_dir)
    try:
        written = animate_run(results, args.output, fps=args.fps, speed=args.speed,
                              plant=args.plant, every=args.every)
    except AnimationError as exc:
        raise UsageError(str(exc)) from None
    print(f"wrote {written}")
    return EXIT_OK


def cmd_reproduce(args: argparse.Namespace) -> int:
    from hierhand.tasks.reproduce import DEFAULT_DIAGRAMS, MissingDiagram, ReproduceError, reproduce

    try:
        summary = reproduce(args.output, args.diagrams or DEFAULT_DIAGRAMS, report=print)
    except MissingDiagram as exc:
        raise UsageError(str(exc)) from None
    except ReproduceError as exc:
        print(f"hierhand: {exc}", file=sys.stderr)
        return EXIT_FAILED
    r = summary["regrasp"]
    print(f"grasp: peak ratio {summary['grasp']['peak_ratio']:.3f}, steady max "
          f"{summary['grasp']['steady_ratio_max']:.3f}; manipulation: position error "
          f"{1000 * summary['manipulation']['position_error_m']:.2f} mm; re-grasp: forefinger separates at "
          f"{r['suppressed']['fore_separation_time_s']} s with suppresser, "
          f"{r['unsuppressed']['fore_separation_time_s']} without")
    print(f"wrote {args.output}/summary.json, report.md and fig09.png ... fig14.png")
    return EXIT_OK


def cmd_fmu_export(args: argparse.Namespace) -> int:
    from blocks import DiagramError
    from hierhand.fmu_export import FmuExportError, export_plant_fmu
    from hierhand.model import HandFileError

    if args.hand is not None and not args.hand.exists():
        raise UsageError(f"--hand {args.hand}: hand file not found")
    try:
        path = export_plant_fmu(args.output, fmi=args.fmi, hand=args.hand)
    except HandFileError as exc:
        raise DiagramError(exc.issues()) from None
    except (FmuExportError, OSError) as exc:
        raise UsageError(f"fmu export: {exc}") from None
    print(f"wrote {path}")
    return EXIT_OK


def cmd_fmu_info(args: argparse.Namespace) -> int:
    from blocks.fmu import FMUInfoError, describe_fmu

    try:
        print(describe_fmu(args.path))
    except FMUInfoError as exc:
        raise UsageError(str(exc)) from None
    return EXIT_OK


def cmd_sweep(args: argparse.Namespace) -> int:
    import time

    from blocks import load_diagram
    from hierhand.sweep import SweepError
    from hierhand.sweep.metrics import parse_metrics
    from hierhand.sweep.plan import execute, prepare, stored_count
    from hierhand.sweep.points import (combine, csv_points, grid_points, origins, parse_grid, parse_random,
                                       random_points)

    try:
        if args.points is not None and (args.grid or args.random):
            raise SweepError("--points cannot be combined with --grid or --random")
        if args.workers is not None and args.workers < 0:
            raise SweepError(f"--workers must be 0 or more, got {args.workers}")
        metrics = parse_metrics(args.metrics)
        axes: dict[str, Any] = {}
        if args.points is not None:
            points = csv_points(args.points)
            axes["points_file"] = str(args.points)
        else:
            grid, dists = parse_grid(args.grid), parse_random(args.random)
            sampled = random_points(dists, args.samples, args.seed) if dists else []
            points = combine(grid_points(grid) if grid else [], sampled)
            if grid:
                axes["grid"] = grid
            if dists:
                axes["random"] = {k: f"{kind}({a:g}, {b:g})" for k, (kind, a, b) in dists.items()}
                axes.update(samples=args.samples, seed=args.seed)
        if args.t_end is not None:
            end_time(args, load_diagram(args.diagram, trust=args.trust))
        plan = prepare(args.diagram, points, metrics, t_end=args.t_end, trust=args.trust, axes=axes,
                       origins=origins(args.grid, args.random, args.points, points))
        t0 = time.perf_counter()
        try:
            report, skipped, failed = execute(plan, args.output, workers=args.workers, scheduler=args.scheduler,
                                              serial=args.serial or args.workers == 0, progress=not args.quiet)
        except KeyboardInterrupt:
            print(f"hierhand: sweep interrupted: {stored_count(plan, args.output)} of {len(plan.points)} points "
                  f"are in {args.output / 'sweep.csv'} (hint: run the same command again to run the rest)",
                  file=sys.stderr)
            return EXIT_INTERRUPTED
    except SweepError as exc:
        raise UsageError(str(exc)) from None
    if not args.quiet:
        where = ("" if report.ran == 0 else " in this process" if report.workers == 0
                 else f" on {report.workers} Dask worker(s)")
        print(f"sweep: {len(plan.points)} points: {report.ran} run{where} ({report.failed} failed), "
              f"{skipped} already in {args.output / 'sweep.csv'}; {time.perf_counter() - t0:.3g} s")
    if failed:
        print(f"hierhand: {failed} point(s) failed; see the status and error columns of "
              f"{args.output / 'sweep.csv'}", file=sys.stderr)
        return EXIT_FAILED
    return EXIT_OK


def cmd_sweep_plot(args: argparse.Namespace) -> int:
    from hierhand.sweep import SweepError
    from hierhand.sweep.plot import plot_sweep

    if args.output.suffix.lower() != ".png":
        raise UsageError(f"-o {args.output}: write a .png file")
    try:
        written = plot_sweep(args.sweep_dir, args.x, args.metric, args.output, y=args.y)
    except SweepError as exc:
        raise UsageError(str(exc)) from None
    print(f"wrote {written}")
    return EXIT_OK


def cmd_blocks(args: argparse.Namespace) -> int:
    from blocks.registry import block_types
    from blocks.typeinfo import describe_type

    types = block_types()
    wanted = args.types or sorted(types)
    unknown = [t for t in wanted if t not in types]
    if unknown:
        raise UsageError(f"unknown block type(s): {', '.join(unknown)}; known: {', '.join(sorted(types))}")
    print("\n\n".join(describe_type(types[name]) for name in wanted))
    return EXIT_OK


def entry() -> None:
    """Console-script entry point."""
    if os.environ.get("HIERHAND_DEBUG"):
        sys.exit(main())
    try:
        sys.exit(main())
    except BrokenPipeError:  # e.g. 'hierhand blocks | head': the reader has gone, nothing to report
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        sys.exit(EXIT_OK)
    except Exception as exc:  # an internal error still gets one line and a way to see more
        print(f"hierhand: internal error: {type(exc).__name__}: {exc} "
              "(set HIERHAND_DEBUG=1 for the traceback, and please report it)", file=sys.stderr)
        sys.exit(EXIT_FAILED)


if __name__ == "__main__":
    entry()
