"""Ctrl-C and SIGTERM during ``hierhand run``: the results so far are saved, completely,
whatever else arrives while they are written.

The diagram is one long advance span (nothing fires after t = 0, where a Touch block
marks the start): an interrupt lands in it, and the span is fast enough to log a few
hundred thousand samples in a moment, whose CSV takes a good part of a second to write.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from blocks import Results

pytestmark = pytest.mark.skipif(os.name != "posix", reason="POSIX signals")

REPO = Path(__file__).resolve().parents[3]
DECIMATE, PERIOD = 100, 1e-4
SPAN = """\
name: span
time: {{t_end: 1000000 s}}
blocks:
  started: {{type: "python:tests.blocks.blockdefs:Touch", params: {{path: "{marker}"}}}}
  one: {{type: Constant, params: {{value: 1.0}}}}
  acc: {{type: "python:tests.blocks.blockdefs:FastAccumulator", period: 0.1 ms}}
connections: [one.y -> acc.u]
log: [{{signal: acc.y, decimate: {decimate}}}]
"""


def start(tmp_path: Path, *options: str) -> tuple[subprocess.Popen, Path]:
    """``hierhand run`` of the span diagram, returned once the run has started."""
    marker = tmp_path / "started"
    diagram = tmp_path / "span.yaml"
    diagram.write_text(SPAN.format(marker=marker, decimate=DECIMATE), encoding="utf-8")
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "hierhand", "run", str(diagram), "-o", str(out), "--trust",
                             *options], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=dict(os.environ, PYTHONPATH=str(REPO)))
    deadline = time.monotonic() + 30
    while not marker.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the run did not start"
        time.sleep(0.01)
    time.sleep(0.2)  # into the span: some 10^5 samples logged
    return proc, out


def finish(proc: subprocess.Popen) -> str:
    try:
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert "Traceback" not in err, err
    return err


def assert_saved_up_to_the_status_time(out: Path, interrupted_by: str) -> Results:
    """The saved run is marked interrupted at the time its data reach (the span's last
    logged sample, at most one decimation step before the tick it had computed)."""
    r = Results.load(out)
    assert r.interrupted and r.status.endswith(f" by {interrupted_by}"), r.status
    t, y = r["acc.y"]
    assert len(t) > 1000
    np.testing.assert_allclose(y[:, 0], t / PERIOD, rtol=1e-9)  # every sample, none lost
    t_stop = r.info["t_stop"]
    assert t[-1] <= t_stop < t[-1] + DECIMATE * PERIOD, (t[-1], t_stop)
    assert r.status.startswith(f"interrupted at t={t_stop:.9g} s")
    return r


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["SIGINT", "SIGTERM"])
def test_a_stop_inside_an_advance_span_saves_the_run_up_to_where_it_got(tmp_path, sig, code):
    """Ctrl-C, and SIGTERM treated alike (exit 143, as a shell reports it)."""
    proc, out = start(tmp_path)
    proc.send_signal(sig)
    err = finish(proc)
    assert proc.returncode == code, err
    assert_saved_up_to_the_status_time(out, sig.name)
    assert "interrupted at t=" in err and f"by {sig.name}" in err
    assert "partial results (marked incomplete) saved" in err


def saving(out: Path) -> None:
    """Wait until the results are being written (their staging folder exists)."""
    deadline = time.monotonic() + 30
    while not (out.is_dir() and any(p.name.startswith(".") for p in out.iterdir())):
        assert time.monotonic() < deadline, "the results were never written"
        time.sleep(0.001)


@pytest.mark.parametrize("second", ["50 ms later", "while saving"])
def test_a_second_ctrl_c_cannot_lose_the_results(tmp_path, second):
    proc, out = start(tmp_path, "--csv")
    proc.send_signal(signal.SIGINT)
    if second == "while saving":
        saving(out)
    time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    err = finish(proc)
    assert proc.returncode == 130, err
    assert "SIGINT while the results are saved" in err  # the second one came after the first was handled
    r = assert_saved_up_to_the_status_time(out, "SIGINT")
    rows = (out / "signals.csv").read_text(encoding="utf-8").count("\n")
    assert rows == len(r["acc.y"][0]) + 1

