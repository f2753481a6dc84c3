"""What the hierhand command imports to start: nothing a command does not use.

Each command line runs in a fresh interpreter, as the console script runs it
(``hierhand.start.main``), which then lists the modules it imported. No timing: the
modules themselves are the measure (networkx alone took a tenth of a second on every
command).
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

import hierhand

PROBE = """
import json, sys
sys.argv = ["hierhand", *json.loads(sys.argv[1])]
from hierhand.start import main
try:
    main()
except SystemExit:
    pass
sys.__stdout__.write("\\nMODULES " + json.dumps(sorted(sys.modules)) + "\\n")
"""

HEAVY = ("numpy", "yaml", "networkx", "matplotlib", "pint", "scipy", "control", "fmpy", "lxml", "dask", "tqdm")


def modules_after(args: list[str], cwd) -> tuple[set[str], str]:
    """The top-level packages imported by ``hierhand ARGS``, and what it printed."""
    done = subprocess.run([sys.executable, "-c", PROBE, json.dumps(args)], cwd=cwd, capture_output=True, text=True,
                          timeout=300)
    out, _, listed = done.stdout.rpartition("\nMODULES ")
    assert listed, done.stderr
    return {name.split(".")[0] for name in json.loads(listed)}, out


@pytest.mark.parametrize("args", [["--version"], ["--help"]])
def test_version_and_help_import_none_of_the_heavy_packages(args, tmp_path):
    imported, out = modules_after(args, tmp_path)
    assert not imported & set(HEAVY), sorted(imported & set(HEAVY))
    assert out.startswith(f"hierhand {hierhand.__version__}" if args == ["--version"] else "usage: hierhand")


def test_a_run_of_library_blocks_imports_neither_plugins_nor_graphs(tmp_path):
    """The toy (library blocks only) runs without networkx (ordering by ports is rare),
    without the installed plug-ins' block types (the FMU block, the hand's) and without
    the progress bar's tqdm when -q asks for none."""
    imported, _ = modules_after(["run", "toy", "-o", str(tmp_path / "out"), "-q"], tmp_path)
    assert (tmp_path / "out" / "signals.npz").is_file()
    assert {"numpy", "yaml"} <= imported
    assert not imported & {"networkx", "matplotlib", "tqdm", "fmpy", "lxml", "scipy"}
