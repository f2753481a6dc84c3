"""Signals while an isolated FMU never returns: Ctrl-C and SIGTERM stop the run (exit 130
and 143) with its results so far, and no process nor temporary file is left behind, also when the run itself
is killed. The FMU hangs in doStep at t = 0.3 s after writing its process's id and its
parent's (the launcher) into a FIFO the test reads: the sign that it hangs now. And the FMU's
processes can be stopped by those signals though the run started with them blocked."""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from blocks.fmu.model import PROCESS_ISOLATION
from tests.blocked_start import blocked, blocked_stops

fmpy = pytest.importorskip("fmpy")

from .build import misbehaving_fmu  # noqa: E402

pytestmark = pytest.mark.skipif(not PROCESS_ISOLATION, reason="FMUs run in processes of their own only on Linux")

ROOT = Path(__file__).resolve().parents[3]
HOOK = ROOT / "tests" / "blocks" / "cli" / "signal_hook"
WAIT = 120.0
"""Seconds a test waits for a sign (the FMU ready, a process ended) before it fails."""


def start(folder: Path, library: bytes, kind: str) -> tuple[subprocess.Popen, int, int]:
    """``python -m blocks run`` of a diagram whose FMU hangs at t = 0.3 s: the run, and the
    process ids of the FMU's process and of the launcher, once the FMU hangs."""
    ready = folder / "ready"
    os.mkfifo(ready)
    misbehaving_fmu(folder / "plant.fmu", kind, library, f"fmi{kind[-1]}DoStep hang 0.3 {ready}")
    (folder / "d.yaml").write_text("""\
name: hangs
time: {t_end: 1 s}
blocks:
  src: {type: Step, period: 0.1 s, params: {time: 0.2}}
  plant: {type: FMU, period: 0.1 s, params: {path: plant.fmu}}
connections: [src.y -> plant.u]
log: [plant.y]
""")
    fd = os.open(ready, os.O_RDONLY | os.O_NONBLOCK)
    (folder / "tmp").mkdir()  # TMPDIR, where the FMU is unpacked
    env = dict(os.environ, PYTHONPATH=str(ROOT), TMPDIR=str(folder / "tmp"), BLOCKS_SCRATCH="")
    proc = subprocess.Popen([sys.executable, "-m", "blocks", "run", "d.yaml", "-o", "out", "-q"], cwd=folder,
                            stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert select.select([fd], [], [], WAIT)[0], "the FMU never said it hangs"
        host, launcher = (int(x) for x in os.read(fd, 64).split())
    except BaseException:
        proc.kill()
        raise
    finally:
        os.close(fd)
    return proc, host, launcher


def ended(pid: int) -> bool:
    """Whether the process ``pid`` ends (within WAIT seconds; it need not be our child)."""
    try:
        handle = os.pidfd_open(pid)
    except ProcessLookupError:
        return True
    try:
        return bool(select.select([handle], [], [], WAIT)[0])
    finally:
        os.close(handle)


@pytest.mark.parametrize("signum, code, kind", [(signal.SIGINT, 130, "cs2"), (signal.SIGTERM, 143, "cs3")],
                         ids=["SIGINT-compiled-step", "SIGTERM-python-step"])
def test_a_signal_stops_a_run_whose_fmu_never_returns(tmp_path, misbehaving, signum, code, kind):
    proc, host, launcher = start(tmp_path, misbehaving[kind], kind)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=WAIT)
    name = signal.Signals(signum).name
    assert proc.returncode == code, err
    assert f"interrupted at t=0.3 s by {name}" in err and "Traceback" not in err
    info = json.loads((tmp_path / "out" / "run.json").read_text())
    assert info["status"] == f"interrupted at t=0.3 s by {name}"
    assert (tmp_path / "out" / "signals.npz").is_file()
    assert ended(host) and ended(launcher)
    assert list((tmp_path / "tmp").iterdir()) == []  # the unpacked FMU removed


def test_killing_the_run_ends_its_fmu_processes(tmp_path, misbehaving):
    """SIGKILL gives the run no chance to clean up: the launcher sees its end of their socket
    close and exits, and the FMU's process dies with the launcher (PR_SET_PDEATHSIG)."""
    proc, host, launcher = start(tmp_path, misbehaving["cs2"], "cs2")
    proc.kill()
    proc.communicate(timeout=WAIT)
    assert ended(launcher) and ended(host)


def test_the_fmu_processes_start_with_the_signals_unblocked(tmp_path, fmus):
    """The run starts with SIGINT and SIGTERM blocked (by its parent); the FMU's process
    (forked by the launcher the run spawns) has them unblocked."""
    (tmp_path / "d.yaml").write_text(f"""\
name: isolated
time: {{t_end: 1 s}}
blocks:
  src: {{type: Step, period: 0.1 s, params: {{time: 0.2}}}}
  plant: {{type: FMU, period: 0.1 s, params: {{path: {fmus.fmi2}, isolation: process}}}}
connections: [src.y -> plant.u]
log: [plant.y]
""")
    env = dict(os.environ, PYTHONPATH=f"{HOOK}{os.pathsep}{ROOT}", SIGNAL_AT="blocks.fmu.isolation.server:serve",
               SIGNAL_RECORD=str(tmp_path / "masks"), BLOCKS_SCRATCH="")
    proc = subprocess.run(blocked([sys.executable, "-m", "blocks", "run", "d.yaml", "-o", "out", "-q"]), cwd=tmp_path,
                          env=env, capture_output=True, text=True, timeout=WAIT)
    assert proc.returncode == 0, proc.stderr
    masks = (tmp_path / "masks").read_text().splitlines()
    assert len(masks) == 1 and blocked_stops(masks[0]) == [], masks
