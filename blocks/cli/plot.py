"""``plot``: the logged signals of a results folder as PNG, SVG or PDF: an axis per
selection, elements by label or index, signals overlaid, the diagram's events marked."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .options import picture_output
from .program import EXIT_FAILED, EXIT_OK, UsageError

SELECTION_HELP = ("an axis: a signal (plant.q), elements of it by label or 0-based index "
                  "(plant.q[fore.1], plant.q[0:3], plant.q[thumb.1,fore.1]), or several such "
                  "separated by commas to overlay them (plant.q[fore.1],ref.y); repeat for more "
                  "axes (default: every logged signal, an axis each)")


def add(sub, program) -> argparse.ArgumentParser:
    """The ``plot`` command."""
    plot = sub.add_parser("plot", help="plot logged signals of a run",
                          description="Plot signals of a results folder: an axis per -s, with the diagram's "
                                      "events (Step times, and what the application marks) as dotted lines "
                                      "and bands.")
    plot.add_argument("run_dir", type=Path, metavar="RUN_DIR", help=f"results folder of '{program.name} run'")
    plot.add_argument("-s", "--signal", action="append", dest="signals", metavar="SELECTION", help=SELECTION_HELP)
    plot.add_argument("--no-markers", action="store_true", help="do not mark the diagram's events")
    plot.add_argument("-o", "--output", type=Path, metavar="FILE.png",
                      help="the picture: FILE.png, FILE.svg or FILE.pdf (default: RUN_DIR/plots/signals.png); "
                           "more axes than fit one page make pages FILE-1.png, FILE-2.png, ...")
    plot.set_defaults(handler=cmd_plot)
    return plot


def cmd_plot(args: argparse.Namespace) -> int:
    """Plot the chosen selections (default: every signal) and print the files written.
    The selections are checked here; the pages are drawn by a plotter process
    (``blocks.plot.beside_run``, the pages shared out between a process per core) where there is one, else here."""
    from blocks.plot.beside_run import plotter_beside

    with plotter_beside(warm_page=False) as plotter:  # no run to overlap: a warm-up page would only delay
        return plot_folder(args, plotter)


def plot_folder(args: argparse.Namespace, plotter) -> int:
    from blocks import Results
    from blocks.plot.pages import FORMATS, Pages, plot_signals
    from blocks.plot.markers import markers
    from blocks.plot.beside_run import PlotProcessError

    from .run_output import describe

    out = args.run_dir / "plots" / "signals.png" if args.output is None else picture_output(args.output, FORMATS)
    results = Results.load(args.run_dir)
    events: list = []
    if not args.no_markers:
        events, notes = markers(results.info)
        for note in notes:
            print(f"{args.program.name}: note: {note}", file=sys.stderr)
    try:
        if plotter is None:
            written = plot_signals(results, out, args.signals, markers=events)
        else:
            Pages.of(results, out, args.signals, markers=events)  # bad selections: said before a page is drawn
            written = plotter.draw(args.run_dir, out, args.signals, markers=not args.no_markers)
    except (KeyError, ValueError) as exc:
        raise UsageError(exc.args[0] if isinstance(exc, KeyError) and exc.args else str(exc)) from None
    except (OSError, PlotProcessError) as exc:
        print(f"{args.program.name}: the plots could not be written: "
              f"{describe(exc) if isinstance(exc, OSError) else exc}", file=sys.stderr)
        return EXIT_FAILED
    for path in written:
        print(f"wrote {path}")
    return EXIT_OK
