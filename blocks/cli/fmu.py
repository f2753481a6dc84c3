"""``fmu``: the group of FMU commands, and ``fmu info``, which describes any FMU.

The group takes its subcommands as arguments, so that an application can add its own
(an exporter of its models) beside ``info``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

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
