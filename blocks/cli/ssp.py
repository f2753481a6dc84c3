"""``ssp export``: a diagram written as an SSP (``blocks.ssp.export_ssp``) for OMSimulator,
libcosim, Dymola and other SSP tools; ``run``, ``validate``, ``graph`` read SSPs as diagrams."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..ssp.steps import ANNOTATIONS
from .options import load, parse_overrides, trust_arg
from .program import EXIT_OK


def add(sub, program) -> argparse.ArgumentParser:
    ssp = sub.add_parser("ssp", help="exchange systems of FMUs as SSP (System Structure and Parameterization)",
                         description="Exchange systems of FMUs with other tools as SSP archives (System "
                                     "Structure and Parameterization).")
    ssp_sub = ssp.add_subparsers(dest="ssp_command", required=True, metavar="SSP_COMMAND")
    export = ssp_sub.add_parser("export", help="write a diagram of FMU blocks as an SSP archive",
                                description="Write DIAGRAM, a diagram of FMU blocks (or an SSP read back), "
                                            "as an SSP archive.")
    export.add_argument("diagram", type=Path, metavar="DIAGRAM", help="YAML diagram file (or an SSP)")
    export.add_argument("-o", "--output", type=Path, required=True, metavar="SYSTEM.ssp", help="the SSP to write")
    export.add_argument("--set", action="append", default=[], dest="overrides", metavar="BLOCK.PARAM=VALUE",
                        help="override a parameter before exporting (repeatable)")
    export.add_argument("--step", metavar="T", help="SSP input only: the step of components that give none")
    export.add_argument("--annotations", choices=sorted(ANNOTATIONS), default="system",
                        help="where the tool-specific annotations go: "
                             + "; ".join(f"{k}: {v}" for k, v in ANNOTATIONS.items()) + " (default: system)")
    trust_arg(export)
    export.set_defaults(handler=cmd_ssp_export)
    return ssp


def cmd_ssp_export(args: argparse.Namespace) -> int:
    """Load the diagram (its checks are the builder's) and write it as an SSP."""
    from blocks.ssp import export_ssp

    parse_overrides(args.overrides)
    written = export_ssp(load(args), args.output, annotations=args.annotations)
    print(f"wrote {written}")
    return EXIT_OK
