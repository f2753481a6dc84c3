"""``fmu``: the group of FMU commands: ``fmu export`` (a diagram as an FMU) and ``fmu info``.

The group takes its subcommands as arguments, so that an application can add its own
(an exporter of its models) beside ``info``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from .options import parse_overrides, trust_arg
from .program import EXIT_OK, Command, UsageError


def group(help: str, *subcommands: Command) -> Command:
    """The ``fmu`` command with ``subcommands`` (``info`` and any of the application's)."""
    def add(sub, program) -> argparse.ArgumentParser:
        fmu = sub.add_parser("fmu", help=help, description=help[:1].upper() + help[1:] + ".")
        fmu_sub = fmu.add_subparsers(dest="fmu_command", required=True, metavar="FMU_COMMAND")
        for command in subcommands:
            command(fmu_sub, program)
        return fmu
    return add


def info(sub, program) -> argparse.ArgumentParser:
    """The ``fmu info`` command."""
    parser = sub.add_parser("info", help="variables, causality, default experiment, interface types",
                            description="Describe an FMU (FMI 2.0 or 3.0) from its modelDescription.xml: "
                                        "its interfaces, default experiment, and variables with causality, "
                                        "type, unit and start value. Its binary is neither loaded nor run.")
    parser.add_argument("path", type=Path, metavar="PATH", help="FMU file")
    parser.set_defaults(handler=cmd_fmu_info)
    return parser


def cmd_fmu_info(args: argparse.Namespace) -> int:
    """Print the FMU's description (its code is not loaded)."""
    from blocks.fmu import FMUInfoError, describe_fmu

    try:
        print(describe_fmu(args.path))
    except FMUInfoError as exc:
        raise UsageError(str(exc)) from None
    return EXIT_OK


def export_args(parser: argparse.ArgumentParser, diagram_required: bool = True) -> None:
    """DIAGRAM, --set, --trust, --fmi, --scheduled-execution, --step and -o of ``fmu export``."""
    parser.add_argument("diagram", type=Path, metavar="DIAGRAM", nargs=None if diagram_required else "?",
                        help="YAML diagram file whose blocks all have compiled kernels")
    parser.add_argument("--set", action="append", default=[], dest="overrides", metavar="BLOCK.PARAM=VALUE",
                        help="override a parameter before exporting (value read as YAML; repeatable)")
    trust_arg(parser)
    parser.add_argument("--fmi", type=int, choices=(2, 3), default=2, help="FMI version (default: 2)")
    parser.add_argument("--scheduled-execution", action="store_true", dest="scheduled",
                        help="FMI 3 scheduled execution: one input clock and model partition per rate, "
                             "activated by the importer's scheduler (docs: Scheduled execution)")
    parser.add_argument("--step", metavar="T",
                        help="the default communication step, a multiple of the internal step (default: it)")
    parser.add_argument("-o", "--output", type=Path, metavar="PATH",
                        help="FMU file or folder to write (default: fmu/<name>_fmi<N>.fmu)")


def export(sub, program) -> argparse.ArgumentParser:
    """The ``fmu export`` command (any diagram of compiled blocks)."""
    parser = sub.add_parser("export", help="export a diagram as an FMI co-simulation FMU",
                            description="Export DIAGRAM as an FMI 2.0 or 3.0 co-simulation FMU whose binary is "
                                        "the op-table core and the blocks' compiled kernels: it runs without "
                                        "Python at the importer. Its inputs and outputs are the diagram's own "
                                        "(a diagram without outputs exports its logged signals), its parameters "
                                        "the blocks' tunable ones.")
    export_args(parser)
    parser.set_defaults(handler=cmd_fmu_export)
    return parser


def cmd_fmu_export(args: argparse.Namespace) -> int:
    """Write the FMU of the diagram the arguments name."""
    print(f"wrote {export_diagram(args)}")
    return EXIT_OK


def export_diagram(args: argparse.Namespace, **options) -> Path:
    """The FMU of ``args``' diagram, written: its path. ``options`` go to ``export_fmu``."""
    from blocks import load_diagram
    from blocks.fmu_export import FmuExportError, export_fmu
    from blocks.safepath import folder_name

    if args.scheduled and args.fmi != 3:
        raise UsageError("fmu export: --scheduled-execution needs --fmi 3 (FMI 2 has no clocks)")
    if args.scheduled and args.step:
        raise UsageError("fmu export: --step is for co-simulation; the clocks of scheduled execution are the rates")
    diagram = load_diagram(args.diagram, overrides=parse_overrides(args.overrides), trust=args.trust)
    name = f"{folder_name(diagram.name)}_fmi{args.fmi}{'_se' if args.scheduled else ''}.fmu"  # one file name, whatever the diagram is called
    out = args.output if args.output is not None else Path("fmu") / name
    if out.suffix.lower() != ".fmu":
        out = out / name
    try:
        return export_fmu(diagram, out, args.fmi, step=args.step, scheduled=args.scheduled, **options)
    except (FmuExportError, OSError) as exc:
        raise UsageError(f"fmu export: {exc}") from None
