"""``hierhand sweep`` and ``sweep-plot`` end to end on the toy diagram: a LocalCluster of 2
workers, in-process runs, resuming, failure isolation, input errors, and a real
``dask scheduler`` with two ``dask worker`` processes on loopback."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from hierhand.cli import main

ROOT = Path(__file__).resolve().parents[3]
TOY = str(ROOT / "diagrams" / "toy.yaml")
BASE = [TOY, "--t-end", "50 ms", "--metric", "y=final(plant.y)", "--metric", "t=first_time_above(plant.y, 0.001)",
        "-q"]


def rows(out: Path) -> list[dict]:
    with open(out / "sweep.csv", newline="") as f:
        return list(csv.DictReader(f))


def by_k(out: Path) -> dict:
    return {r["prop.k"]: r for r in rows(out)}


def test_grid_on_a_local_cluster_of_two_workers_with_a_failing_point(tmp_path, capsys):
    out = tmp_path / "sweep"
    code = main(["sweep", *BASE, "-o", str(out), "--grid", "prop.k=1,2,abc,4", "--workers", "2"])
    assert code == 1
    assert "1 point(s) failed" in capsys.readouterr().err
    got = by_k(out)
    assert set(got) == {"1", "2", "4", '"abc"'}
    assert got['"abc"']["status"] == "failed" and "must be numeric" in got['"abc"']["error"]
    assert all(got[k]["status"] == "ok" and float(got[k]["y"]) > 0 for k in ("1", "2", "4"))
    assert float(got["1"]["y"]) < float(got["2"]["y"]) < float(got["4"]["y"])
    serial = tmp_path / "serial"
    main(["sweep", *BASE, "-o", str(serial), "--grid", "prop.k=1,2,abc,4", "--serial"])
    assert {k: r["y"] for k, r in by_k(serial).items()} == {k: r["y"] for k, r in got.items()}


def test_resume_runs_only_the_missing_points(tmp_path, capsys):
    out = tmp_path / "sweep"
    args = ["sweep", *BASE[:-1], "-o", str(out), "--grid", "prop.k=1,2,4", "--grid", "integ.B=[[0.02]],[[0.04]]",
            "--workers", "0"]
    assert main(args) == 0
    first = rows(out)
    assert len(first) == 6
    lines = (out / "sweep.csv").read_text().splitlines(keepends=True)
    (out / "sweep.csv").write_text("".join(lines[:3]) + lines[3][:20])  # two rows kept, one torn
    capsys.readouterr()
    assert main(args) == 0
    assert "4 run in this process (0 failed), 2 already in" in capsys.readouterr().out
    again = rows(out)
    assert len(again) == 6
    assert sorted(r["point_hash"] for r in again) == sorted(r["point_hash"] for r in first)
    assert {r["point_hash"]: r["y"] for r in again} == {r["point_hash"]: r["y"] for r in first}
    assert main(args) == 0
    assert "0 run (0 failed), 6 already in" in capsys.readouterr().out


def test_random_points_and_sweep_plot(tmp_path):
    out = tmp_path / "sweep"
    assert main(["sweep", *BASE, "-o", str(out), "--random", "prop.k=uniform(1,4)", "--grid", "integ.B=[[0.02]],"
                 "[[0.04]]", "--samples", "3", "--seed", "5", "--serial"]) == 0
    assert len(rows(out)) == 6
    assert main(["sweep-plot", str(out), "--x", "prop.k", "--metric", "y", "-o", str(tmp_path / "l.png")]) == 0
    assert main(["sweep-plot", str(out), "--x", "prop.k", "--y", "integ.B", "--metric", "y",
                 "-o", str(tmp_path / "h.png")]) == 0
    assert (tmp_path / "l.png").stat().st_size > 1000 and (tmp_path / "h.png").stat().st_size > 1000
    assert main(["sweep-plot", str(out), "--x", "prop.q", "--metric", "y", "-o", str(tmp_path / "x.png")]) == 2


def test_sweep_plot_of_a_folder_without_a_sweep_names_the_command(tmp_path, capsys):
    assert main(["sweep-plot", str(tmp_path), "--x", "a.b", "--metric", "m", "-o", str(tmp_path / "x.png")]) == 2
    assert capsys.readouterr().err == (f"hierhand: error: {tmp_path}: no sweep.csv here; is this the -o folder of "
                                       "'hierhand sweep'?\n")


def test_points_file(tmp_path):
    points = tmp_path / "points.csv"
    points.write_text("prop.k,integ.B\n1,[[0.02]]\n3,[[0.01]]\n")
    out = tmp_path / "sweep"
    assert main(["sweep", *BASE, "-o", str(out), "--points", str(points), "--serial"]) == 0
    assert [(r["prop.k"], r["integ.B"]) for r in rows(out)] == [("1", "[[0.02]]"), ("3", "[[0.01]]")]


@pytest.mark.parametrize("extra, message", [
    (["--grid", "prop.q=1,2"], "block 'prop' (Gain) has no parameter 'q'"),
    (["--grid", "propp.k=1,2"], "no block named 'propp'"),
    (["--grid", "prop.k=1", "--metric", "z=median(plant.y)"], "unknown reducer or measure 'median'"),
    (["--grid", "prop.k=1", "--metric", "z=final(plant.y[3])"], "index 3 is out of range"),
    (["--grid", "prop.k=1", "--metric", "z=final(prop.y)"], "not logged"),
    (["--grid", "prop.k=1", "--t-end", "-1"], "--t-end must be positive"),
    ([], "no points"),
])
def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys, extra, message):
    assert main(["sweep", TOY, "-o", str(tmp_path / "s"), "--serial", *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1
    assert not (tmp_path / "s" / "sweep.csv").exists()


def test_sweep_on_a_running_scheduler(tmp_path, dask_elsewhere):
    out = tmp_path / "sweep"
    assert main(["sweep", *BASE, "-o", str(out), "--grid", "prop.k=1,2,4", "--scheduler", dask_elsewhere.address]) == 0
    assert sorted(r["prop.k"] for r in rows(out)) == ["1", "2", "4"]
    assert all(r["status"] == "ok" for r in rows(out))


CRASH_MODULE = '''
import os
from blocks import Block


class CrashOn(Block):
    """y = u, except that the process dies (no exception, no clean-up) when u equals crash_on."""

    def __init__(self, crash_on: float = -1.0):
        self.crash_on = float(crash_on)
        self.inputs = {"u": 1}
        self.outputs = {"y": 1}
        self.feedthrough = True

    def output(self, t, state, inputs):
        if inputs["u"][0] == self.crash_on:
            os._exit(3)
        return {"y": inputs["u"].copy()}
'''

CRASH_DIAGRAM = """\
name: crash
time: {t_end: 5 ms}
blocks:
  src: {type: Constant, params: {value: 1.0}}
  crash: {type: "python:crash_block_mod:CrashOn", period: 1 ms, params: {crash_on: 12.0}}
connections:
  - src.y -> crash.u
log: [crash.y]
"""


def test_a_point_that_kills_its_worker_fails_alone(tmp_path, monkeypatch, capfd):
    import dask

    (tmp_path / "crash_block_mod.py").write_text(CRASH_MODULE, encoding="utf-8")
    (tmp_path / "crash.yaml").write_text(CRASH_DIAGRAM, encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    out = tmp_path / "sweep"
    values = ",".join(str(v) for v in range(1, 17))
    # After the first single-point tasks, the 16 points go in chunks, one of them holding the
    # point that kills its worker: that chunk is lost whole and its points run again alone.
    # A lost-worker timeout of 0 s stands for a restart slower than any timeout (a busy
    # machine): the sweep's cluster still waits for its nannies to restart their workers.
    with dask.config.set({"distributed.scheduler.allowed-failures": 1, "distributed.deploy.lost-worker-timeout": "0 s"}):
        code = main(["sweep", str(tmp_path / "crash.yaml"), "-o", str(out), "--grid", f"src.value={values}",
                     "--metric", "y=final(crash.y)", "--trust", "--workers", "2", "-q"])
    got = {float(r["src.value"]): r for r in rows(out)}
    assert code == 1, got
    err = capfd.readouterr().err.strip().splitlines()  # Dask's own log lines included
    assert len(err) == 1 and "1 point(s) failed" in err[0], (err, [(v, r["error"]) for v, r in got.items()])
    assert sorted(got) == [float(v) for v in range(1, 17)]
    assert got[12.0]["status"] == "failed" and "KilledWorker" in got[12.0]["error"]
    assert all(r["status"] == "ok" and float(r["y"]) == v for v, r in got.items() if v != 12.0)


def test_a_point_that_fails_to_load_names_the_option_that_gave_it():
    from blocks.sweep.runner import SweepJob, run_point

    job = SweepJob(diagram=TOY, t_end="10 ms", origins=(("prop.k.x", "--grid prop.k.x=1,2"),))
    outcome = run_point(job, {"prop.k.x": 1})
    assert outcome.status == "failed" and outcome.error.startswith("--grid prop.k.x=1,2: 'prop.k' is a float")


def test_the_start_method_variable_is_checked_before_anything_runs(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("HIERHAND_SWEEP_START", "bogus")
    assert main(["sweep", *BASE, "-o", str(tmp_path / "s"), "--grid", "prop.k=1", "--workers", "1"]) == 2
    assert capsys.readouterr().err.startswith("hierhand: error: HIERHAND_SWEEP_START=bogus: this platform starts "
                                              "processes with ")
    assert not (tmp_path / "s").exists()
    assert main(["sweep", *BASE, "-o", str(tmp_path / "s"), "--grid", "prop.k=1", "--serial"]) == 0
