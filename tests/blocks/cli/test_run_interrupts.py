"""Ctrl-C and SIGTERM during ``hierhand run``: the results so far are saved, completely,
whatever else arrives while they are written.

The diagram is one long advance span (nothing fires after t = 0): an interrupt lands in
it. The accumulator creates a marker file once it has logged READY samples (at the start
of an advance call with READY x DECIMATE hits behind it), and the test sends its signal
only then, so what it asserts holds on a machine of any speed. A second signal while
the results are saved is sent by the process itself when it starts writing them
(``signal_hook``).
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
HOOK = Path(__file__).resolve().parent / "signal_hook"
DECIMATE, PERIOD = 100, 1e-4
READY = 20_000
"""Samples logged before the test sends its signal."""
SPAN = """\
name: span
time: {{t_end: 1000000 s}}
blocks:
  one: {{type: Constant, params: {{value: 1.0}}}}
  acc: {{type: "python:tests.blocks.blockdefs:ReadyAccumulator", period: 0.1 ms,
         params: {{path: "{marker}", after: {after}}}}}
connections: [one.y -> acc.u]
log: [{{signal: acc.y, decimate: {decimate}}}]
"""


def start(tmp_path: Path, *options: str, env: dict[str, str] | None = None) -> tuple[subprocess.Popen, Path]:
    """``hierhand run`` of the span diagram, returned once it has logged READY samples
    (``env``: more of the process's environment)."""
    marker = tmp_path / "ready"
    diagram = tmp_path / "span.yaml"
    diagram.write_text(SPAN.format(marker=marker, after=READY * DECIMATE, decimate=DECIMATE), encoding="utf-8")
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "hierhand", "run", str(diagram), "-o", str(out), "--trust",
                             *options], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONPATH": str(REPO), **(env or {})})
    while not marker.exists():  # a run that never logs them is a hang: pytest-timeout ends it, not a clock here
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.01)
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
    assert len(t) >= READY
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


@pytest.mark.parametrize("second", ["at once", "while saving"])
def test_a_second_ctrl_c_cannot_lose_the_results(tmp_path, second):
    """A second Ctrl-C right behind the first (the two may reach the process as one), or
    one that the process sends itself when it starts writing the results: noted there,
    and the results are whole."""
    hook = {"PYTHONPATH": f"{HOOK}{os.pathsep}{REPO}", "SIGNAL_AT": "blocks.results.signals:Results.write_files"}
    proc, out = start(tmp_path, "--csv", env=hook if second == "while saving" else None)
    proc.send_signal(signal.SIGINT)
    if second == "at once":
        proc.send_signal(signal.SIGINT)
    err = finish(proc)
    assert proc.returncode == 130, err
    if second == "while saving":
        assert "SIGINT while the results are saved" in err
    r = assert_saved_up_to_the_status_time(out, "SIGINT")
    rows = (out / "signals.csv").read_text(encoding="utf-8").count("\n")
    assert rows == len(r["acc.y"][0]) + 1
