"""A command-line program made of commands: its parser, its error handling, its exit codes.

The framework's commands (``blocks.cli.GENERIC_COMMANDS``) work on any diagram; an
application makes its own program from them and its own commands, in the order its help
lists them, and calls ``main`` or ``entry`` with it (an application's ``cli`` module does)::

    PROGRAM = Program("mytool", "what it does", (run.add, validate.add, my_command))

A command is a function ``command(sub, program)`` that adds its subparser to the
program's subparsers and sets ``handler(args) -> exit code`` as its default;
``args.program`` is the running ``Program``, whose ``name`` begins every message.

Exit codes: 0 ok, 2 bad input (a one-line message per problem, no traceback), 1 a failure
during a simulation (the message names block, time and signal; partial results are kept)
or results that could not be saved where asked, 130 Ctrl-C and 143 SIGTERM (a run saves
what it computed, marked interrupted).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from blocks.process.terminal import EscapedStream, unescaped

TYPE_CHECKING = False  # typing's own constant, without importing typing: --version and --help start light
if TYPE_CHECKING:
    from blocks.issues import Issue

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT = 0, 1, 2
EXIT_INTERRUPTED = 130

Command = Callable[["argparse._SubParsersAction", "Program"], argparse.ArgumentParser]
"""Adds one subcommand (or a group of them) to the subparsers, with its ``handler``."""


class UsageError(Exception):
    """Bad command-line input, reported as one line with exit code 2."""


class Program:
    """A command-line program: its name (the prefix of its messages), its help's
    description, its commands in help order, the distribution whose version
    ``--version`` prints (None: the one that ships the ``blocks`` package), and the prefix
    of its environment variables (``PREFIX_DEBUG=1`` shows the traceback of an internal
    error). ``advice``: the application's hint for a problem it knows how to fix (an FMU
    that its own exporter makes), in place of the problem's own; None: no better hint.
    ``version``: what ``--version`` prints after the name (None: the distribution's
    installed version, read from its metadata, which costs more than the rest of a
    start). ``shipped``: the application's own diagram of a name (``regrasp``), for a
    DIAGRAM argument that names no file, so its documented commands work in any folder
    after any install. A plain class (not a dataclass, whose import pulls in ``inspect``):
    a program starts before anything else."""

    __slots__ = ("name", "description", "commands", "distribution", "env_prefix", "advice", "version", "shipped")

    def __init__(self, name: str, description: str, commands: tuple[Command, ...], distribution: str | None = None,
                 env_prefix: str = "BLOCKS", advice: Callable[[Issue], str | None] | None = None,
                 version: str | None = None, shipped: Callable[[str], Path | None] | None = None):
        self.name, self.description, self.commands = name, description, tuple(commands)
        self.distribution, self.env_prefix, self.advice = distribution, env_prefix, advice
        self.version, self.shipped = version, shipped

    def __repr__(self) -> str:
        return f"Program({self.name!r})"

    def env(self, suffix: str) -> str:
        """The name of one of the program's environment variables, e.g. ``HIERHAND_DEBUG``."""
        return f"{self.env_prefix}_{suffix}"

    def advised(self, issue: Issue) -> Issue:
        """``issue`` with the application's hint, where it has one."""
        hint = self.advice(issue) if self.advice is not None else None
        if not hint:
            return issue
        import dataclasses

        return dataclasses.replace(issue, hint=hint)


def build_parser(program: Program) -> argparse.ArgumentParser:
    """The program's argument parser: ``--version`` and one subcommand per command."""
    parser = argparse.ArgumentParser(prog=program.name, description=program.description)
    parser.add_argument("--version", action=_Version, nargs=0, help="show program's version number and exit")
    parser.set_defaults(program=program)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for command in program.commands:
        command(sub, program)
    return parser


class _Version(argparse.Action):
    """``--version``: 'PROGRAM VERSION', looked up only when asked (reading the installed
    packages' metadata is not free, and every command would pay for it)."""

    def __call__(self, parser, namespace, values, option_string=None):
        program = parser.get_default("program")
        sys.stdout.write(f"{parser.prog} {program.version or version(program.distribution)}\n")
        parser.exit()


def version(distribution: str | None) -> str:
    """The installed version of ``distribution`` (None: the one that ships ``blocks``), or
    '(not installed)'."""
    from importlib import metadata

    if distribution is None:
        distribution = next(iter(metadata.packages_distributions().get("blocks", [])), "")
    try:
        return metadata.version(distribution) if distribution else "(not installed)"
    except metadata.PackageNotFoundError:
        return "(not installed)"


def main(program: Program, argv: Sequence[str] | None = None) -> int:
    """Parse ``argv`` (default: the process's), run the command, and turn the errors users
    cause into one line each and an exit code."""
    args = build_parser(program).parse_args(argv)
    from blocks import DiagramError, ResultsError

    if hasattr(args, "diagram"):
        args.diagram = shipped_or_given(args.diagram, program)

    try:
        return args.handler(args)
    except DiagramError as exc:
        for issue in exc.issues:
            print(str(program.advised(issue)), file=sys.stderr)
        return EXIT_BAD_INPUT
    except (UsageError, ResultsError) as exc:
        print(f"{program.name}: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as exc:
        from blocks.process.stop import exit_code

        print(f"{program.name}: interrupted", file=sys.stderr)
        return exit_code(exc)


def shipped_or_given(diagram: Path | None, program: Program) -> Path | None:
    """A command's DIAGRAM: the path as given, unless no such file exists and the program
    ships a diagram of that name."""
    if diagram is None or program.shipped is None or diagram.exists():
        return diagram
    return program.shipped(str(diagram)) or diagram


def entry(program: Program) -> None:
    """Console-script entry point: ``main``, and an exit with its code.

    A closed pipe ('PROGRAM blocks | head') ends quietly; any other exception, an internal
    error, gets one line naming the environment variable that shows its traceback.
    """
    debug = program.env("DEBUG")
    for stream in (sys.stdout, sys.stderr):  # a name in any script, on a terminal that shows only ASCII
        with contextlib.suppress(AttributeError, ValueError):
            stream.reconfigure(errors="backslashreplace")
    sys.stdout, sys.stderr = EscapedStream(unescaped(sys.stdout)), EscapedStream(unescaped(sys.stderr))
    if os.environ.get(debug):
        sys.exit(main(program))
    try:
        sys.exit(main(program))
    except BrokenPipeError:  # the reader has gone, nothing to report
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        sys.exit(EXIT_OK)
    except Exception as exc:
        print(f"{program.name}: internal error: {type(exc).__name__}: {exc} "
              f"(set {debug}=1 for the traceback, and please report it)", file=sys.stderr)
        sys.exit(EXIT_FAILED)
