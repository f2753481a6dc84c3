"""The framework's command line: generic commands for any diagram, and the program that runs them.

One module per command (or group): ``run``, ``validate``, ``graph``, ``plot``, ``fmu``
(the group, with ``export`` and ``info``), ``sweep`` (``sweep`` and ``sweep-plot``) and
``block_types`` (``blocks``), ``schema`` (the diagram file's JSON Schema); ``options`` holds the diagram options they share,
``program`` the parser, the error handling and the exit codes, ``run_output`` what
``run`` needs to save its results whatever happens (and ``blocks.process.stop`` the signals).

``python -m blocks`` runs ``PROGRAM``, the generic commands alone; an application builds
its own ``Program`` from ``GENERIC_COMMANDS``' members and its commands (``hierhand`` does).
"""

from __future__ import annotations

from . import block_types, fmu, graph, plot, run, schema, ssp, sweep, validate
from .program import (EXIT_BAD_INPUT, EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, Command, Program, UsageError,
                      build_parser, entry, main)

GENERIC_COMMANDS: tuple[Command, ...] = (run.add, validate.add, graph.add, plot.add,
                                         fmu.group("export a diagram as an FMU, or describe an FMU", fmu.export,
                                                   fmu.info), ssp.add, sweep.command(), sweep.plot,
                                         block_types.add, schema.add)
"""Every generic command, in the order of the help."""

PROGRAM = Program("blocks", "Multirate block-diagram co-simulation: run YAML diagrams, inspect and plot them.",
                  GENERIC_COMMANDS)
"""The framework's own program (``python -m blocks``)."""

__all__ = ["EXIT_BAD_INPUT", "EXIT_FAILED", "EXIT_INTERRUPTED", "EXIT_OK", "GENERIC_COMMANDS", "PROGRAM", "Command",
           "Program", "UsageError", "build_parser", "entry", "main"]
