"""Ctrl-C and SIGTERM in every phase of ``hierhand run``: one line, the documented exit code,
no traceback, and whatever results there are saved.

Each test has the process signal itself at a chosen point (``signal_hook``: its start-up
imports, loading the diagram, the first progress report of the run, saving, drawing the
plots), so none depends on timing.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from blocks import Results

pytestmark = pytest.mark.skipif(os.name != "posix", reason="POSIX signals")

REPO = Path(__file__).resolve().parents[3]
HOOK = Path(__file__).resolve().parent / "signal_hook"
SHORT = """\
name: short
time: {t_end: 20 ms}
blocks:
  ramp: {type: Ramp, period: 1 ms, params: {slope: 1.0}}
log: [ramp.y]
"""


def run(tmp_path: Path, at: str, send: str, *options: str, diagram: str = SHORT,
        call: int = 1) -> subprocess.CompletedProcess:
    (tmp_path / "d.yaml").write_text(diagram, encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=f"{HOOK}{os.pathsep}{REPO}", SIGNAL_AT=at, SIGNAL_SEND=send,
               SIGNAL_CALL=str(call))
    proc = subprocess.run([sys.executable, "-m", "hierhand", "run", "d.yaml", "-o", "out", *options],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert "Traceback" not in proc.stderr, proc.stderr
    return proc


@pytest.mark.parametrize("send, code", [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_signal_during_the_start_up_imports_is_one_line(tmp_path, send, code):
    proc = run(tmp_path, "import:numpy", send)
    assert proc.returncode == code and proc.stderr == "hierhand: interrupted\n", proc.stderr
    assert not (tmp_path / "out").exists()


def test_sigterm_while_the_diagram_loads_is_one_line_and_143(tmp_path):
    proc = run(tmp_path, "blocks.loader:read_builder", "SIGTERM")
    assert proc.returncode == 143 and proc.stderr == "hierhand: interrupted\n", proc.stderr


def test_sigterm_then_sigint_while_simulating_exits_as_the_first_asks(tmp_path):
    proc = run(tmp_path, "blocks.cli.run:ProgressBar.__call__", "SIGTERM,SIGINT",
               diagram=SHORT.replace("20 ms", "1000 s"), call=2)
    assert proc.returncode == 143, proc.stderr
    r = Results.load(tmp_path / "out")
    assert r.interrupted and r.status.endswith("by SIGTERM") and len(r["ramp.y"][0]) > 0


def test_sigterm_while_a_complete_run_is_saved_does_not_exit_0(tmp_path):
    proc = run(tmp_path, "blocks.results:Results.write_files", "SIGTERM")
    assert proc.returncode == 143, proc.stderr
    assert "SIGTERM while the results are saved" in proc.stderr
    assert "SIGTERM after the run: its results are complete in out" in proc.stderr
    assert Results.load(tmp_path / "out").complete


def test_sigint_while_plotting_stops_the_plots_and_keeps_the_results(tmp_path):
    proc = run(tmp_path, "blocks.plot:figure", "SIGINT", "--plot")
    assert proc.returncode == 130, proc.stderr
    assert "plots stopped by SIGINT" in proc.stderr
    assert Results.load(tmp_path / "out").complete
    assert not (tmp_path / "out" / "plots").exists()
    assert [p.name for p in (tmp_path / "out").iterdir() if p.name.startswith(".")] == []
