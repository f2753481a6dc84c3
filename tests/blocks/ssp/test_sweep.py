"""Sweeps of an SSP: the archive (a folder SSP zipped) travels to the workers as the
sweep's one file, with the ``--step`` of components whose SSD gives none, and ``--grid
COMPONENT.PARAM`` sets the component's FMU parameter as ``--set`` does."""

from __future__ import annotations

import csv
import shutil

import pytest

from blocks import load_diagram, simulate
from blocks.sweep import grid_points, parse_metrics
from blocks.sweep.plan import execute, prepare

from .conftest import NO_STEP, ssd, variant, write_ssp
from .test_import import component

POINTS = grid_points({"a.a": [-1.0, -2.0], "a.x0": [1.0, 3.0]})
METRICS = ["y=final(a.y)"]
STEP = "50 ms"


def test_an_ssp_sweeps_where_its_folder_is_not_with_the_step_given(first_order, tmp_path, monkeypatch):
    folder = write_ssp(tmp_path / "client" / "system", ssd(f"<ssd:Elements>{component('a', step=None)}</ssd:Elements>"),
                       first_order)
    expected = {(p["a.a"], p["a.x0"]): simulate(load_diagram(folder, overrides=p, step=STEP))["a.y"][1][-1, 0]
                for p in POINTS}
    assert len(set(expected.values())) == 4  # every parameter matters
    plan = prepare(folder, POINTS, parse_metrics(METRICS), step=STEP)
    assert plan.job.bundle.ssp and plan.job.bundle.step == STEP
    other = prepare(folder, POINTS, parse_metrics(METRICS), step="25 ms")
    assert other.diagram_hash != plan.diagram_hash  # the step is part of what a point ran
    shutil.rmtree(tmp_path / "client")
    monkeypatch.chdir(tmp_path)
    for out, how in ((tmp_path / "serial", {"serial": True}),
                     (tmp_path / "cluster", {"workers": 1, "start_method": "spawn"})):
        report, skipped, failed = execute(plan, out, progress=False, **how)
        assert (report.ran, skipped, failed) == (4, 0, 0)
        with open(out / "sweep.csv", newline="") as f:
            got = {(float(r["a.a"]), float(r["a.x0"])): float(r["y"]) for r in csv.DictReader(f)}
        assert got == pytest.approx(expected, rel=1e-15, abs=0)


def test_the_sweep_command_takes_an_ssp_and_its_step(first_order_library, tmp_path, capsys):
    from blocks.cli import PROGRAM, main

    folder = write_ssp(tmp_path / "system", ssd(f"<ssd:Elements>{component('a', step=None)}</ssd:Elements>"),
                       variant(first_order_library, NO_STEP))
    args = ["sweep", str(folder), "-o", str(tmp_path / "out"), "--grid", "a.a=-1,-2", "--metric", METRICS[0],
            "--serial", "--quiet"]
    assert main(PROGRAM, args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "component 'a' has no step size" in err[0], err
    assert main(PROGRAM, [*args, "--step", STEP]) == 0
    assert len((tmp_path / "out" / "sweep.csv").read_text().splitlines()) == 3
