"""Every command and every Python example of README.md and of the documentation (docs/**/*.md)
runs as written.

Their fenced ```bash / ```sh / ```console blocks are run with bash (``set -e``), their
```python blocks as scripts, each in a fresh process, in a temporary copy of what the pages
refer to (diagrams/, docs/, fmu/, benchmarks/) so that their outputs (runs/..., fmu/...)
never land in the repository. A block that appears on several pages (the README's quick
start is also the getting-started page's) runs once, under its first place: README.md, then
the pages in name order. Blocks that are not commands (```text, ```yaml, ```toml) are only
counted. The few commands that cannot run here are listed in SKIPPED below, each with the
reason, and the test checks that their text is still on a page, so a changed command is
seen.

``hierhand``, ``python`` and ``fmpy`` are found through shims on PATH that run this
interpreter (``sys.executable -m ...``) with the worktree on PYTHONPATH: the ``hierhand`` on
the machine's PATH may belong to another checkout.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
import stat
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
SHELL = {"bash", "sh", "console", "shell"}
NOT_COMMANDS = {"text", "yaml", "toml", ""}
LISTINGS = {"c", "py"}
"""Blocks that show a file of the project (a tutorial's real code): not run, but each must be
found in a file of the packages, so that the page cannot drift from the code."""
COPIED = ("diagrams", "docs", "fmu", "benchmarks")

# The quick start's installs are dropped and the rest of the line runs: there is no network
# here, and the package under test is already importable (the worktree on PYTHONPATH). The
# text before '&&' must be exactly this, so that a changed install line is noticed.
INSTALL_PREFIX = "pip install -e . && "
# The quick start's virtual environment is not made: the suite runs in one already, and
# the shims below put this worktree's commands first on PATH, which activating another
# environment would undo. A changed line is an install line the test refuses below.
SETUP_LINES = {"python3 -m venv .venv && . .venv/bin/activate"}

SKIPPED = {
    # Installs the test extras (no network) and then runs this very test suite, which would
    # run this test again, recursively; the suite is what is running now.
    'pip install -e ".[test]" && python -m pytest':
        "install + the whole test suite (the suite running now)",
    # Runs the four tasks at 300 random points and each ablation at 100 (minutes of both
    # cores) and writes runs/robustness/ (docs/robustness.png is a copy of its plot): a
    # benchmark whose numbers the paper-tasks page quotes, run by hand, too long for the suite.
    "python benchmarks/robustness.py --ablations": "long-running benchmark (minutes on 2 cores)",
}

# The command line page's example (``entry(Program(...))``) is a program: run as written with no
# arguments it prints its usage and exits 2, as any argparse program does. It is run with
# the command it defines, and must answer it.
PROGRAM_ARGS = {"entry(Program(": (["hello"], "mytool says hello")}


def fenced_blocks(text: str) -> list[tuple[str, str, int]]:
    """(language, body, line of the opening fence) of every fenced block."""
    blocks, lines, i = [], text.splitlines(), 0
    while i < len(lines):
        m = re.match(r"^(```+)\s*([\w+-]*)\s*$", lines[i])
        if m:
            fence, lang, start = m.group(1), m.group(2).lower(), i + 1
            j = i + 1
            while j < len(lines) and not lines[j].startswith(fence):
                j += 1
            blocks.append((lang, "\n".join(lines[i + 1:j]) + "\n", start))
            i = j + 1
        else:
            i += 1
    return blocks


def page_blocks() -> list[tuple[str, str, str]]:
    """(language, body, 'page:line') of every fenced block of every page, in page order."""
    found = []
    for page in PAGES:
        name = page.relative_to(ROOT).as_posix()
        found += [(lang, body, f"{name}:{line}") for lang, body, line in fenced_blocks(page.read_text(encoding="utf-8"))]
    return found


def first_places(blocks: list[tuple[str, str, str]], langs: set[str]) -> list[tuple[str, str]]:
    """(body, place) of each distinct block of ``langs``, at its first place."""
    seen: dict[str, str] = {}
    for lang, body, place in blocks:
        if lang in langs:
            seen.setdefault(body, place)
    return list(seen.items())


BLOCKS = page_blocks()
SHELL_BLOCKS = first_places(BLOCKS, SHELL)
PYTHON_BLOCKS = first_places(BLOCKS, {"python"})
TEXT = "\n".join(page.read_text(encoding="utf-8") for page in PAGES)


def test_every_block_is_a_known_kind():
    unknown = [(lang, place) for lang, _, place in BLOCKS if lang not in SHELL | NOT_COMMANDS | LISTINGS | {"python"}]
    assert not unknown, f"blocks of a language this test does not handle: {unknown}"
    assert len(SHELL_BLOCKS) >= 5 and len(PYTHON_BLOCKS) >= 5


@pytest.fixture(scope="module")
def workdir(tmp_path_factory) -> tuple[Path, dict[str, str]]:
    """A folder with the pages' relative paths, and an environment whose PATH runs this
    worktree's hierhand, python and fmpy."""
    work = tmp_path_factory.mktemp("pages")
    for name in COPIED:
        shutil.copytree(ROOT / name, work / name, ignore=shutil.ignore_patterns("__pycache__"))
    shims = tmp_path_factory.mktemp("shims")
    for name, module in (("hierhand", "-m hierhand"), ("python", ""), ("python3", ""), ("fmpy", "-m fmpy")):
        shim = shims / name
        shim.write_text(f'#!/bin/sh\nexec "{sys.executable}" {module} "$@"\n', encoding="utf-8")
        shim.chmod(shim.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join((str(shims), env.get("PATH", "")))
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH", "")) if p)
    env["MPLBACKEND"] = "Agg"
    return work, env


def shell_command(body: str) -> str | None:
    """The text to run for a shell block, or None if it is one of SKIPPED."""
    if body.strip() in SKIPPED:
        return None
    lines = [line for line in body.splitlines() if line.strip() not in SETUP_LINES]
    assert not any(line.lstrip().startswith(("pip ", "python3 -m venv")) for line in lines
                   if not line.startswith(INSTALL_PREFIX)), body
    return "\n".join(line[len(INSTALL_PREFIX):] if line.startswith(INSTALL_PREFIX) else line
                     for line in lines) + "\n"


def test_skipped_commands_are_still_on_a_page():
    bodies = {body.strip() for body, _ in SHELL_BLOCKS}
    for command in SKIPPED:
        assert command in bodies, f"SKIPPED names a command no page has any longer: {command}"
    assert any(body.startswith(INSTALL_PREFIX) or INSTALL_PREFIX in body for body in bodies)


@pytest.mark.parametrize("body,place", SHELL_BLOCKS, ids=[place for _, place in SHELL_BLOCKS])
def test_shell_block_runs(body: str, place: str, workdir):
    command = shell_command(body)
    if command is None:
        pytest.skip(f"{place}: {SKIPPED[body.strip()]}")
    work, env = workdir
    proc = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", command], cwd=work, env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"{place}: exit {proc.returncode}\n{command}\n{proc.stdout}\n{proc.stderr}"
    assert "Traceback" not in proc.stderr, proc.stderr


@pytest.mark.parametrize("body,place", PYTHON_BLOCKS, ids=[place for _, place in PYTHON_BLOCKS])
def test_python_block_runs(body: str, place: str, workdir, tmp_path):
    if "libcosimpy" in body and importlib.util.find_spec("libcosimpy") is None:
        pytest.skip(f"{place}: needs libcosimpy (the test extra), which is not installed here")
    work, env = workdir
    script = tmp_path / f"{re.sub(r'[^A-Za-z0-9]+', '_', place)}.py"
    script.write_text(body, encoding="utf-8")
    args, expected = next((v for k, v in PROGRAM_ARGS.items() if k in body), ([], None))
    proc = subprocess.run([sys.executable, str(script), *args], cwd=work, env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"{place}: exit {proc.returncode}\n{body}\n{proc.stdout}\n{proc.stderr}"
    if expected is not None:
        assert expected in proc.stdout


SET_EXAMPLE = re.compile(r"`--set ([\w.]+)=([^`]+)`")
# --set examples in the prose, each run on a diagram that has the block it names; the
# Observer example's 'obs.plant=other' and the subsystem examples' 'ctrl....' belong to
# diagrams the pages only sketch (tests/blocks/test_subsystems.py runs them), as do the SSP
# examples' (tests/blocks/ssp).
SET_DIAGRAM = {"plant.A": "diagrams/toy.yaml", "obs.plant": None, "ctrl.prop.k": None, "ctrl.integ.A": None,
               "COMPONENT.PARAM": None, "sub.comp.k": None, "BLOCK.PARAM": None}
SET_EXAMPLES = sorted(set(SET_EXAMPLE.findall(TEXT)))


@pytest.mark.parametrize("path,value", SET_EXAMPLES, ids=[f"{p}={v}" for p, v in SET_EXAMPLES])
def test_inline_set_example_is_accepted(path: str, value: str, workdir, tmp_path):
    diagram = SET_DIAGRAM.get(path, "diagrams/regrasp.yaml")
    if diagram is None:
        pytest.skip("a block of a diagram the pages only sketch")
    work, env = workdir
    value = value[1:-1] if value[:1] == value[-1:] == "'" else value  # the shell's quotes
    proc = subprocess.run([sys.executable, "-m", "hierhand", "run", diagram, "-o", str(tmp_path / "out"),
                           "--t-end", "10 ms", "-q", "--set", f"{path}={value}"],
                          cwd=work, env=env, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr


SOURCES = [p for package in ("blocks", "hierhand") for p in sorted((ROOT / package).rglob("*"))
           if p.suffix in (".py", ".c", ".h") and p.is_file()]


def listing_lines(text: str) -> list[str]:
    """A text's non-blank lines, spaces collapsed and a C line continuation dropped."""
    return [" ".join(line.rstrip().rstrip("\\").split()) for line in text.splitlines() if line.strip()]


@pytest.mark.parametrize("body, place", first_places(BLOCKS, LISTINGS), ids=lambda v: v if ":" in str(v) else "")
def test_a_listing_shows_a_file_of_the_project_as_it_is(body, place):
    """A listing's lines are lines of one source file, in the file's order (an excerpt may
    leave lines out between them), as written there."""
    shown = listing_lines(body)
    for path in SOURCES:
        lines = iter(listing_lines(path.read_text(encoding="utf-8")))
        if all(any(line == want for line in lines) for want in shown):
            return
    pytest.fail(f"{place}: this listing is not (or no longer) the text of any file of blocks/ or hierhand/")
