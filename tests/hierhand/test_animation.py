"""``hierhand animate`` and ``animate_run``: a GIF of a real (short) run, and its errors."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import blocks
from hierhand.animation import AnimationError, _frame_indices, animate_run, default_speed, frame_figure

ROOT = Path(__file__).resolve().parents[2]

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


def test_cli_writes_a_gif_of_the_frames_asked_for(run_dir, tmp_path):
    gif = tmp_path / "new" / "folder" / "every.gif"  # the folder is created
    proc = cli(run_dir, "-o", gif, "--every", "50")
    assert proc.returncode == 0, proc.stderr
    assert frames(gif) == 5  # q samples 0, 50, 100, 150, 200 (0 to 20 ms at 0.1 ms)
    assert "5 frames at 25 fps" in proc.stdout


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
    with pytest.raises(AnimationError, match=r"\.gif or \*\.mp4"):
        animate_run(results, tmp_path / "x.png")


def test_frames_follow_q_and_hold_between_its_samples():
    t = np.arange(11) * 0.1  # q at 10 Hz, 0 to 1 s
    assert list(_frame_indices(t, fps=5, speed=1.0, every=None)) == [0, 2, 4, 6, 8, 10]
    assert list(_frame_indices(t, fps=4, speed=1.0, every=None)) == [0, 2, 5, 7, 10]  # 0.25 s -> held 0.2
    assert list(_frame_indices(t, fps=20, speed=1.0, every=None))[:4] == [0, 0, 1, 1]  # slower than q: held
    assert list(_frame_indices(t, fps=25, speed=1.0, every=4)) == [0, 4, 8, 10]  # ends on the last sample


def test_gif_frame_count_follows_speed_and_fps(run_dir, tmp_path):
    results = blocks.Results.load(run_dir)  # 20 ms of q at 0.1 ms
    out = animate_run(results, tmp_path / "a.gif", fps=5, speed=0.01)  # 2 ms a frame: 0, 2, ..., 20 ms
    assert frames(out) == 11
    with Image.open(out) as im:
        assert im.info["duration"] == 200  # ms per frame at 5 fps
    out = animate_run(results, tmp_path / "b.gif", fps=4, speed=0.03)  # 7.5 ms: 0, 7.5, 15 ms and the end
    assert frames(out) == 4


def test_default_speed_makes_about_ten_seconds_and_is_printed(run_dir, tmp_path):
    assert default_speed(1.0) == pytest.approx(0.1)  # a 1 s task: 10 s of GIF, ten times slower
    assert default_speed(1.2) == pytest.approx(0.1)
    assert default_speed(0.02) == pytest.approx(0.002)
    assert default_speed(30.0) == pytest.approx(2.0)
    told = []
    out = animate_run(blocks.Results.load(run_dir), tmp_path / "d.gif", fps=2, report=told.append)
    assert frames(out) == 21  # 20 ms at 0.002 s per second of GIF, 2 fps: a frame per ms
    assert len(told) == 1 and "speed 0.002 (chosen" in told[0] and "21 frames" in told[0]


@pytest.fixture(scope="module")
def regrasp():
    """The first 50 ms of the shipped re-grasp task: thumb and forefinger on the object."""
    results = blocks.simulate(blocks.load_diagram(ROOT / "diagrams" / "regrasp.yaml"), t_end=0.05)
    assert results.complete
    return results


def test_force_arrows_start_at_the_contact_points_along_the_forces(regrasp):
    from matplotlib.colors import to_rgb
    from matplotlib.patches import FancyArrow

    from hierhand.model import load_hand

    fig = frame_figure(regrasp, 0.04, newtons_per_mm=0.5)
    texts = " | ".join(t.get_text() for t in fig.texts)
    assert "1 N = 2 mm" in texts and "t = 0.040 s" in texts
    assert "object on its support (released at 0.1 s)" in texts
    assert "in contact (normal force): thumb" in texts and "forefinger" in texts
    ax = fig.axes[0]
    red = [p for p in ax.patches if isinstance(p, FancyArrow) and np.allclose(p.get_facecolor()[:3], to_rgb("tab:red"))]
    dark = [p for p in ax.patches if isinstance(p, FancyArrow) and np.allclose(p.get_facecolor()[:3], to_rgb("0.15"))]
    fn = regrasp.held("plant.fn", np.array([0.04]))[0]
    ft = regrasp.held("plant.ft", np.array([0.04]))[0]
    n = regrasp.held("plant.normal", np.array([0.04]))[0].reshape(3, 2)
    touching = np.flatnonzero(fn > 0)
    assert list(touching) == [0, 1]  # thumb and forefinger
    assert len(red) == len(touching) + 1  # one per contact and the key arrow
    assert len(dark) == len(touching)  # the normal parts
    hand = load_hand(regrasp.info["parameters"]["plant"])
    tips = hand.tip_positions(regrasp.held("plant.q", np.array([0.04]))[0])
    m_per_n = 1e-3 / 0.5
    for f in touching:
        contact = tips[f] + hand.tip_radius[f] * n[f]
        force = fn[f] * n[f] + ft[f] * np.array([-n[f, 1], n[f, 0]])
        # a FancyArrow's polygon: its head's point is vertex 0, its tail's centre the
        # midpoint of vertices 3 and 4
        matches = [a for a in red if np.allclose((a.get_xy()[3] + a.get_xy()[4]) / 2, contact, atol=1e-9)]
        assert len(matches) == 1
        assert np.allclose(matches[0].get_xy()[0], contact + force * m_per_n, atol=1e-9)
        normal = [a for a in dark if np.allclose(a.get_xy()[0], contact + fn[f] * n[f] * m_per_n, atol=1e-9)]
        assert len(normal) == 1


def test_no_arrows_and_a_hint_without_normal_logged(run_dir):
    results = blocks.Results.load(run_dir)
    bare = blocks.Results({k: results[k] for k in results if k != "plant.normal"}, results.info)
    fig = frame_figure(bare, 0.01)
    texts = " | ".join(t.get_text() for t in fig.texts)
    assert "no force arrows" in texts and "plant.normal" in texts
    assert "no finger in contact" in texts  # fn tells who touches


def test_mp4_without_ffmpeg_is_a_one_line_error(run_dir, tmp_path, monkeypatch, capsys):
    import shutil

    from hierhand import cli

    monkeypatch.setattr(shutil, "which", lambda name, *a, **k: None)
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # import fails
    with pytest.raises(AnimationError, match="ffmpeg"):
        animate_run(run_dir, tmp_path / "a.mp4")
    code = cli.main(["animate", str(run_dir), "-o", str(tmp_path / "a.mp4")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert "needs ffmpeg" in err[0] and "install" in err[0] and "a.gif" in err[0]
    assert not (tmp_path / "a.mp4").exists()


def test_mp4_is_piped_to_the_ffmpeg_found(tmp_path, monkeypatch):
    import shutil

    from hierhand.animation import _writer
    from hierhand.frame_writers import Mp4Writer

    monkeypatch.setattr(shutil, "which", lambda name, *a, **k: "/opt/bin/ffmpeg" if name == "ffmpeg" else None)
    writer = _writer(tmp_path / "a.mp4", 25)
    assert isinstance(writer, Mp4Writer) and writer.ffmpeg == "/opt/bin/ffmpeg" and writer.fps == 25


def rendered(fig) -> tuple[np.ndarray, tuple[slice, slice]]:
    """A figure's pixels, and the rows and columns of its axes (the hand and the arrows)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    pixels = np.asarray(canvas.buffer_rgba())[..., :3].astype(float)
    box = fig.axes[0].get_window_extent()
    height = pixels.shape[0]
    return pixels, (slice(int(height - box.y1) + 2, int(height - box.y0) - 2), slice(int(box.x0) + 2, int(box.x1) - 2))


def test_each_gif_frame_is_the_hand_its_arrows_and_its_time_as_a_whole_figure_draws_them(regrasp, tmp_path):
    """The GIF's frames are drawn by blitting (what frames share drawn once); each frame's
    hand and force arrows must look as the frame's own figure drawn whole (``frame_figure``)
    does, up to the GIF's 256-colour palette, and its header must show its own time."""
    out = animate_run(regrasp, tmp_path / "r.gif", every=20)  # q (every 1 ms) samples 0, 20, 40 and the last, 50
    times = [0.0, 0.02, 0.04, 0.05]
    with Image.open(out) as im:
        assert im.n_frames == len(times)
        decoded = []
        for k in range(im.n_frames):
            im.seek(k)
            decoded.append(np.asarray(im.convert("RGB")).astype(float))
    for k, t in enumerate(times):
        whole, (rows, cols) = rendered(frame_figure(regrasp, t))
        assert decoded[k].shape == whole.shape
        off = np.abs(decoded[k][rows, cols] - whole[rows, cols]).max(axis=2) > 48
        assert off.mean() < 0.001, f"frame {k} (t = {t} s): {off.sum()} pixels of the axes differ from its figure"
    header = slice(0, rows.start - 40)  # the time, phase and contact lines above the axes
    for a, b in zip(decoded, decoded[1:]):
        assert (np.abs(a[header] - b[header]).max(axis=2) > 60).sum() > 20  # each frame its own time
    moved = np.abs(decoded[2][rows, cols] - decoded[0][rows, cols]).max(axis=2) > 60
    assert moved.sum() > 200  # the hand moved and the arrows came


def test_cli_writes_an_mp4_that_decodes_to_its_frames(run_dir, tmp_path):
    """A real MP4 through the ffmpeg of imageio-ffmpeg (a test extra): 5 frames at 10 fps."""
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg")
    mp4 = tmp_path / "hand.mp4"
    proc = cli(run_dir, "-o", mp4, "--every", "50", "--fps", "10")
    assert proc.returncode == 0, proc.stderr
    count, seconds = imageio_ffmpeg.count_frames_and_secs(str(mp4))
    assert count == 5 and seconds == pytest.approx(0.5, abs=0.05)
    first = next(imageio_ffmpeg.read_frames(str(mp4)))["size"]
    assert first[0] > 300 and first[1] > 300  # a whole figure, not a stub frame
