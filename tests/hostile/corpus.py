"""The hostile-input regression corpus: one ``Case`` per broken or hostile input.

A case is the files a user (or an attacker) hands the tool, the command line, and what
must come back: the exit code, a fragment of the message on stderr, and no traceback.
Cases live in the ``cases_*.py`` modules beside this one (a list ``CASES`` each), grouped
by what they attack; ``test_corpus.py`` runs every one of them through the real command
line in a fresh temporary folder.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

ROOT = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class Case:
    """A hostile or broken input and the answer the tool owes it.

    ``files`` maps paths relative to the case's folder to their text (``str``) or bytes;
    ``argv`` is the command line after ``hierhand``, where ``{dir}`` stands for the case's
    folder and ``{root}`` for the repository; ``message`` is a regular expression searched
    in stderr; ``absent`` lists paths (relative to the folder, may climb out with ``..``)
    that must not exist afterwards; ``check`` runs further assertions on the folder;
    ``env`` sets variables of the command's environment (a locale, an encoding).
    ``timeout`` only keeps a hung command from holding the suite: far beyond any case's
    time on a busy machine, it asserts nothing about speed.
    """

    name: str
    argv: tuple[str, ...]
    exit: int
    message: str
    files: dict[str, str | bytes] = field(default_factory=dict)
    absent: tuple[str, ...] = ()
    timeout: float = 300.0
    check: Callable[[Path, subprocess.CompletedProcess], None] | None = None
    env: dict[str, str] = field(default_factory=dict)


def run(case: Case, folder: Path, cli=None) -> subprocess.CompletedProcess:
    """Write the case's files under ``folder`` and run its command line there: through
    ``cli`` (a ``tests.forked_cli.ForkedCLI``) if given, else in a fresh interpreter."""
    for rel, content in case.files.items():
        path = folder / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content, encoding="utf-8")
    argv = [a.format(dir=folder, root=ROOT) for a in case.argv]
    if cli is not None and not case.env:  # a case's own environment (a locale) needs an interpreter of its own
        return cli.run(argv, folder, timeout=case.timeout)
    env = {**os.environ, "PYTHONPATH": str(ROOT), **case.env}
    return subprocess.run([sys.executable, "-m", "hierhand", *argv], capture_output=True, text=True,
                          cwd=folder, env=env, timeout=case.timeout)


def verify(case: Case, folder: Path, proc: subprocess.CompletedProcess) -> None:
    """Assert the exit code, the message, no traceback and the absent paths."""
    shown = f"--- stdout ---\n{proc.stdout[-2000:]}\n--- stderr ---\n{proc.stderr[-2000:]}"
    assert proc.returncode == case.exit, f"{case.name}: exit {proc.returncode}, expected {case.exit}\n{shown}"
    assert "Traceback" not in proc.stderr, f"{case.name}: traceback\n{shown}"
    assert re.search(case.message, proc.stderr), f"{case.name}: no {case.message!r} on stderr\n{shown}"
    for rel in case.absent:
        assert not (folder / rel).exists(), f"{case.name}: {rel} exists"
    if case.check is not None:
        case.check(folder, proc)
