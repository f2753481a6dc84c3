"""``run``: simulate a diagram and write its results folder, with a progress bar on a terminal."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .options import diagram_args, end_time, load
from .program import EXIT_FAILED, EXIT_OK, UsageError


def add(sub, program) -> argparse.ArgumentParser:
    """The ``run`` command."""
    run = sub.add_parser("run", help="simulate a diagram and write its results",
                         description="Simulate DIAGRAM and write signals.npz and run.json to the output folder.")
    diagram_args(run)
    run.add_argument("-o", "--output", type=Path,
                     help="results folder (default: runs/<diagram name>, the name made one safe folder name)")
    run.add_argument("--csv", action="store_true", help="also write signals.csv")
    run.add_argument("--csv-digits", type=int, metavar="N",
                     help="significant digits of signals.csv's numbers, 1 to 17 (default: the shortest "
                          "text that reads back as the same double)")
    run.add_argument("--mat", action="store_true",
                     help="also write signals.mat (MATLAB, Octave, scipy.io): each signal's time, values, "
                          "units and element names")
    run.add_argument("--decimate", type=int, metavar="N",
                     help="log every N-th sample of each logged signal (on top of the diagram's own "
                          "decimate), for long runs")
    run.add_argument("--plot", action="store_true", help="also plot the logged signals to <output>/plots/")
    run.add_argument("-q", "--quiet", action="store_true", help="no progress bar or summary line")
    run.add_argument("--allow-nonfinite", action="store_true",
                     help="let outputs be NaN or infinite (by default the first such value fails the run)")
    run.set_defaults(handler=cmd_run)
    return run


class ProgressBar:
    """The run's progress in simulated seconds on stderr (``blocks.process.progress``): only
    on a terminal, without -q, and only once a run takes a second."""

    def __init__(self, t_end: float, enabled: bool):
        from blocks.process.progress import progress_bar, shows

        self.t_end = t_end
        self.bar = progress_bar(t_end, "run", unit="s", enabled=enabled, delay=1.0,
                                bar_format="{desc}: {percentage:5.1f}%|{bar}| t = {n:.4g} / {total:.4g} s "
                                           "[{elapsed}<{remaining}]") if shows(enabled) else None
        """None where nothing is drawn (no terminal, -q): then tqdm is not even imported."""

    def __call__(self, fraction: float, elapsed: float) -> None:
        """The simulate callback: ``fraction`` of the run done after ``elapsed`` seconds."""
        if self.bar is not None:
            self.bar.update(fraction * self.t_end - self.bar.n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def check_formats(args: argparse.Namespace) -> None:
    """UsageError for a --csv-digits or --decimate out of range, before anything is loaded."""
    from blocks.results.signals import check_digits

    if args.csv_digits is not None:
        if not args.csv:
            raise UsageError("--csv-digits sets the precision of signals.csv: add --csv")
        try:
            check_digits(args.csv_digits)
        except ValueError as exc:
            raise UsageError(f"--csv-digits: {exc}") from None
    if args.decimate is not None and args.decimate < 1:
        raise UsageError(f"--decimate must be a positive whole number, got {args.decimate}")


def check_mat_names(diagram) -> None:
    """UsageError, before the run, for a logged signal that a MAT file cannot name."""
    from blocks.results.mat import MatNameError, mat_paths

    try:
        mat_paths(e.signal for e in diagram.log)
    except MatNameError as exc:
        raise UsageError(f"--mat: {exc}") from None


def cmd_run(args: argparse.Namespace) -> int:
    """``run``; with ``--plot`` a plotter process (``blocks.plot.beside_run``) gets ready to
    draw while the diagram loads and runs."""
    from blocks.plot.beside_run import plotter_beside

    with plotter_beside(args.plot) as plotter:
        return simulate_and_save(args, plotter)


def simulate_and_save(args: argparse.Namespace, plotter) -> int:
    """Simulate and save. The output folder is checked before the run (plots included);
    Ctrl-C or SIGTERM stops the run and its results so far are saved, and no signal cuts
    the saving short (``blocks.process.stop``). Plots are drawn once the files are saved: a signal
    then stops the drawing (the results stay), and after an interrupt they are skipped. A
    signal that comes while a complete run is saved ends the command with its exit code
    once the files are written. A run that a block ends early (``EndRun``) is complete: it
    says where and why, even with -q. A failed or interrupted run that replaces a complete
    one says where the complete one's files went."""
    from blocks import DiagramError, simulate
    from blocks.results.folder import OutputFolderError
    from blocks.safepath import folder_name
    from blocks.process.stop import StopSignals, exit_code

    from .run_output import check_output, remove_if_empty, save_plots, save_run

    prog = args.program.name
    check_formats(args)
    diagram = load(args)
    if args.decimate is not None:
        diagram = diagram.decimated(args.decimate)
    if args.mat:
        check_mat_names(diagram)
    t_end = end_time(args, diagram)
    out = args.output or Path("runs") / folder_name(diagram.name)
    if args.plot:
        from blocks.plot.pages import PlotSizeError, check_plot_size

        try:
            check_plot_size(len(diagram.log), sum(diagram.width(e.signal) for e in diagram.log))
        except PlotSizeError as exc:
            raise UsageError(f"--plot: the diagram logs {len(diagram.log)} signals: {exc}") from None
    try:
        created = check_output(out, plot=args.plot)
    except OutputFolderError as exc:
        raise UsageError(f"output folder {exc}") from None
    bar = ProgressBar(float(t_end), enabled=not args.quiet)
    plots_note = ""
    with StopSignals(prog) as stops:
        try:
            results = simulate(diagram, t_end=t_end, progress=bar, check_finite=not args.allow_nonfinite)
        except (DiagramError, KeyboardInterrupt):  # refused, or stopped, before it started
            if created:
                remove_if_empty(out)
            raise
        finally:
            bar.close()
        with stops.held():
            saved = save_run(results, out, csv=args.csv, mat=args.mat, csv_digits=args.csv_digits,
                             temp_prefix=f"{prog}-results-")
        if args.plot and saved.folder is not None:
            if stops.received is None:
                try:
                    save_plots(results, saved, plotter)
                except KeyboardInterrupt:
                    plots_note = f"; plots stopped by {stops.received or 'SIGINT'}"
            else:
                plots_note = f"; plots skipped after the {stops.received}"
            if plots_note:
                plots_note += f" ('{prog} plot {saved.folder}' draws them)"
    stopped = stops.received
    if not results.complete:
        print(f"{prog}: {diagram.file}: {results.status}", file=sys.stderr)
    if saved.kept is not None:
        print(f"{prog}: the complete run that was in {out} is kept in {saved.kept}", file=sys.stderr)
    if saved.problem:
        print(f"{prog}: {saved.problem}", file=sys.stderr)
        return EXIT_FAILED
    if not results.complete:
        print(f"{prog}: partial results (marked incomplete) saved in {out}{plots_note}", file=sys.stderr)
        return exit_code(stopped) if results.interrupted else EXIT_FAILED
    if results.ended_by is not None:
        print(f"{diagram.name}: {results.end_note}")
    if stopped is not None:
        print(f"{prog}: {stopped} after the run: its results are complete in {out}{plots_note}", file=sys.stderr)
        return exit_code(stopped)
    if not args.quiet:
        info = results.info
        rtf = info.get("real_time_factor")
        simulated = results.stop_time if results.ended_by is not None else float(t_end)
        print(f"{diagram.name}: {simulated:g} s simulated in {info['wall_time_s']:.3g} s"
              + (f" ({rtf:.3g}x real time)" if rtf else "") + f"; results in {out}"
              + (f", plots: {', '.join(str(p) for p in saved.plots)}" if saved.plots else ""))
    return EXIT_OK
