"""Corpus cases of the second hardening round: values from the command line under the file
limits, sweep sizes, results folders read back, links out of the output folder, staging
names, numbers no float holds, tags that lie, and names no ASCII terminal shows.

Each case is a class of input; every limit is checked before the work it guards (the unit
tests bound that work, e.g. tests/blocks/test_yamlsource.py counts what a refusal builds).
"""

from __future__ import annotations

import io
import json
import subprocess
import zipfile
from pathlib import Path

import numpy as np

from blocks import Results

from .corpus import Case

TOY = """\
name: toy
time: {t_end: 5 ms}
blocks:
  ramp: {type: Ramp, period: 1 ms, params: {slope: 1.0}}
  g: {type: Gain, params: {k: 2.0}}
connections: [ramp.y -> g.u]
log: [ramp.y, g.y]
"""

LAUGHS = "[&a [1,1,1,1,1,1,1,1,1,1], " + ", ".join(
    f"&{b} [{', '.join([f'*{a}'] * 10)}]" for a, b in zip("abcdef", "bcdefg")) + ", [" + ", ".join(["*g"] * 10) + "]]"
"""10^8 values in one line of aliases."""

METRIC = ("--metric", "m=final(g.y)")


def _npz(arrays: dict) -> bytes:
    out = io.BytesIO()
    np.savez(out, **arrays)
    return out.getvalue()


def _huge_header() -> bytes:
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w") as archive:
        with archive.open("g.y.npy", "w") as member:
            np.lib.format.write_array_header_1_0(member, {"descr": "<f8", "fortran_order": False,
                                                          "shape": (10**12, 1)})
    return out.getvalue()


def _bomb() -> bytes:
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        with archive.open("g.y.npy", "w", force_zip64=True) as member:
            np.lib.format.write_array_header_1_0(member, {"descr": "<f8", "fortran_order": False,
                                                          "shape": (2**26, 1)})
            for _ in range(512):
                member.write(bytes(1 << 20))
    return out.getvalue()


GOOD_INFO = json.dumps({"diagram": "toy", "status": "complete", "t_end": 0.005})


def results_folder(info: str = GOOD_INFO, npz: bytes | None = None) -> dict[str, str | bytes]:
    return {"r/run.json": info, "r/signals.npz": npz if npz is not None else
            _npz({"g.y": np.zeros((3, 1)), "time:g.y": np.arange(3.0)})}


def complete_run_kept(folder: Path, proc: subprocess.CompletedProcess) -> None:
    kept = Results.load(folder / "out" / "previous-complete-run")
    assert kept.complete and kept.info["diagram"] == "toy"
    assert not Results.load(folder / "out").complete


def user_staging_folder_stays(folder: Path, proc: subprocess.CompletedProcess) -> None:
    assert (folder / "out" / ".staging-notes" / "n.txt").read_text() == "mine"
    assert Results.load(folder / "out").complete


CASES = [
    # YAML on the command line: the limits of files
    Case("set-billion-laughs", ("run", "d.yaml", "-o", "out", "--set", f"g.k={LAUGHS}"), 2,
         r"^hierhand: error: --set g\.k: YAML aliases repeat more than", files={"d.yaml": TOY}),
    Case("set-deep-nesting", ("run", "d.yaml", "-o", "out", "--set", "g.k=" + "[" * 50000), 2,
         r"--set g\.k: YAML lists and mappings nested deeper than 100", files={"d.yaml": TOY}),
    Case("set-5000-digit-integer", ("run", "d.yaml", "-o", "out", "--set", "g.k=" + "9" * 5000), 2,
         r"--set g\.k: a number written with 5000 characters", files={"d.yaml": TOY}),
    Case("set-yes-as-a-gain", ("run", "d.yaml", "-o", "out", "--set", "g.k=yes"), 2,
         r"parameter 'k' must be numeric, got True \(true/false, and YAML's yes/no", files={"d.yaml": TOY}),
    Case("set-float-tag-on-garbage", ("run", "d.yaml", "-o", "out", "--set", "g.k=!!float garbage"), 2,
         r"--set g\.k: 'garbage' is not a number, as its tag 'float' says", files={"d.yaml": TOY}),
    Case("grid-billion-laughs", ("sweep", "d.yaml", "-o", "sw", "--grid", f"g.k={LAUGHS}", *METRIC), 2,
         r"--grid g\.k: YAML aliases repeat more than", files={"d.yaml": TOY}),
    Case("points-cell-recursive-alias", ("sweep", "d.yaml", "-o", "sw", "--points", "p.csv", *METRIC), 2,
         r"--points p\.csv:2: column g\.k: recursive YAML alias",
         files={"d.yaml": TOY, "p.csv": 'g.k\n"&a [*a]"\n'}),
    Case("points-huge-field", ("sweep", "d.yaml", "-o", "sw", "--points", "p.csv", *METRIC), 2,
         r"--points p\.csv:2: not CSV: field larger than field limit",
         files={"d.yaml": TOY, "p.csv": 'g.k\n"' + "x" * 200_000 + '"\n'}),
    Case("points-with-a-bom", ("sweep", "d.yaml", "-o", "sw", "--points", "p.csv", "--serial", "-q", *METRIC), 0,
         r"^$", files={"d.yaml": TOY, "p.csv": "\ufeffg.k\n1\n2\n".encode("utf-8")}),
    # numbers and tags in files
    Case("diagram-5000-digit-integer", ("validate", "d.yaml"), 2, r"^d\.yaml:5: a number written with 5000",
         files={"d.yaml": TOY.replace("k: 2.0", "k: " + "9" * 5000)}),
    Case("diagram-nel-keeps-line-numbers", ("validate", "d.yaml"), 2, r"(?m)^d\.yaml:3: unknown top-level key 'bogus'",
         files={"d.yaml": "name: toy\x85x: 1\nblocks: {}\nbogus: 1\n"}),
    # sweep sizes and arguments
    Case("grid-of-a-billion-points", ("sweep", "d.yaml", "-o", "sw", "--grid", "g.k=" + ",".join(map(str, range(1000))),
                                      "--grid", "ramp.slope=" + ",".join(map(str, range(1000))),
                                      "--grid", "ramp.start=" + ",".join(map(str, range(1000))), *METRIC), 2,
         r"make 1e\+09 points, more than a sweep may have \(1000000\) \(hint:", files={"d.yaml": TOY}),
    Case("samples-1e8", ("sweep", "d.yaml", "-o", "sw", "--random", "g.k=uniform(0,1)", "--samples", "100000000",
                         *METRIC), 2, r"--samples 100000000 make 1e\+08 points", files={"d.yaml": TOY}),
    Case("uniform-to-infinity", ("sweep", "d.yaml", "-o", "sw", "--random", "g.k=uniform(0, inf)", *METRIC), 2,
         r"arguments must be finite", files={"d.yaml": TOY}),
    Case("negative-seed", ("sweep", "d.yaml", "-o", "sw", "--random", "g.k=uniform(0, 1)", "--seed", "-1", *METRIC),
         2, r"--seed must be a whole number of 0 or more", files={"d.yaml": TOY}),
    Case("scheduler-not-an-address", ("sweep", "d.yaml", "-o", "sw", "--grid", "g.k=1,2", "--scheduler", "nowhere",
                                      *METRIC), 2, r"--scheduler 'nowhere': not a scheduler's address",
         files={"d.yaml": TOY}),
    Case("sweep-folder-is-a-file", ("sweep", "d.yaml", "-o", "sw", "--grid", "g.k=1,2", *METRIC), 2,
         r"sweep folder sw is a file, not a folder", files={"d.yaml": TOY, "sw": "a file"}),
    # results folders read back: bad input, not internal errors
    Case("results-run-json-a-list", ("plot", "r", "-o", "p.png"), 2, r"r/run\.json: a run's record is a JSON "
         r"object, not a list", files=results_folder(info="[1, 2]")),
    Case("results-run-json-deep", ("plot", "r", "-o", "p.png"), 2, r"r/run\.json: JSON nested too deeply",
         files=results_folder(info="[" * 100_000 + "]" * 100_000)),
    Case("results-field-of-the-wrong-type", ("plot", "r", "-o", "p.png"), 2,
         r"r/run\.json: field 'status' must be text, not a list",
         files=results_folder(info=json.dumps({"status": [1]}))),
    Case("results-npz-truncated", ("plot", "r", "-o", "p.png"), 2, r"r/signals\.npz is not a readable NPZ",
         files=results_folder(npz=_npz({"g.y": np.zeros((3, 1)), "time:g.y": np.arange(3.0)})[:200])),
    Case("results-npz-one-dimensional", ("plot", "r", "-o", "p.png"), 2, r"signal 'g\.y' must be samples x width",
         files=results_folder(npz=_npz({"g.y": np.zeros(3), "time:g.y": np.arange(3.0)}))),
    Case("results-npz-lengths-differ", ("plot", "r", "-o", "p.png"), 2, r"one time per sample",
         files=results_folder(npz=_npz({"g.y": np.zeros((3, 1)), "time:g.y": np.arange(4.0)}))),
    Case("results-npz-huge-shape-header", ("plot", "r", "-o", "p.png"), 2, r"declares shape \(1000000000000, 1\)",
         files=results_folder(npz=_huge_header())),
    Case("results-npz-decompression-bomb", ("plot", "r", "-o", "p.png"), 2,
         r"beyond what the file may hold once decompressed", files=results_folder(npz=_bomb())),
    Case("results-too-many-signals-to-plot", ("plot", "r", "-o", "p.png"), 2,
         r"a plot of 2000 axes is more than one plot draws",
         files=results_folder(npz=_npz({**{f"b{i}.y": np.zeros((2, 1)) for i in range(2000)},
                                        **{f"time:b{i}.y": np.arange(2.0) for i in range(2000)}}))),
    # nothing lost, nothing written elsewhere
    Case("failed-rerun-keeps-the-complete-run", ("run", "d.yaml", "-o", "out", "--set", "g.k=1e308",
                                                 "--set", "ramp.slope=1e308"), 1,
         r"the complete run that was in out is kept in out/previous-complete-run",
         files={"d.yaml": TOY, "out/run.json": GOOD_INFO,
                "out/signals.npz": _npz({"g.y": np.zeros((3, 1)), "time:g.y": np.arange(3.0)})},
         check=complete_run_kept),
    Case("users-staging-like-folder-stays", ("run", "d.yaml", "-o", "out", "-q"), 0, r"^$",
         files={"d.yaml": TOY, "out/.staging-notes/n.txt": "mine"}, check=user_staging_folder_stays),
]

