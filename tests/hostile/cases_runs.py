"""Corpus cases for ``hierhand run`` and its output folder: a bad -o is refused before the
run, a run's files replace the previous run's as one set, incomplete runs keep their data.

A bad output folder is tried with a diagram whose run fails at its first tick (exit 1): the
answer 2, about the folder, proves that the folder was checked before the simulation
started, whatever the machine's speed.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
from pathlib import Path

from blocks import Results

from ..blocks.cli.test_cli import FAILS_AT_ONCE
from .corpus import Case

SHORT = """\
name: short
time: {t_end: 10 ms}
blocks:
  ramp: {type: Ramp, period: 1 ms, params: {slope: 1.0}}
log: [ramp.y]
"""

FAILING = """\
name: failing
time: {t_end: 10 ms}
blocks:
  ramp: {type: Ramp, period: 1 ms, params: {slope: 1.0}}
  limit: {type: Saturation, params: {lower: 0.0, upper: 1.0}}
  plant: {type: HandPlant, period: 0.1 ms}
  tau: {type: Step, period: 1 ms, params: {time: 0.002, before: [0, 0, 0, 0, 0, 0, 0, 0, 0],
                                           after: [0, 0, 0, 0, 0, 0, 0, 1.0e150, 0]}}
connections: [ramp.y -> limit.u, tau.y -> plant.tau]
log: [limit.y, plant.q]
"""

PREVIOUS_RUN = {"out/signals.npz": b"an earlier run's signals", "out/signals.csv": "time\n0\n",
                "out/run.json": '{"diagram": "earlier", "status": "complete"}\n',
                "out/plots/signals.png": b"an earlier run's plot", "out/notes.txt": "the user's own notes\n"}


def one_line(folder: Path, proc: subprocess.CompletedProcess) -> None:
    assert len(proc.stderr.splitlines()) == 1, proc.stderr


def replaced_as_one_set(folder: Path, proc: subprocess.CompletedProcess) -> None:
    """The earlier run's files are gone or replaced, the user's stay, modes honour the umask."""
    out = folder / "out"
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt", "run.json", "signals.npz"]
    r = Results.load(out)
    assert r.complete and r.info["diagram"] == "short" and list(r) == ["ramp.y"]
    umask = os.umask(0)
    os.umask(umask)
    assert all((out / n).stat().st_mode & 0o777 == 0o666 & ~umask for n in ("run.json", "signals.npz"))


def failed_run_kept(folder: Path, proc: subprocess.CompletedProcess) -> None:
    """The data up to the failure, its time once in the status, and the plot."""
    r = Results.load(folder / "out")
    assert r.status.startswith("failed at t=0.0022 s") and set(re.findall(r"t=(\S+) s", r.status)) == {"0.0022"}
    assert r["plant.q"][0][-1] == 0.0022
    assert (folder / "out" / "plots" / "signals.png").is_file()
    assert json.loads((folder / "out" / "run.json").read_text())["t_stop"] == 0.0022


CASES = [
    Case("run-output-is-a-file", ("run", "d.yaml", "-o", "out.txt"), 2,
         r"^hierhand: error: output folder out\.txt is a file, not a folder$",
         files={"d.yaml": FAILS_AT_ONCE, "out.txt": "not a folder"}, check=one_line),
    Case("run-output-under-a-file", ("run", "d.yaml", "-o", "out.txt/run"), 2,
         r"output folder out\.txt/run cannot be created: out\.txt is a file",
         files={"d.yaml": FAILS_AT_ONCE, "out.txt": "not a folder"}, check=one_line),
    Case("run-output-default-under-a-file", ("run", "d.yaml"), 2,
         r"output folder runs/long cannot be created: runs is a file",
         files={"d.yaml": FAILS_AT_ONCE, "runs": "not a folder"}, check=one_line),
    Case("run-refused-after-the-check-leaves-no-folder", ("run", "d.yaml", "-o", "out", "--t-end", "0.00015"), 2,
         r"t_end", files={"d.yaml": SHORT}, absent=("out",)),
    Case("run-replaces-the-previous-runs-files-as-one-set", ("run", "d.yaml", "-o", "out"), 0, r"^$",
         files={"d.yaml": SHORT, **PREVIOUS_RUN}, absent=("out/signals.csv", "out/plots"),
         check=replaced_as_one_set),
    Case("run-failure-keeps-data-and-plot-up-to-one-time", ("run", "d.yaml", "-o", "out", "--plot"), 1,
         r"failed at t=0\.0022 s: .* in the step at t=0\.0022 s", files={"d.yaml": FAILING},
         check=failed_run_kept),
]
