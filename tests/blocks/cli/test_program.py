"""A program made of commands: an application adds its own beside the generic ones, and every
message and exit code follows the program's name; ``python -m blocks`` is the generic one."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from blocks.cli import EXIT_OK, GENERIC_COMMANDS, Program, UsageError, block_types, build_parser, main, run

REPO = Path(__file__).resolve().parents[3]
TOY = REPO / "diagrams" / "toy.yaml"


def hello(sub, program):
    """An application's command: prints a greeting, or refuses a name it does not like."""
    parser = sub.add_parser("hello", help="greet")
    parser.add_argument("name")
    parser.set_defaults(handler=lambda args: greet(args.name, args.program.name))
    return parser


def greet(name: str, program: str) -> int:
    if name == "nobody":
        raise UsageError("nobody is there")
    print(f"{program} says hello to {name}")
    return EXIT_OK


def command_names(program: Program) -> list[str]:
    """The commands as the program's help lists them, in order."""
    lines = build_parser(program).format_help().split("positional arguments:")[1].split("options:")[0]
    return [line.split()[0] for line in lines.splitlines()[2:] if line.startswith("    ") and line[4] != " "]


TOOL = Program("tool", "a test program", (run.add, hello, block_types.add), env_prefix="TOOL")


def test_an_application_command_sits_beside_the_generic_ones(capsys):
    assert main(TOOL, ["hello", "you"]) == 0
    assert capsys.readouterr().out == "tool says hello to you\n"
    assert main(TOOL, ["hello", "nobody"]) == 2
    assert capsys.readouterr().err == "tool: error: nobody is there\n"
    assert command_names(TOOL) == ["run", "hello", "blocks"]


def test_generic_messages_begin_with_the_programs_name(tmp_path, capsys):
    assert main(TOOL, ["run", str(TOY), "-o", str(tmp_path / "out"), "--set", "bad"]) == 2
    assert capsys.readouterr().err == "tool: error: --set 'bad': expected BLOCK.PARAM=VALUE, e.g. --set prop.k=2\n"


def test_the_generic_program_lists_every_generic_command():
    assert command_names(Program("p", "", GENERIC_COMMANDS)) == ["run", "validate", "graph", "plot", "fmu", "ssp", "sweep",
                                                                 "sweep-plot", "blocks", "schema"]


@pytest.mark.parametrize("args, code, stream, text", [
    (["validate", str(TOY)], 0, "stdout", "diagram 'toy-multirate'"),
    (["run", str(TOY), "--t-end", "0"], 2, "stderr", "blocks: error: --t-end must be positive"),
])
def test_python_m_blocks_runs_the_generic_program(tmp_path, args, code, stream, text):
    proc = subprocess.run([sys.executable, "-m", "blocks", *args], capture_output=True, text=True, cwd=tmp_path,
                          env=dict(os.environ, PYTHONPATH=str(REPO)), timeout=120)
    assert proc.returncode == code, proc.stderr
    assert getattr(proc, stream).startswith(text)
