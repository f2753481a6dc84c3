"""The ``hierhand`` command line on the shipped toy diagram: run, validate, graph, plot, blocks."""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from blocks import Results

REPO = Path(__file__).resolve().parents[3]
TOY = REPO / "diagrams" / "toy.yaml"
TOY_BLOCKS = ("ref", "err", "plant", "integ", "prop", "u")
LIBRARY_TYPES = ("Constant", "Step", "Ramp", "Gain", "Sum", "Saturation", "UnitDelay",
                 "ZeroOrderHold", "DiscreteStateSpace", "DiscreteTransferFunction")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def hierhand(*args: str, cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    """``python -m hierhand ARGS`` in ``cwd``: a process of its own, forked from the session's
    command-line server (``tests.forked_cli``), or with ``env`` a fresh interpreter."""
    if env is None:
        from tests.forked_cli import shared

        return shared().run([str(a) for a in args], cwd, timeout=300)
    return subprocess.run([sys.executable, "-m", "hierhand", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd, env=env, timeout=300)


def assert_png(path: Path) -> None:
    assert path.is_file(), path
    assert path.read_bytes()[:8] == PNG_MAGIC


@pytest.fixture(scope="module")
def toy_run(tmp_path_factory):
    """``hierhand run diagrams/toy.yaml -o DIR --csv --plot``, once for the module."""
    work = tmp_path_factory.mktemp("toy")
    out = work / "out"
    proc = hierhand("run", TOY, "-o", out, "--csv", "--plot", cwd=work)
    assert proc.returncode == 0, proc.stderr
    return out, proc


def test_run_writes_all_files(toy_run):
    out, proc = toy_run
    for name in ("signals.npz", "run.json", "signals.csv"):
        assert (out / name).is_file(), name
    assert_png(out / "plots" / "signals.png")
    assert "Traceback" not in proc.stderr


def test_run_signals_npz(toy_run):
    out, _ = toy_run
    with np.load(out / "signals.npz") as data:
        assert set(data.files) == {"plant.y", "time:plant.y"}
        t, y = data["time:plant.y"], data["plant.y"]
    # plant runs at 0.1 ms from 0 to 1 s inclusive.
    assert t.shape == (10_001,) and y.shape == (10_001, 1)
    assert t[0] == 0.0 and t[-1] == 1.0
    np.testing.assert_array_equal(t, np.arange(10_001) / 10_000)
    assert np.all(np.isfinite(y))


def test_run_json(toy_run):
    out, _ = toy_run
    info = json.loads((out / "run.json").read_text(encoding="utf-8"))
    assert info["status"] == "complete"
    assert info["diagram"] == "toy-multirate"
    assert info["t_end"] == 1.0
    assert info["parameters"]["prop"] == {"k": 5.0}
    assert info["parameters"]["plant"]["A"] == [[0.999]]
    assert set(info["parameters"]) == set(TOY_BLOCKS)
    versions = info["versions"]
    assert "python" in versions and "numpy" in versions
    assert isinstance(info["wall_time_s"], float) and info["wall_time_s"] >= 0
    rtf = info["real_time_factor"]
    assert rtf is None or (isinstance(rtf, float) and rtf > 0)
    assert isinstance(info.get("diagram_hash"), str) and info["diagram_hash"]


def test_run_csv(toy_run):
    out, _ = toy_run
    with open(out / "signals.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["time", "plant.y"]
    assert len(rows) == 1 + 10_001
    assert float(rows[1][0]) == 0.0 and float(rows[-1][0]) == 1.0
    with np.load(out / "signals.npz") as data:
        np.testing.assert_array_equal([float(r[1]) for r in rows[1:]], data["plant.y"][:, 0])


def test_run_results_load_back(toy_run):
    out, _ = toy_run
    r = Results.load(out)
    assert r.complete
    t, y = r["plant.y"]
    assert t[-1] == 1.0
    # The loop drives the plant towards the constant reference 1.0 from below.
    assert 0.0 < y[-1, 0] < 1.0


def test_stop_time_is_an_alias_of_t_end(tmp_path):
    a = hierhand("run", TOY, "-o", tmp_path / "a", "--stop-time", "0.5", "-q", cwd=tmp_path)
    b = hierhand("run", TOY, "-o", tmp_path / "b", "--t-end", "0.5", "-q", cwd=tmp_path)
    assert a.returncode == 0, a.stderr
    assert b.returncode == 0, b.stderr
    ra, rb = Results.load(tmp_path / "a"), Results.load(tmp_path / "b")
    ta, ya = ra["plant.y"]
    tb, yb = rb["plant.y"]
    assert ta[-1] == 0.5
    assert ra.info["t_end"] == 0.5
    np.testing.assert_array_equal(ta, tb)
    np.testing.assert_array_equal(ya, yb)


def test_set_changes_the_result_and_is_recorded(tmp_path, toy_run):
    default_out, _ = toy_run
    out = tmp_path / "k2"
    proc = hierhand("run", TOY, "-o", out, "--set", "prop.k=2", "-q", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    info = json.loads((out / "run.json").read_text(encoding="utf-8"))
    assert info["parameters"]["prop"]["k"] == 2
    default = Results.load(default_out)["plant.y"][1]
    changed = Results.load(out)["plant.y"][1]
    assert changed.shape == default.shape
    assert not np.array_equal(changed, default)


def test_validate_prints_tick_hyperperiod_and_order(tmp_path):
    proc = hierhand("validate", TOY, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert "base tick: 100 us" in out
    assert "hyperperiod" in out and "10 ms" in out
    assert "execution order" in out
    assert "(lazy: a stateless block of inherited rate, computed only when a block that fires reads it" in out
    assert "(advanced between events: stepped over the ticks where nothing else fires in one call)" in out
    for name in TOY_BLOCKS:
        assert name in out
    order = out.split("execution order", 1)[1]
    # plant, integ and prop are the blocks with their own period: all appear in the order.
    for name in ("plant", "integ", "prop"):
        assert name in order


def test_validate_plan_prints_the_op_table_with_names(tmp_path):
    """The plan the C core runs, readably: each program's ops by block and port, the
    events that run it, the copies into delayed inputs and the log entries."""
    proc = hierhand("validate", TOY, "--plan", "--t-end", "20 ms", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    plan = proc.stdout.split("op table: ", 1)[1]
    assert plan.startswith("200 ticks of 1/10000 s, hyperperiod 100 ticks; 6 blocks")
    assert "  2  plant  y@2[1]  in: u<-@5[1]  every 1 ticks, advance rows @6[10 x 1]" in plan
    events = plan.split("  2  at ticks 10, 20, 30, 40, 50, 60, ... (mod 100)", 1)[1].split("\n  3  ", 1)[0]
    assert events.split("\n")[1:] == ["       output err", "       output integ", "       output u",
                                       "       update integ",
                                       "       advance plant to the next event, logging plant.y "
                                       "(the event's last advance)"]
    assert "  3  the end, at tick 200:" in plan
    assert "  0  plant.y: every hit, columns 0..0 of plant, at most 201 rows" in plan


def test_validate_plan_without_an_end_time_says_so(tmp_path):
    text = TOY.read_text(encoding="utf-8").replace("time: {t_end: 1 s}\n", "")
    diagram = tmp_path / "endless.yaml"
    diagram.write_text(text, encoding="utf-8")
    proc = hierhand("validate", diagram, "--plan", cwd=tmp_path)
    assert proc.returncode == 2 and "no end time" in proc.stderr and "Traceback" not in proc.stderr


def test_graph_prints_dot_with_every_block(tmp_path):
    proc = hierhand("graph", TOY, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    dot = proc.stdout
    assert dot.lstrip().startswith("digraph")
    assert dot.rstrip().endswith("}")
    for name in TOY_BLOCKS:
        assert f'"{name}"' in dot
    assert dot.count("->") == 7          # one edge per connection of the toy diagram


@pytest.mark.parametrize("suffix", [".svg", ".png"])
def test_graph_writes_image_files(tmp_path, suffix):
    target = tmp_path / f"x{suffix}"
    proc = hierhand("graph", TOY, "-o", target, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert target.is_file()
    if suffix == ".png":
        assert_png(target)
    else:
        assert "<svg" in target.read_text(encoding="utf-8")


def test_plot_one_signal(tmp_path, toy_run):
    out, _ = toy_run
    target = tmp_path / "f.png"
    proc = hierhand("plot", out, "-s", "plant.y", "-o", target, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert_png(target)


def test_plot_unknown_signal_is_one_line_exit_2(tmp_path, toy_run):
    out, _ = toy_run
    target = tmp_path / "g.png"
    proc = hierhand("plot", out, "-s", "nope.y", "-o", target, cwd=tmp_path)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert "nope.y" in lines[0]
    assert "plant.y" in lines[0]          # says what can be plotted
    assert not target.exists()


def test_plot_of_a_folder_without_results_exits_2(tmp_path):
    proc = hierhand("plot", tmp_path, "-o", tmp_path / "f.png", cwd=tmp_path)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_blocks_lists_the_library(tmp_path):
    proc = hierhand("blocks", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    headings = {line.split()[0] for line in proc.stdout.splitlines() if line and not line[0].isspace()}
    assert set(LIBRARY_TYPES) <= headings


def test_blocks_gain_shows_its_parameter(tmp_path):
    proc = hierhand("blocks", "Gain", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].split()[0] == "Gain"
    assert any(line.strip().startswith("k ") or line.strip().startswith("k:") for line in lines), proc.stdout
    assert "Sum" not in proc.stdout.split()


def test_blocks_unknown_type_exits_2(tmp_path):
    proc = hierhand("blocks", "Nope", cwd=tmp_path)
    assert proc.returncode == 2
    assert "Nope" in proc.stderr and "Traceback" not in proc.stderr


FAILING_MODULE = '''\
"""A pass-through block that fails once t passes t_fail."""
from blocks import Block


class Bomb(Block):
    def __init__(self, t_fail: float = 0.005):
        self.t_fail = float(t_fail)
        self.inputs = {"u": 1}
        self.outputs = {"y": 1}
        self.feedthrough = True

    def output(self, t, state, inputs):
        if t > self.t_fail:
            raise ValueError("value out of range")
        return {"y": inputs["u"].copy()}
'''

FAILING_DIAGRAM = """\
name: failing
time: {t_end: 10 ms}
blocks:
  ramp: {type: Ramp, period: 1 ms, params: {slope: 1.0}}
  bomb: {type: "python:bomb_block_mod:Bomb", params: {t_fail: 0.0045}}
connections:
  - ramp.y -> bomb.u
log: [ramp.y, bomb.y]
"""


def test_simulation_failure_exits_1_and_keeps_partial_results(tmp_path):
    (tmp_path / "bomb_block_mod.py").write_text(FAILING_MODULE, encoding="utf-8")
    diagram = tmp_path / "failing.yaml"
    diagram.write_text(FAILING_DIAGRAM, encoding="utf-8")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(tmp_path), env.get("PYTHONPATH", "")) if p)
    out = tmp_path / "out"
    proc = hierhand("run", diagram, "-o", out, "--trust", cwd=tmp_path, env=env)
    assert proc.returncode == 1, proc.stderr
    assert "Traceback" not in proc.stderr
    assert "bomb" in proc.stderr
    # The first hit after t_fail = 4.5 ms is the ramp's 5 ms hit.
    assert "t=0.005" in proc.stderr
    assert (out / "signals.npz").is_file()
    info = json.loads((out / "run.json").read_text(encoding="utf-8"))
    assert info["status"].startswith("failed at t=")
    assert "bomb" in info["status"]
    r = Results.load(out)
    assert not r.complete
    t, y = r["bomb.y"]
    assert t[-1] < 0.010
    np.testing.assert_allclose(t, [0.0, 0.001, 0.002, 0.003, 0.004])
    np.testing.assert_allclose(y[:, 0], t)
    t_ramp, _ = r["ramp.y"]
    assert t_ramp[-1] < 0.010


LONG_DIAGRAM = """\
name: long
time: {t_end: 100000 s}
blocks:
  ramp: {type: Ramp, period: 0.1 ms, params: {slope: 1.0}}
log: [{signal: ramp.y, decimate: 10000}]
"""

FAILS_AT_ONCE = """\
name: long
time: {t_end: 100000 s}
blocks:
  big: {type: Constant, params: {value: 1.0e308}}
  g: {type: Gain, params: {k: 1.0e308}}
connections: [big.y -> g.u]
log: [g.y]
"""
"""A long run that fails at its first tick (an infinite output: exit 1): a command that
answers it with exit 2 about its output folder checked the folder before running, whatever
the machine's speed (where a long run proved it only by answering within a timeout)."""


@pytest.mark.skipif(not hasattr(signal, "SIGINT") or os.name != "posix", reason="POSIX signals")
def test_ctrl_c_saves_the_run_so_far_and_exits_130(tmp_path):
    diagram = tmp_path / "long.yaml"
    diagram.write_text(LONG_DIAGRAM, encoding="utf-8")
    out = tmp_path / "out"
    hook = Path(__file__).resolve().parent / "signal_hook"  # Ctrl-C at the run's second progress report
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(hook), *filter(None, [os.environ.get("PYTHONPATH")])]),
               SIGNAL_AT="blocks.cli.run:ProgressBar.__call__", SIGNAL_SEND="SIGINT", SIGNAL_CALL="2")
    proc = subprocess.Popen([sys.executable, "-m", "hierhand", "run", str(diagram), "-o", str(out)],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    assert "interrupted at t=" in err and "partial results (marked incomplete) saved" in err
    r = Results.load(out)
    assert r.interrupted and not r.complete
    t, y = r["ramp.y"]
    assert 0 < r.info["t_stop"] < 100000 and t[-1] <= r.info["t_stop"]
    np.testing.assert_allclose(y[:, 0], t)
