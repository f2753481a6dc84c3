"""``hierhand animate`` and ``animate_run``: a GIF of a real (short) run, and its errors."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

import blocks
from hierhand.animation import AnimationError, _frame_indices, animate_run

DIAGRAM = """\
name: animate-test
time: {t_end: 20 ms}
blocks:
  plant: {type: HandPlant, period: 0.1 ms}
  zero:  {type: Constant, params: {value: [0, 0, 0, 0, 0, 0, 0, 0, 0]}}
  gain:  {type: Gain, period: 1 ms, params: {k: 1.0}}
connections:
  - zero.y -> gain.u
  - gain.y -> plant.tau
log:
  - plant.q
  - plant.obj
  - {signal: plant.fn, decimate: 10}
  - {signal: plant.ft, decimate: 10}
  - {signal: plant.normal, decimate: 10}
  - plant.tip
"""


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    root = tmp_path_factory.mktemp("animate")
    (root / "d.yaml").write_text(DIAGRAM, encoding="utf-8")
    results = blocks.simulate(blocks.load_diagram(root / "d.yaml"))
    assert results.complete
    return results.save(root / "run")


def cli(*args):
    return subprocess.run([sys.executable, "-m", "hierhand", "animate", *map(str, args)],
                          capture_output=True, text=True, timeout=120)


def frames(path) -> int:
    with Image.open(path) as im:
        return im.n_frames


def test_cli_writes_a_gif_with_several_frames(run_dir, tmp_path):
    gif = tmp_path / "new" / "folder" / "hand.gif"  # the folder is created
    proc = cli(run_dir, "-o", gif)
    assert proc.returncode == 0, proc.stderr
    assert gif.is_file()
    assert frames(gif) > 1  # t = 0 and the final state at 20 ms

    every = tmp_path / "every.gif"
    proc = cli(run_dir, "-o", every, "--every", "50")
    assert proc.returncode == 0, proc.stderr
    assert frames(every) == 5  # q samples 0, 50, 100, 150, 200 (0 to 20 ms at 0.1 ms)


def test_cli_without_q_is_bad_input_naming_the_signal(run_dir, tmp_path):
    results = blocks.Results.load(run_dir)
    signals = {k: v for k, v in results.signals.items() if k != "plant.q"}
    blocks.Results(signals, results.info).save(tmp_path / "no_q")
    proc = cli(tmp_path / "no_q", "-o", tmp_path / "x.gif")
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "plant.q" in lines[0] and "log" in lines[0]
    assert not (tmp_path / "x.gif").exists()

    proc = cli(tmp_path / "missing", "-o", tmp_path / "x.gif")
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1


def test_python_api_slow_motion_and_without_force_signals(run_dir, tmp_path):
    results = blocks.Results.load(run_dir)
    out = animate_run(results, tmp_path / "slow.gif", fps=10, speed=0.04)  # 4 ms of run per frame
    assert frames(out) == 6  # 0, 4, ..., 20 ms
    bare = blocks.Results({k: results[k] for k in ("plant.q", "plant.obj")}, results.info)
    assert frames(animate_run(bare, tmp_path / "bare.gif", every=100)) == 3


def test_plant_choice_errors(run_dir, tmp_path):
    results = blocks.Results.load(run_dir)
    info = dict(results.info, block_types={"a": "HandPlant", "b": "HandPlant"})
    with pytest.raises(AnimationError, match="--plant NAME"):
        animate_run(blocks.Results(results.signals, info), tmp_path / "x.gif")
    with pytest.raises(AnimationError, match="no HandPlant"):
        animate_run(blocks.Results(results.signals, dict(results.info, block_types={"g": "Gain"})),
                    tmp_path / "x.gif")
    with pytest.raises(AnimationError, match="is a Gain"):
        animate_run(results, tmp_path / "x.gif", plant="gain")
    with pytest.raises(AnimationError, match=r"\.gif"):
        animate_run(results, tmp_path / "x.png")


def test_frames_follow_q_and_hold_between_its_samples():
    t = np.arange(11) * 0.1  # q at 10 Hz, 0 to 1 s
    assert list(_frame_indices(t, fps=5, speed=1.0, every=None)) == [0, 2, 4, 6, 8, 10]
    assert list(_frame_indices(t, fps=4, speed=1.0, every=None)) == [0, 2, 5, 7, 10]  # 0.25 s -> held 0.2
    assert list(_frame_indices(t, fps=20, speed=1.0, every=None))[:4] == [0, 0, 1, 1]  # slower than q: held
    assert list(_frame_indices(t, fps=25, speed=1.0, every=4)) == [0, 4, 8, 10]  # ends on the last sample
