"""Ctrl-C during ``hierhand sweep``, sent as a terminal sends it (SIGINT to the whole process
group, workers included): one line and exit code 130, no traceback from any process, only
whole rows in sweep.csv, no process left behind, and the same command then runs the rest.
SIGTERM to the sweep's process alone (as a batch system or ``timeout`` sends it), and a
point that kills the process running it: nothing left in TMPDIR (``blocks.process.scratch``), no
process left.

The signals are sent by the sweep's process itself just before it writes its third row
(``tests/blocks/cli/signal_hook``): mid-sweep whatever the machine's speed, so each point
can be short."""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
TOY = ROOT / "diagrams" / "toy.yaml"
GRID = "prop.k=1,2,3,4,5,6,7,8"
HOOK = ROOT / "tests" / "blocks" / "cli" / "signal_hook"


def _diagram(folder: Path) -> Path:
    """The toy diagram logging every 1000th sample."""
    text = TOY.read_text().replace("log: [plant.y]", "log: [{signal: plant.y, decimate: 1000}]")
    assert "decimate: 1000" in text
    path = folder / "toy_long.yaml"
    path.write_text(text)
    return path


def _command(out: Path, mode: list[str]) -> list[str]:
    return [sys.executable, "-m", "hierhand", "sweep", str(_diagram(out.parent)), "-o", str(out),
            "--t-end", "20 s", "--metric", "y=final(plant.y)", "--grid", GRID, "-q", *mode]


def _empty_tmpdir(tmp_path: Path) -> dict[str, str]:
    """The environment of a sweep whose TMPDIR is a new empty folder, ``tmp_path / 'tmp'``."""
    (tmp_path / "tmp").mkdir()
    return {**{k: v for k, v in os.environ.items() if k != "BLOCKS_SCRATCH"}, "TMPDIR": str(tmp_path / "tmp")}


def _signalled(tmp_path: Path, send: str, **more: str) -> dict[str, str]:
    """``_empty_tmpdir``'s environment for a sweep that sends ``send`` just before it writes
    its third row to sweep.csv (two whole rows are in); ``more`` for the hook."""
    path = os.pathsep.join([str(HOOK), *filter(None, [os.environ.get("PYTHONPATH")])])
    return {**_empty_tmpdir(tmp_path), "PYTHONPATH": path, "SIGNAL_AT": "blocks.sweep.store:SweepStore.append",
            "SIGNAL_SEND": send, "SIGNAL_CALL": "3", **more}


def _left_in(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def _rows(out: Path) -> list[dict]:
    with open(out / "sweep.csv", newline="") as f:
        return list(csv.DictReader(f))


def _group_gone(pgid: int, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.05)
    return False


@pytest.mark.skipif(not hasattr(os, "killpg"), reason="process groups are POSIX")
@pytest.mark.parametrize("mode", [["--workers", "2"], ["--serial"], []], ids=["local-cluster", "serial", "default"])
def test_ctrl_c_keeps_whole_rows_and_the_same_command_resumes(tmp_path, mode):
    out = tmp_path / "sweep"
    env = _signalled(tmp_path, "SIGINT", SIGNAL_TO="group")
    proc = subprocess.Popen(_command(out, mode), cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, env=env)
    try:
        _, err = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=60)
    assert proc.returncode == 130
    assert "Traceback" not in err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("hierhand: sweep interrupted: ")
    assert "run the same command again" in lines[0]
    assert _group_gone(proc.pid, timeout=120), "a worker process outlived the interrupted sweep"
    assert _left_in(tmp_path / "tmp") == []

    kept = _rows(out)
    assert 2 <= len(kept) < 8
    assert f"{len(kept)} of 8 points are in" in lines[0]
    assert all(r["status"] == "ok" and float(r["y"]) > 0 for r in kept)
    assert (out / "sweep.csv").read_text().endswith("\n")

    done = subprocess.run(_command(out, mode), cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    final = _rows(out)
    assert len(final) == 8 and len({r["point_hash"] for r in final}) == 8
    assert {r["point_hash"]: r["y"] for r in final if r["point_hash"] in {k["point_hash"] for k in kept}} == \
        {r["point_hash"]: r["y"] for r in kept}


@pytest.mark.skipif(not hasattr(os, "killpg"), reason="process groups are POSIX")
@pytest.mark.parametrize("mode", [["--workers", "2"], []], ids=["local-cluster", "default"])
def test_sigterm_to_the_sweep_leaves_nothing_in_tmpdir_and_no_process(tmp_path, mode):
    """The sweep's process alone gets SIGTERM once rows are in (its local runner or its Dask
    workers have written the diagram's files): exit 143, and the runner's and workers'
    files, which they could not remove themselves, are gone with the sweep's own."""
    out = tmp_path / "sweep"
    proc = subprocess.Popen(_command(out, mode), cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, env=_signalled(tmp_path, "SIGTERM"))
    try:
        _, err = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=60)
    assert proc.returncode == 143, err
    assert err.startswith("hierhand: sweep interrupted: ") and len(err.splitlines()) == 1, err
    assert _group_gone(proc.pid, timeout=120), "a worker process outlived the stopped sweep"
    assert _left_in(tmp_path / "tmp") == []


def test_a_point_that_kills_its_process_leaves_nothing_in_tmpdir(tmp_path):
    """The local runner dies under a point (its diagram files still written): the sweep runs
    the rest in a new one, and at its end nothing of either is left."""
    from .test_sweep_cli import CRASH_DIAGRAM, CRASH_MODULE

    (tmp_path / "crash_block_mod.py").write_text(CRASH_MODULE, encoding="utf-8")
    (tmp_path / "crash.yaml").write_text(CRASH_DIAGRAM, encoding="utf-8")
    env = {**_empty_tmpdir(tmp_path), "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)])}
    done = subprocess.run([sys.executable, "-m", "hierhand", "sweep", "crash.yaml", "-o", "sweep", "--grid",
                           "src.value=11,12,13", "--metric", "y=final(crash.y)", "--trust", "-q"], cwd=tmp_path,
                          env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 1 and "1 point(s) failed" in done.stderr, done.stderr
    assert "died (exit code 3)" in (tmp_path / "sweep" / "sweep.csv").read_text()
    assert _left_in(tmp_path / "tmp") == []
