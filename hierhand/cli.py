"""The ``hierhand`` command line: the framework's generic commands plus the hand's own.

``blocks.cli`` provides run, validate, graph, plot, fmu info, sweep, sweep-plot and
blocks, with the exit codes and messages of every command; this module adds what only
the hand application does: ``animate`` (a GIF of a run), ``reproduce`` (the paper's
tasks), ``fmu export`` (a diagram of library and hand blocks, or the plant, as an FMU) and
``examples`` (the shipped diagrams, which every diagram command also takes by name).
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from collections.abc import Sequence
from pathlib import Path

from blocks.cli import EXIT_FAILED, EXIT_OK, Program, UsageError, block_types, entry as run_program
from blocks.cli import fmu, graph, main as run_main, plot, run, schema, ssp, sweep, validate

from hierhand import __version__

DESCRIPTION = "Multirate block-diagram co-simulation: run YAML diagrams, inspect and plot them."
MEASURES_HELP = "a hand task measure: separation_time, object_dropped, peak_ratio[(T)], recovery_time[(T)]"
"""What ``--metric`` may name besides the reducers: the measures hierhand registers
(``hierhand.tasks.measures``, entry-point group ``blocks.measures``)."""


EXPORTED_FMU = re.compile(r"FMU file not found: looked at (?P<path>\S*HandPlant_fmi(?P<fmi>[23])\.fmu)\b")
"""The message of a missing FMU named as ``hierhand fmu export`` names its files."""


def advice(issue) -> str | None:
    """How to make a missing plant FMU of this package (``hierhand fmu export``), and where
    the shipped diagrams are when a diagram file is not found."""
    if issue.message == "diagram file not found":
        return "check the path, or name a shipped diagram: 'hierhand examples' lists them"
    found = EXPORTED_FMU.search(issue.message)
    if found is None:
        return None
    path = os.path.relpath(os.path.normpath(found["path"]))
    return f"make it with 'hierhand fmu export --fmi {found['fmi']} -o {path}'"


def add_animate(sub, program) -> argparse.ArgumentParser:
    """The ``animate`` command."""
    animate = sub.add_parser("animate", help="animate the hand, object and contact forces of a run (GIF or MP4)",
                             description="Write a GIF (or an MP4, with ffmpeg) of the hand, the object and the "
                                         "contact force arrows over time from a results folder, each frame "
                                         "showing the simulated time, the task's phase and the fingers in "
                                         "contact (needs PLANT.q and PLANT.obj logged; arrows need PLANT.fn, "
                                         "PLANT.ft and PLANT.normal).")
    animate.add_argument("run_dir", type=Path, metavar="RUN_DIR", help="results folder of 'hierhand run'")
    animate.add_argument("-o", "--output", type=Path, required=True, metavar="FILE.gif",
                         help="file to write: FILE.gif, or FILE.mp4 (needs ffmpeg)")
    animate.add_argument("--fps", type=float, default=25.0, help="frames per second (default: 25)")
    timing = animate.add_mutually_exclusive_group()
    timing.add_argument("--speed", type=float, default=None,
                        help="simulated seconds per second of animation (0.1 = ten times slower than real "
                             "time; default: a round value making it last about 10 s, 0.1 for a 1 s run)")
    timing.add_argument("--every", type=int, metavar="N",
                        help="instead of --speed: a frame at every N-th logged sample of PLANT.q")
    animate.add_argument("--plant", metavar="NAME", help="the HandPlant block (needed if the run has several)")
    animate.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no report")
    animate.set_defaults(handler=cmd_animate)
    return animate


def add_reproduce(sub, program) -> argparse.ArgumentParser:
    """The ``reproduce`` command."""
    rep = sub.add_parser("reproduce", help="run the paper's three tasks: figures, summary.json, report.md",
                         description="Run the grasp, manipulation and re-grasp tasks (with and without "
                                     "suppresser) and write fig09.png ... fig14.png, summary.json and report.md.")
    rep.add_argument("-o", "--output", type=Path, default=Path("runs/reproduce"),
                     help="output folder (default: runs/reproduce)")
    rep.add_argument("--diagrams", type=Path, default=None,
                     help="folder of the task diagrams (default: the shipped ones, diagrams/ of the "
                          "repository or of the installed package)")
    rep.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no report")
    rep.set_defaults(handler=cmd_reproduce)
    return rep


def add_examples(sub, program) -> argparse.ArgumentParser:
    """The ``examples`` command."""
    examples = sub.add_parser("examples", help="list the shipped diagrams, or copy them into a folder",
                              description="List the diagrams shipped with hierhand (the paper's tasks, the "
                                          "controller, the toy), which any diagram command also takes by name "
                                          "('hierhand run regrasp'); with DIR, copy them and the diagram file's "
                                          "JSON Schema into DIR, to read and change.")
    examples.add_argument("folder", type=Path, nargs="?", metavar="DIR",
                          help="the folder to copy them into (made if need be; files already there are not "
                               "overwritten)")
    examples.set_defaults(handler=cmd_examples)
    return examples


def add_fmu_export(sub, program) -> argparse.ArgumentParser:
    """The ``fmu export`` command: a diagram, or the hand plant alone."""
    export = sub.add_parser("export", help="export a diagram, or the hand plant, as an FMI co-simulation FMU",
                            description="Export DIAGRAM (any diagram of library and hand blocks: the controller, "
                                        "the closed loop) as an FMI 2.0 or 3.0 co-simulation FMU whose binary is "
                                        "the op-table core and the blocks' C kernels, native on Linux, no Python "
                                        "at the importer, with its C sources. Without DIAGRAM (or with --hand): "
                                        "the HandPlant alone, its parameters the hand file's values.")
    fmu.export_args(export, diagram_required=False)
    export.add_argument("--hand", type=Path, metavar="FILE",
                        help="the plant export's hand file (default: the shipped hand); not with DIAGRAM")
    export.set_defaults(handler=cmd_fmu_export)
    return export


def cmd_animate(args: argparse.Namespace) -> int:
    from blocks import Results
    from hierhand.animation import AnimationError, animate_run

    results = Results.load(args.run_dir)
    try:
        written = animate_run(results, args.output, fps=args.fps, speed=args.speed, plant=args.plant,
                              every=args.every, report=None if args.quiet else print, progress=not args.quiet)
    except AnimationError as exc:
        raise UsageError(str(exc)) from None
    if not args.quiet:
        print(f"wrote {written}")
    return EXIT_OK


def cmd_reproduce(args: argparse.Namespace) -> int:
    from hierhand.tasks.reproduce import DEFAULT_DIAGRAMS, MissingDiagram, ReproduceError, reproduce

    try:
        summary = reproduce(args.output, args.diagrams or DEFAULT_DIAGRAMS,
                            report=(lambda s: None) if args.quiet else print, progress=not args.quiet)
    except MissingDiagram as exc:
        raise UsageError(str(exc)) from None
    except ReproduceError as exc:
        print(f"hierhand: {exc}", file=sys.stderr)
        return EXIT_FAILED
    if args.quiet:
        return EXIT_OK
    r = summary["regrasp"]

    def seconds(value: float | None) -> str:
        return "never" if value is None else f"{value} s"

    print(f"grasp: peak ratio {summary['grasp']['peak_ratio']:.3f}, steady max "
          f"{summary['grasp']['steady_ratio_max']:.3f}; manipulation: position error "
          f"{1000 * summary['manipulation']['position_error_m']:.2f} mm; re-grasp: forefinger separates at "
          f"{seconds(r['suppressed']['fore_separation_time_s'])} with suppresser, "
          f"{seconds(r['unsuppressed']['fore_separation_time_s'])} without")
    print(f"wrote {args.output}/summary.json, report.md and fig09.png ... fig14.png")
    return EXIT_OK


def cmd_examples(args: argparse.Namespace) -> int:
    from blocks.diagram_file.yaml_source import YamlSourceError, load_yaml, read_yaml_file

    from hierhand.examples import copy_examples, example_files

    if args.folder is None:
        for path in example_files():
            if path.suffix == ".yaml":
                try:
                    description = " ".join(str(load_yaml(read_yaml_file(path)).get("description", "")).split())
                except (OSError, YamlSourceError, AttributeError):
                    description = ""
                print(f"{path.stem:22} {description.split('. ')[0]}")
        return EXIT_OK
    try:
        written = copy_examples(args.folder)
    except FileExistsError as exc:
        raise UsageError(f"examples: already there, not overwritten: {exc} (hint: choose a new folder)") from None
    except OSError as exc:
        raise UsageError(f"examples: cannot write into {args.folder}: {exc.strerror or exc}") from None
    print(f"copied {len(written)} files into {args.folder}")
    return EXIT_OK


def cmd_fmu_export(args: argparse.Namespace) -> int:
    from blocks import DiagramError
    from hierhand.fmu_export import FmuExportError, export_plant_fmu, kernel_set
    from hierhand.model import HandFileError

    if args.diagram is not None:
        if args.hand is not None:
            raise UsageError("fmu export: --hand is for the plant export, without DIAGRAM (a diagram gives its "
                             "plant's hand itself)")
        print(f"wrote {fmu.export_diagram(args, kernel_set=kernel_set())}")
        return EXIT_OK
    if args.overrides or args.step or args.scheduled:
        raise UsageError("fmu export: --set, --step and --scheduled-execution need a DIAGRAM (the plant export "
                         "takes --hand)")
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


def _shipped(name: str) -> Path | None:
    """A shipped diagram by name (imported when a DIAGRAM names no file)."""
    from hierhand.examples import shipped_diagram

    return shipped_diagram(name)


PROGRAM = Program(
    name="hierhand", description=DESCRIPTION, distribution="hierhand", version=__version__, env_prefix="HIERHAND",
    advice=advice,
    commands=(run.add, validate.add, graph.add, plot.add, add_animate, add_reproduce,
              fmu.group("export a diagram or the hand plant as an FMU, or describe an FMU", add_fmu_export,
                        fmu.info),
              ssp.add, sweep.command(MEASURES_HELP), sweep.plot, block_types.add, schema.add, add_examples),
    shipped=lambda name: _shipped(name))
"""The ``hierhand`` command: its commands in the order of its help."""


def main(argv: Sequence[str] | None = None) -> int:
    """Run one ``hierhand`` command line; returns its exit code."""
    return run_main(PROGRAM, argv)


def entry() -> None:
    """Console-script entry point."""
    run_program(PROGRAM)


if __name__ == "__main__":
    entry()
