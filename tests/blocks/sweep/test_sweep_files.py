"""A sweep's diagram travels as content: workers that cannot see the client's files or
folders run its points all the same (serially, on a LocalCluster worker, on a ``dask
worker`` started elsewhere); the point hashes follow the files' content; ``keep_results``
brings each run's files home; a scheduler with other package versions is refused."""

from __future__ import annotations

import csv
import math
import os
import shutil
import tempfile
import zipfile
from pathlib import Path

import pytest

from blocks import Results, load_diagram
from blocks.sweep import grid_points, parse_metrics, run_sweep
from blocks.sweep.plan import execute, prepare
from blocks.sweep.runner import SweepJob, run_point

ROOT = Path(__file__).resolve().parents[3]

FAILING = '''
from blocks import Block


class FailAt(Block):
    """y = u until time ``at``, then an error."""

    def __init__(self, at: float = 1.0):
        self.at = float(at)
        self.inputs = {"u": 1}
        self.outputs = {"y": 1}
        self.feedthrough = True

    def output(self, t, state, inputs):
        if t >= self.at:
            raise RuntimeError(f"failing at t={float(t):g}")
        return {"y": inputs["u"].copy()}
'''

DIAGRAM = """\
name: files
time: {t_end: 20 ms}
blocks:
  ref:   {type: Constant, params_file: params/ref.yaml}
  err:   {type: Sum, params: {signs: "+-"}}
  plant: {type: DiscreteStateSpace, period: 1 ms, params_file: ../shared/plant.yaml}
  prop:  {type: Gain, period: 1 ms, params: {k: 5.0}}
  fail:  {type: "python:failing:FailAt", period: 1 ms, params: {at: 1.0}}
connections:
  - ref.y -> err.u0
  - plant.y -> err.u1
  - err.y -> prop.u
  - prop.y -> fail.u
  - fail.y -> plant.u
log: [plant.y]
"""

POINTS = grid_points({"ref.value": [1.0, 2.0], "fail.at": [1.0, 0.005]})
METRICS = ["y=final(plant.y)"]


def make_project(root: Path, b: float = 0.1) -> Path:
    """proj/diagrams/files.yaml with a params file below it, one beside its folder (../)
    and a python: block module."""
    (root / "diagrams" / "params").mkdir(parents=True)
    (root / "shared").mkdir()
    (root / "diagrams" / "params" / "ref.yaml").write_text("value: 1.0\n")
    (root / "shared" / "plant.yaml").write_text(f"{{A: [[0.9]], B: [[{b}]], C: [[1.0]], D: [[0.0]]}}\n")
    (root / "diagrams" / "failing.py").write_text(FAILING)
    path = root / "diagrams" / "files.yaml"
    path.write_text(DIAGRAM)
    return path


def rows(out: Path) -> list[dict]:
    with open(out / "sweep.csv", newline="") as f:
        return list(csv.DictReader(f))


def by_point(out: Path) -> dict:
    return {(float(r["ref.value"]), float(r["fail.at"])): r for r in rows(out)}


def direct(diagram: Path) -> dict:
    """Each point run from the files themselves, in this process."""
    job = SweepJob(diagram=str(diagram), metrics=tuple(parse_metrics(METRICS)), trust=True)
    return {(p["ref.value"], p["fail.at"]): run_point(job, p) for p in POINTS}


def check(out: Path, expected: dict) -> None:
    got = by_point(out)
    assert set(got) == set(expected)
    for key, outcome in expected.items():
        assert got[key]["status"] == outcome.status, (key, got[key]["error"])
        if outcome.status == "ok":
            assert float(got[key]["y"]) == pytest.approx(outcome.values["y"], rel=1e-12)
        else:
            assert got[key]["error"] == outcome.error


def test_the_loader_reports_the_files_a_diagram_reads(tmp_path):
    diagram = make_project(tmp_path / "proj")
    files = load_diagram(diagram, trust=True).files
    assert set(files) == {"params/ref.yaml", "../shared/plant.yaml", "failing.py"}
    assert all(p.is_file() for p in files.values())
    assert load_diagram(ROOT / "diagrams" / "toy.yaml").files == {}


def test_points_run_where_the_client_files_are_not(tmp_path, monkeypatch):
    diagram = make_project(tmp_path / "proj")
    expected = direct(diagram)
    assert [expected[k].status for k in sorted(expected)] == ["failed", "ok", "failed", "ok"]
    plan = prepare(diagram, POINTS, parse_metrics(METRICS), trust=True, keep_results=True)
    names = {f.ref: f.name for f in plan.job.bundle.files}
    assert names == {"params/ref.yaml": "tree/diagrams/params/ref.yaml", "../shared/plant.yaml": "tree/shared/plant.yaml",
                     "failing.py": "tree/diagrams/failing.py"}
    shutil.rmtree(tmp_path / "proj")  # nothing of the client's folder is left to read
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    for out, how in ((tmp_path / "serial", {"serial": True}),
                     (tmp_path / "cluster", {"workers": 1, "start_method": "spawn"})):
        report, skipped, failed = execute(plan, out, progress=False, **how)
        assert (report.ran, skipped, failed) == (4, 0, 2)
        check(out, expected)
        for row in rows(out):  # --keep-results: every run's files, the failed runs' partial ones too
            results = Results.load(out / "runs" / row["point_hash"])
            sweep = results.info["sweep"]
            assert sweep["status"] == row["status"] and sweep["point_hash"] == row["point_hash"]
            assert results.info["diagram_file"] == str(diagram)
            if row["status"] == "ok":
                assert results.complete and float(row["y"]) == pytest.approx(results["plant.y"][1][-1, 0], rel=1e-12)
                assert sweep["metrics"]["y"] == pytest.approx(float(row["y"]), rel=1e-12)
            else:
                assert results.status.startswith("failed") and math.isclose(results.stop_time, 0.005)
                assert results["plant.y"][0][-1] <= 0.005 + 1e-12  # what it computed before it failed
    assert not list(Path(tempfile.gettempdir()).glob(f"blocks-*/bundle-{plan.diagram_hash[:12]}-*"))


def test_a_changed_params_file_makes_new_points(tmp_path):
    diagram = make_project(tmp_path / "proj")
    out = tmp_path / "sweep"
    metrics = parse_metrics(METRICS)
    first = prepare(diagram, POINTS, metrics, trust=True)
    assert prepare(diagram, POINTS, metrics, trust=True).diagram_hash == first.diagram_hash
    summary = run_sweep(diagram, POINTS, METRICS, out, serial=True, trust=True, progress=False)
    assert (summary.report.ran, summary.skipped) == (4, 0)
    before = {k: r["y"] for k, r in by_point(out).items() if r["status"] == "ok"}
    (tmp_path / "proj" / "shared" / "plant.yaml").write_text("{A: [[0.9]], B: [[0.2]], C: [[1.0]], D: [[0.0]]}\n")
    second = prepare(diagram, POINTS, metrics, trust=True)
    assert second.diagram_hash != first.diagram_hash
    assert not {h for h, _ in first.points} & {h for h, _ in second.points}
    summary = run_sweep(diagram, POINTS, METRICS, out, serial=True, trust=True, progress=False)
    assert (summary.report.ran, summary.skipped) == (4, 0)  # nothing of the old rows reused
    latest = {h: r for r in rows(out) for h in [r["point_hash"]]}
    after = {(float(latest[h]["ref.value"]), float(latest[h]["fail.at"])): latest[h]["y"]
             for h, _ in second.points if latest[h]["status"] == "ok"}
    assert set(after) == set(before) and all(after[k] != before[k] for k in after)


@pytest.fixture(scope="module")
def plant_fmu(tmp_path_factory) -> Path:
    """The hand plant exported as an FMI 2 FMU (a clean checkout has none in fmu/)."""
    from hierhand.fmu_export import export_plant_fmu

    return export_plant_fmu(tmp_path_factory.mktemp("export") / "HandPlant_fmi2.fmu", fmi=2)


def _copy_fmu_project(root: Path, fmu: Path) -> Path:
    """The shipped FMU diagram in ``root/diagrams`` with the subsystem it includes, its FMU at
    ``../fmu/`` as it expects."""
    (root / "diagrams").mkdir(parents=True)
    (root / "fmu").mkdir()
    shutil.copy(fmu, root / "fmu" / "HandPlant_fmi2.fmu")
    shutil.copy(ROOT / "diagrams" / "regrasp_fmu.yaml", root / "diagrams")
    shutil.copy(ROOT / "diagrams" / "controller.yaml", root / "diagrams")
    return root / "diagrams" / "regrasp_fmu.yaml"


def test_an_fmu_travels_with_the_sweep_by_relative_and_absolute_path(tmp_path, plant_fmu):
    diagram = _copy_fmu_project(tmp_path / "proj", plant_fmu)
    other = tmp_path / "fmus" / "Other.fmu"
    other.parent.mkdir()
    with zipfile.ZipFile(plant_fmu) as src, zipfile.ZipFile(other, "w") as dst:
        for item in src.infolist():  # the same model, other bytes
            dst.writestr(item, src.read(item.filename))
        dst.writestr("documentation/note.txt", "another copy")
    points = [{"plant.path": "../fmu/HandPlant_fmi2.fmu"}, {"plant.path": str(other)}]
    metrics = parse_metrics(["x=final(plant.obj[1])"])  # the FMU numbers its elements from 1
    plan = prepare(diagram, points, metrics, t_end="20 ms", keep_results=True)
    names = {f.ref: f.name for f in plan.job.bundle.files}
    assert names["../fmu/HandPlant_fmi2.fmu"] == "tree/fmu/HandPlant_fmi2.fmu"
    assert names[str(other)].startswith("abs/") and names[str(other)].endswith("/Other.fmu")
    expected = run_point(SweepJob(diagram=str(diagram), metrics=tuple(metrics), t_end="20 ms"), points[0])
    assert expected.status == "ok"
    shutil.rmtree(tmp_path / "proj")
    shutil.rmtree(tmp_path / "fmus")
    out = tmp_path / "sweep"
    report, _, failed = execute(plan, out, serial=True, progress=False)
    assert failed == 0, [r["error"] for r in rows(out)]
    got = {r["point_hash"]: r for r in rows(out)}
    for (h, point) in plan.points:
        assert float(got[h]["x"]) == pytest.approx(expected.values["x"], rel=1e-12)
        shown = Results.load(out / "runs" / h).info["parameters"]["plant"]["path"]
        written = point["plant.path"]
        assert shown == (written if os.path.isabs(written) else str(diagram.parent / written))
    # the FMU's bytes are part of the points' identity
    diagram = _copy_fmu_project(tmp_path / "proj", plant_fmu)
    again = prepare(diagram, points[:1], metrics, t_end="20 ms")
    with zipfile.ZipFile(tmp_path / "proj" / "fmu" / "HandPlant_fmi2.fmu", "a") as fmu:
        fmu.writestr("documentation/note.txt", "changed")
    changed = prepare(diagram, points[:1], metrics, t_end="20 ms")
    assert again.points[0][0] != changed.points[0][0] and again.diagram_hash != changed.diagram_hash


def test_keep_results_from_the_command_line(tmp_path, capsys):
    from hierhand.cli import main

    diagram = make_project(tmp_path / "proj")
    out = tmp_path / "sweep"
    args = ["sweep", str(diagram), "-o", str(out), "--grid", "ref.value=1,2", "--metric", "y=final(plant.y)",
            "--trust", "--serial", "-q", "--keep-results"]
    assert main(args) == 0
    kept = sorted(p.name for p in (out / "runs").iterdir())
    assert kept == sorted(r["point_hash"] for r in rows(out))
    for r in rows(out):
        assert float(r["y"]) == pytest.approx(Results.load(out / "runs" / r["point_hash"])["plant.y"][1][-1, 0],
                                              rel=1e-12)
    stamp = {h: (out / "runs" / h / "run.json").stat().st_mtime_ns for h in kept}
    assert main(args) == 0  # resumed: nothing runs, the folders stay as they were
    assert {h: (out / "runs" / h / "run.json").stat().st_mtime_ns for h in kept} == stamp
    plain = tmp_path / "plain"  # off by default
    assert main(["sweep", str(diagram), "-o", str(plain), "--grid", "ref.value=1", "--metric", "y=final(plant.y)",
                 "--trust", "--serial", "-q"]) == 0
    assert (plain / "sweep.csv").is_file() and not (plain / "runs").exists()


def test_version_mismatch_is_one_line_and_exit_2(tmp_path, capsys, monkeypatch):
    from distributed import Client, LocalCluster

    from hierhand.cli import main

    real = Client.get_versions

    def mismatched(self, check=False, packages=None):
        versions = real(self, check=False, packages=packages)
        for info in versions["workers"].values():
            info["packages"]["numpy"] = "1.0.0"
        versions["scheduler"]["packages"]["dask"] = "2000.1.0"
        return versions

    monkeypatch.setattr(Client, "get_versions", mismatched)
    with LocalCluster(n_workers=1, processes=False, threads_per_worker=1, protocol="tcp", host="127.0.0.1",
                      dashboard_address=None, scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}) as cluster:
        diagram = make_project(tmp_path / "proj")
        code = main(["sweep", str(diagram), "-o", str(tmp_path / "s"), "--grid", "ref.value=1",
                     "--metric", "y=final(plant.y)", "--trust", "-q", "--scheduler", cluster.scheduler_address])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    import dask
    import numpy

    assert f"dask {dask.__version__} here, 2000.1.0 on the scheduler, {dask.__version__} on 1 worker(s)" in err
    assert f"numpy {numpy.__version__} here, 1.0.0 on 1 worker(s)" in err
    assert "hint: install the same versions" in err
    assert not (tmp_path / "s" / "sweep.csv").exists()  # refused before the file is made


def test_a_dask_worker_elsewhere_runs_the_points(tmp_path, dask_elsewhere):
    diagram = make_project(tmp_path / "proj")
    expected = direct(diagram)
    plan = prepare(diagram, POINTS, parse_metrics(METRICS), trust=True)
    shutil.rmtree(tmp_path / "proj")
    out = tmp_path / "sweep"
    report, _, failed = execute(plan, out, scheduler=dask_elsewhere.address, progress=False)
    assert (report.ran, failed) == (4, 2)
    check(out, expected)
    assert not list(dask_elsewhere.home.glob("blocks-*/bundle-*"))  # the workers' copies go with the sweep
