"""``graph``: the wiring of a diagram as DOT text, or drawn to SVG, PNG or PDF: blocks as
records with their ports, wires port to port, colours by rate with a legend; a subsystem
as one box, or (``--expand``) as a frame around its blocks."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .options import diagram_args, load
from .program import EXIT_OK, UsageError


def add(sub, program) -> argparse.ArgumentParser:
    """The ``graph`` command."""
    graph = sub.add_parser("graph", help="draw the wiring of a diagram (DOT, SVG or PNG)",
                           description="Draw DIAGRAM's wiring: each block a box with its name, type, rate "
                                       "and the parameters the diagram gives it, its ports on its edges, "
                                       "wires port to port (delayed ones dashed), colours by rate. .svg, "
                                       ".png and .pdf are drawn with matplotlib; .dot (or no -o) is "
                                       "Graphviz text.")
    diagram_args(graph)
    graph.add_argument("-o", "--output", type=Path,
                       help="file to write: .dot, .svg or .png (default: DOT text on stdout)")
    graph.add_argument("--expand", action="store_true",
                       help="draw the blocks of every subsystem, each subsystem a frame around them")
    graph.set_defaults(handler=cmd_graph)
    return graph


def cmd_graph(args: argparse.Namespace) -> int:
    """Write the wiring where -o says, by its suffix, or print the DOT text."""
    from blocks import build_schedule
    from blocks.graph import render, to_dot

    diagram = load(args)
    schedule = build_schedule(diagram, None)
    out = args.output
    if out is None:
        sys.stdout.write(to_dot(diagram, schedule, args.expand))
        return EXIT_OK
    suffix = out.suffix.lower()
    try:
        if suffix in (".dot", ".gv"):
            out.parent.mkdir(parents=True, exist_ok=True)
            out.write_text(to_dot(diagram, schedule, args.expand), encoding="utf-8")
        elif suffix in (".svg", ".png", ".pdf"):
            render(diagram, schedule, out, args.expand)
        else:
            raise UsageError(f"-o {out}: unknown format {suffix or '(none)'!r}; use .dot, .svg or .png")
    except OSError as exc:  # a folder on the way is a file, not writable, ...
        raise UsageError(f"-o {out}: cannot write it: {exc.strerror or exc}") from None
    print(f"wrote {out}")
    return EXIT_OK
