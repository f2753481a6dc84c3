"""``plot``: the logged signals of a results folder, one axis per signal, as PNG."""

from __future__ import annotations

import argparse
from pathlib import Path

from .program import EXIT_OK, UsageError


def add(sub, program) -> argparse.ArgumentParser:
    """The ``plot`` command."""
    plot = sub.add_parser("plot", help="plot logged signals of a run",
                          description="Plot signals of a results folder, one axis per signal.")
    plot.add_argument("run_dir", type=Path, metavar="RUN_DIR", help=f"results folder of '{program.name} run'")
    plot.add_argument("-s", "--signal", action="append", dest="signals", metavar="BLOCK.PORT",
                      help="signal to plot (repeatable; default: all logged signals)")
    plot.add_argument("-o", "--output", type=Path, help="PNG file (default: RUN_DIR/plots/signals.png)")
    plot.set_defaults(handler=cmd_plot)
    return plot


def cmd_plot(args: argparse.Namespace) -> int:
    """Plot the chosen signals (default: all) and print the files written."""
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
