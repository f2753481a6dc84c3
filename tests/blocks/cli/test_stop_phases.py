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
from tests.blocked_start import blocked, blocked_stops

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
        call: int = 1, to: str = "self") -> subprocess.CompletedProcess:
    (tmp_path / "d.yaml").write_text(diagram, encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=f"{HOOK}{os.pathsep}{REPO}", SIGNAL_AT=at, SIGNAL_SEND=send,
               SIGNAL_CALL=str(call), SIGNAL_TO=to)
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
    proc = run(tmp_path, "blocks.diagram_file.reader:read_builder", "SIGTERM")
    assert proc.returncode == 143 and proc.stderr == "hierhand: interrupted\n", proc.stderr


def test_sigterm_then_sigint_while_simulating_exits_as_the_first_asks(tmp_path):
    proc = run(tmp_path, "blocks.cli.run:ProgressBar.__call__", "SIGTERM,SIGINT",
               diagram=SHORT.replace("20 ms", "1000 s"), call=2)
    assert proc.returncode == 143, proc.stderr
    r = Results.load(tmp_path / "out")
    assert r.interrupted and r.status.endswith("by SIGTERM") and len(r["ramp.y"][0]) > 0


def test_sigterm_while_a_complete_run_is_saved_does_not_exit_0(tmp_path):
    proc = run(tmp_path, "blocks.results.signals:Results.write_files", "SIGTERM")
    assert proc.returncode == 143, proc.stderr
    assert "SIGTERM while the results are saved" in proc.stderr
    assert "SIGTERM after the run: its results are complete in out" in proc.stderr
    assert Results.load(tmp_path / "out").complete


PAGES = "name: pages\ntime: {t_end: 20 ms}\nblocks:\n" + "".join(
    f"  r{i}: {{type: Ramp, period: 1 ms, params: {{slope: {i}.0}}}}\n" for i in range(1, 15)) + \
    "log: [" + ", ".join(f"r{i}.y" for i in range(1, 15)) + "]\n"
"""A run whose plot is three pages: the plotter draws one and forks a drawer for each other."""


def left_running(mark: str) -> list[int]:
    """The processes still running (zombies aside) whose environment holds ``mark``."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            if mark.encode() in (entry / "environ").read_bytes() and \
                    (entry / "stat").read_text().rsplit(")", 1)[1].split()[0] != "Z":
                found.append(int(entry.name))
        except OSError:
            continue
    return found


@pytest.mark.parametrize("send, code", [("SIGINT", 130), ("SIGTERM", 143)])
@pytest.mark.parametrize("diagram", [SHORT, PAGES], ids=["one page", "three pages"])
def test_a_signal_while_plotting_stops_the_plots_keeps_the_results_and_leaves_no_process(
        tmp_path, monkeypatch, send, code, diagram):
    """The pages are drawn by forked processes; the signal reaches the run's process from
    the first page's drawing, as a Ctrl-C or a kill does."""
    monkeypatch.setenv("PLOT_TEST_MARK", str(tmp_path))
    proc = run(tmp_path, "blocks.plot.pages:Pages.draw", send, "--plot", diagram=diagram, to="main")
    assert proc.returncode == code, proc.stderr
    assert f"plots stopped by {send}" in proc.stderr
    assert Results.load(tmp_path / "out").complete
    assert not (tmp_path / "out" / "plots").exists()
    assert [p.name for p in (tmp_path / "out").iterdir() if p.name.startswith(".")] == []
    assert left_running(f"PLOT_TEST_MARK={tmp_path}") == []


def test_plots_drawn_beside_the_run_are_those_drawn_in_its_process(tmp_path):
    """``run --plot`` (its plotter forked before the run) and ``plot`` of the same results
    (its plotter forked as it starts) draw the same pixels; that these are the pixels drawn
    in one process is tests/blocks/plot/test_beside_run.py's."""
    from PIL import Image

    (tmp_path / "d.yaml").write_text(PAGES, encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=str(REPO))
    for argv in (["run", "d.yaml", "-o", "out", "--plot"], ["plot", "out", "-o", "again.png"]):
        done = subprocess.run([sys.executable, "-m", "hierhand", *argv], cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
    drawn = sorted((tmp_path / "out" / "plots").iterdir())
    assert [p.name for p in drawn] == ["signals-1.png", "signals-2.png", "signals-3.png"]
    for number, page in enumerate(drawn, start=1):
        with Image.open(page) as a, Image.open(tmp_path / f"again-{number}.png") as b:
            assert a.size == b.size and a.tobytes() == b.tobytes(), page.name


def test_a_plotter_killed_by_a_signal_keeps_the_results_and_says_the_plots_are_missing(tmp_path):
    proc = run(tmp_path, "blocks.plot.pages:Pages.draw", "SIGKILL", "--plot", diagram=PAGES)
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr == (f"hierhand: the results are saved in out, but not their plots: the process drawing "
                           "the plots ended unexpectedly (killed by SIGKILL)\n")
    assert Results.load(tmp_path / "out").complete and not (tmp_path / "out" / "plots").exists()


@pytest.mark.parametrize("send, code", [("SIGINT", 130), ("SIGTERM", 143)])
def test_a_signal_pending_when_started_blocked_is_one_line(tmp_path, send, code):
    """Started by a parent with the signals blocked, this one pending: it is handled as
    soon as the handlers are in place."""
    (tmp_path / "d.yaml").write_text(SHORT, encoding="utf-8")
    proc = subprocess.run(blocked([sys.executable, "-m", "hierhand", "run", "d.yaml", "-o", "out"], pending=send),
                          cwd=tmp_path, env=dict(os.environ, PYTHONPATH=str(REPO)), capture_output=True, text=True,
                          timeout=120)
    assert (proc.returncode, proc.stderr) == (code, "hierhand: interrupted\n")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("diagram", [SHORT, PAGES], ids=["one page", "three pages"])
def test_the_plotters_start_with_the_signals_unblocked(tmp_path, diagram):
    """Though the run started with them blocked (by its parent), the processes that draw
    its plots can be stopped by SIGINT and SIGTERM."""
    (tmp_path / "d.yaml").write_text(diagram, encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=f"{HOOK}{os.pathsep}{REPO}", SIGNAL_AT="blocks.plot.pages:Pages.draw",
               SIGNAL_RECORD=str(tmp_path / "masks"))
    proc = subprocess.run(blocked([sys.executable, "-m", "hierhand", "run", "d.yaml", "-o", "out", "--plot"]),
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    masks = (tmp_path / "masks").read_text().splitlines()
    assert masks and [blocked_stops(line) for line in masks] == [[]] * len(masks)
