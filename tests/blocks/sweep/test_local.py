"""The sweep's default way: points start at once in a forked local process; a LocalCluster
takes over when the work left pays for one. Every point runs exactly once whoever runs it,
the rows equal a serial sweep's, and a point that kills the local process fails alone."""

from __future__ import annotations

import csv
import os
import multiprocessing
from pathlib import Path

import pytest

from blocks.sweep import grid_points, run_sweep
from blocks.sweep import local
from blocks.sweep.local import CLUSTER_START_S, cluster_pays_off
from blocks.sweep.queue import PointQueue, SharedQueue
from blocks.sweep.runner import default_workers
from hierhand.cli import main

from .test_sweep_cli import CRASH_DIAGRAM, CRASH_MODULE

pytestmark = pytest.mark.skipif(not local.can_run_locally(), reason="the local runner forks")

ROOT = Path(__file__).resolve().parents[3]
TOY = ROOT / "diagrams" / "toy.yaml"
METRICS = ["y=final(plant.y)", "t=first_time_above(plant.y, 0.001)"]


@pytest.fixture
def no_cluster(monkeypatch):
    """The local process runs every point: whether a cluster pays off is judged from how
    long the points take, which a busy machine changes, so a test about the local process
    fixes that judgement instead of counting on a quick machine."""
    monkeypatch.setattr(local, "cluster_pays_off", lambda *_: False)


def rows(out: Path) -> dict[str, dict]:
    with open(out / "sweep.csv", newline="") as f:
        return {r["point_hash"]: {k: v for k, v in r.items() if k != "wall_s"} for r in csv.DictReader(f)}


def test_a_cluster_pays_off_only_for_work_beyond_its_start_and_only_with_more_than_one_worker():
    assert not cluster_pays_off(0.009, 16, 2)  # 0.14 s of runs: less than the start alone
    assert cluster_pays_off(0.009, 256, 2)
    assert not cluster_pays_off(100.0, 1000, 1)  # one worker is no faster than the local process
    # the break-even point falls as workers are added, and more work never undoes a decision
    even = {w: next(n for n in range(1, 10_000) if cluster_pays_off(0.01, n, w)) for w in (2, 4, 16)}
    assert even[2] > even[4] > even[16] > CLUSTER_START_S / 0.01
    assert all(cluster_pays_off(0.01, n, 2) for n in range(even[2], even[2] + 500))


def test_the_shared_queue_hands_out_every_point_once_across_processes():
    items = [(str(i), {"i": i}) for i in range(2000)]
    queue = SharedQueue(items, multiprocessing.get_context("fork"))
    got = multiprocessing.get_context("fork").Queue()

    def take():
        while chunk := queue.take_indices(3):
            got.put(list(chunk))

    takers = [multiprocessing.get_context("fork").Process(target=take) for _ in range(2)]
    for p in takers:
        p.start()
    mine = []
    while part := queue.take(5):
        mine += [int(h) for h, _ in part]
    for p in takers:
        p.join()
    while not got.empty():
        mine += got.get()
    assert sorted(mine) == list(range(2000)) and len(queue) == 0
    plain = PointQueue(items[:7])
    assert [len(plain.take(3)) for _ in range(4)] == [3, 3, 1, 0] and len(plain) == 0


def test_a_small_sweep_runs_in_the_local_process_with_the_rows_of_a_serial_sweep(tmp_path, no_cluster):
    points = grid_points({"prop.k": [1, 2, 3, 4, 5]})
    default = run_sweep(TOY, points, METRICS, tmp_path / "default", t_end="50 ms", progress=False)
    assert (default.report.ran, default.report.local, default.report.workers) == (5, 5, 0)
    run_sweep(TOY, points, METRICS, tmp_path / "serial", t_end="50 ms", progress=False, serial=True)
    assert rows(tmp_path / "default") == rows(tmp_path / "serial")


def test_asking_for_spawned_processes_keeps_the_sweep_from_forking_a_local_one(tmp_path):
    assert local.can_run_locally() and local.can_run_locally("fork") and not local.can_run_locally("spawn")
    summary = run_sweep(TOY, grid_points({"prop.k": [1, 2]}), METRICS, tmp_path / "s", t_end="50 ms",
                        progress=False, start_method="spawn")
    assert summary.report.local == 0 and summary.report.workers >= 1 and summary.failed == 0


NAP_MODULE = '''
import os
import time

from blocks import Block

_runs = 0


def _on_a_worker() -> bool:
    try:
        from distributed import get_worker

        get_worker()
        return True
    except (ImportError, ValueError):
        return False


class Nap(Block):
    """y = u; each run sleeps ``nap`` seconds at its first output: runs of a known length
    that leave the cores free. With a ``mark`` file, a run on a Dask worker makes it, and a
    process's third and later runs elsewhere wait for it (a minute at most): the local
    process cannot run every point before the cluster runs one, however loaded the machine."""

    def __init__(self, nap: float = 0.0, mark: str = ""):
        self.nap = float(nap)
        self.mark = mark
        self.inputs = {"u": 1}
        self.outputs = {"y": 1}
        self.feedthrough = True

    def initial_state(self):
        return [True]

    def output(self, t, state, inputs):
        global _runs
        if state[0]:
            _runs += 1
            time.sleep(self.nap)
            if self.mark and _on_a_worker():
                open(self.mark, "w").close()
            elif self.mark and _runs >= 3:
                deadline = time.monotonic() + 60
                while not os.path.exists(self.mark) and time.monotonic() < deadline:
                    time.sleep(0.005)
            state[0] = False
        return {"y": inputs["u"].copy()}
'''

NAP_DIAGRAM = """\
name: nap
time: {t_end: 3 ms}
blocks:
  src: {type: Constant, params: {value: 1.0}}
  nap: {type: "python:nap_block:Nap", period: 1 ms, params: {nap: 0.04, mark: MARK}}
connections:
  - src.y -> nap.u
log: [nap.y]
"""


@pytest.mark.skipif(default_workers() < 2, reason="with one core a cluster never pays off")
def test_the_cluster_takes_over_from_the_local_process_and_no_point_runs_twice(tmp_path):
    (tmp_path / "nap_block.py").write_text(NAP_MODULE, encoding="utf-8")
    (tmp_path / "nap.yaml").write_text(NAP_DIAGRAM.replace("MARK", f"'{tmp_path / 'worker-ran'}'"), encoding="utf-8")
    points = grid_points({"src.value": list(range(40))})  # 1.6 s of runs: worth a cluster
    default = run_sweep(tmp_path / "nap.yaml", points, ["y=final(nap.y)"], tmp_path / "default", progress=False,
                        trust=True)
    report = default.report
    assert report.workers == default_workers() and 1 <= report.local < 40 and (report.ran, report.failed) == (40, 0), report
    got = rows(tmp_path / "default")
    assert len(got) == 40 and len(open(tmp_path / "default" / "sweep.csv").read().splitlines()) == 41
    assert sorted(float(r["y"]) for r in got.values()) == list(range(40))
    run_sweep(tmp_path / "nap.yaml", points, ["y=final(nap.y)"], tmp_path / "serial", progress=False,
              trust=True, serial=True)
    assert got == rows(tmp_path / "serial")


def test_a_point_that_kills_the_local_process_fails_alone_and_the_rest_run(tmp_path, monkeypatch, capsys,
                                                                          no_cluster):
    (tmp_path / "crash_block_mod.py").write_text(CRASH_MODULE, encoding="utf-8")
    (tmp_path / "crash.yaml").write_text(CRASH_DIAGRAM, encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    out = tmp_path / "sweep"
    values = ",".join(str(v) for v in range(1, 17))
    code = main(["sweep", str(tmp_path / "crash.yaml"), "-o", str(out), "--grid", f"src.value={values}",
                 "--metric", "y=final(crash.y)", "--trust"])
    captured = capsys.readouterr()
    assert code == 1
    assert captured.err.strip().splitlines() == [f"hierhand: 1 point(s) failed; see the status and error columns "
                                                 f"of {out / 'sweep.csv'}"]
    assert "16 run in a local process (too little work for a cluster to pay off) (1 failed)" in captured.out
    got = {float(r["src.value"]): r for r in rows(out).values()}
    assert sorted(got) == [float(v) for v in range(1, 17)]
    assert got[12.0]["status"] == "failed"
    assert got[12.0]["error"] == "the process running this point died (exit code 3)"
    assert all(r["status"] == "ok" and float(r["y"]) == v for v, r in got.items() if v != 12.0)


def test_a_local_process_that_dies_before_its_first_point_stops_the_sweep_with_a_hint(tmp_path, monkeypatch):
    from blocks.sweep import SweepError

    monkeypatch.setattr(local, "_serve", lambda *_: os._exit(5))
    with pytest.raises(SweepError, match=r"ended before its first point \(exit code 5\) \(hint: --workers N"):
        run_sweep(TOY, grid_points({"prop.k": [1, 2]}), METRICS, tmp_path / "s", t_end="50 ms", progress=False)


def test_kept_results_of_local_runs_have_their_folders_and_match_their_rows(tmp_path, no_cluster):
    from blocks import Results

    points = grid_points({"prop.k": [1, 2, 3, 4]})
    summary = run_sweep(TOY, points, METRICS, tmp_path / "s", t_end="50 ms", progress=False, keep_results=True)
    assert summary.report.local == 4
    for h, row in rows(tmp_path / "s").items():
        kept = Results.load(tmp_path / "s" / "runs" / h)
        assert kept.info["sweep"]["point_hash"] == h and kept.info["sweep"]["status"] == row["status"] == "ok"
        assert float(row["y"]) == float(kept["plant.y"][1][-1, 0])
