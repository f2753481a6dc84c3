"""Where ``hierhand run`` puts its results: a read-only -o is refused before the run; when
saving fails after the run, the results go to a temporary folder that the message names."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from blocks import Results
from blocks.cli.run_output import save_run

from .test_cli import FAILS_AT_ONCE, LONG_DIAGRAM
from ..results.test_folder import read_only_folder

REPO = Path(__file__).resolve().parents[3]


def hierhand(tmp_path: Path, *args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    """The command line in ``tmp_path``, whose temporary files go to ``tmp_path/temp``."""
    (tmp_path / "temp").mkdir(exist_ok=True)
    env = dict(os.environ, PYTHONPATH=str(REPO), TMPDIR=str(tmp_path / "temp"))
    return subprocess.run([sys.executable, "-m", "hierhand", *args], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=timeout)


def test_a_read_only_output_folder_is_refused_before_the_run(tmp_path):
    folder = read_only_folder(tmp_path)
    (tmp_path / "d.yaml").write_text(FAILS_AT_ONCE, encoding="utf-8")
    proc = hierhand(tmp_path, "run", "d.yaml", "-o", str(folder))
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr == f"hierhand: error: output folder {folder} is not writable: Permission denied\n"


def test_results_that_cannot_be_saved_go_to_a_temporary_folder(tmp_path):
    short = LONG_DIAGRAM.replace("100000 s", "10 ms").replace("decimate: 10000", "decimate: 10")
    (tmp_path / "d.yaml").write_text(short, encoding="utf-8")
    (tmp_path / "out" / "signals.npz").mkdir(parents=True)  # passes the check, fails the save
    proc = hierhand(tmp_path, "run", "d.yaml", "-o", "out")
    assert proc.returncode == 1, proc.stderr
    found = re.fullmatch(r"hierhand: cannot save the results in out: Is a directory: out/signals\.npz; "
                         r"saved them in (\S+) instead\n", proc.stderr)
    assert found, proc.stderr
    spare = Path(found.group(1))
    assert spare.parent == tmp_path / "temp"
    r = Results.load(spare)
    assert r.complete and r["ramp.y"][0][-1] == pytest.approx(0.01)


def test_results_that_cannot_be_saved_anywhere_are_reported_lost(tmp_path, monkeypatch):
    import tempfile

    (tmp_path / "signals.npz").mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "no-such-temp"))
    r = Results({"a.y": (np.zeros(1), np.zeros((1, 1)))}, {"status": "complete"})
    saved = save_run(r, tmp_path, csv=False)
    assert saved.folder is None
    assert saved.problem.startswith(f"cannot save the results in {tmp_path} (Is a directory: ")
    assert saved.problem.endswith("): they are lost")
