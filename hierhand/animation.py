"""Animation of a run (GIF, or MP4 with ffmpeg): the hand, the object and the contact forces.

``animate_run(results, "hand.gif")`` draws the ``HandPlant`` of a results folder (see
``blocks.Results``) frame by frame with ``hierhand.model.draw.draw_hand`` and writes each
frame as it is drawn (``hierhand.frame_writers``: a GIF, or an MP4 through ffmpeg, when an
ffmpeg executable is on the PATH or ``imageio_ffmpeg`` is installed), keeping none. It needs the plant's ``q``
and ``obj`` logged; with ``fn`` and ``normal`` (and ``ft``) logged too it draws the force
each fingertip applies to the object, ``fn * n + ft * t`` with ``t`` the normal ``n``
turned +90 degrees, at the contact point (tip centre + tip radius * n), and its normal
part ``fn * n`` as a thin dark arrow beside it.

Frames are samples of ``<plant>.q``: one every ``speed / fps`` seconds of simulated time
(or every ``every``-th sample), plus the last one. ``speed`` defaults to a round number
making the animation last about ``TARGET_SECONDS`` (a 1 s run: 0.1, ten times slower than
real time). Every other signal keeps its own sample times and is taken at a frame's time
by zero-order hold.

Each frame shows the simulated time, the task's phase (``task_phases``: read from the
diagram's blocks, its ``ObjectSupport`` hand-over, ``Step`` times and the
``ManipulationPD`` fingertip trajectories) and the fingers in contact with their normal
forces.
"""

from __future__ import annotations

import importlib
import math
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from blocks.process.progress import progress_bar
from blocks.results.signals import held_index

from .tasks.phases import FINGER_WORDS, Phase, phase_at, task_phases

__all__ = ["AnimationError", "Phase", "animate_run", "default_speed", "ffmpeg_executable", "frame_figure",
           "phase_at", "task_phases"]

MAX_FRAMES = 1000
TARGET_SECONDS = 10.0
"""The default speed makes an animation about this long (a round speed: 8 to 16 s or so)."""
ARROW_SIGNALS = ("fn", "ft", "normal")
HOLD_RTOL = 1e-9
"""Frame times are sums of float steps: a sample this close (relative) after one is at it."""
FORMATS = (".gif", ".mp4")
class AnimationError(ValueError):
    """A run that cannot be animated (no hand plant, a signal not logged, bad options)."""


# -- the command ----------------------------------------------------------------------


def animate_run(results: Any, path: str | Path, fps: float = 25, speed: float | None = None,
                plant: str | None = None, every: int | None = None,
                newtons_per_mm: float | None = None, max_frames: int = MAX_FRAMES,
                dpi: int = 100, report: Callable[[str], None] | None = None, progress: bool = False) -> Path:
    """Write an animated GIF (or MP4) of the hand plant in ``results`` to ``path``; return the path.

    ``results``: a ``blocks.Results`` or its folder. ``path``: ``*.gif`` or ``*.mp4`` (MP4
    needs ffmpeg). ``fps``: frames per second. ``speed``: simulated seconds per second of
    animation (0.1 = ten times slower than real time); None: ``default_speed`` of the
    run's length, about ``TARGET_SECONDS`` of animation. ``every``: instead, a frame at
    every ``every``-th sample of ``<plant>.q``. ``plant``: the ``HandPlant`` block's name
    (needed only if the run has several). ``newtons_per_mm``: arrow scale (default: a
    round number drawing the largest force at most a fifth of the view long). ``report``: told the speed
    chosen and the frame count. ``progress``: a bar of the frames written, on a terminal. Raises ``AnimationError`` with a one-line message for
    runs that cannot be animated.
    """
    path = Path(path)
    _check_format(path)
    if not (isinstance(fps, (int, float)) and math.isfinite(fps) and fps > 0):
        raise AnimationError(f"fps must be a positive number, got {fps!r}")
    if speed is not None and not (isinstance(speed, (int, float)) and math.isfinite(speed) and speed > 0):
        raise AnimationError(f"speed must be a positive number, got {speed!r}")
    if every is not None and (isinstance(every, bool) or not isinstance(every, int) or every < 1):
        raise AnimationError(f"every must be a positive integer, got {every!r}")
    writer = _writer(path, fps)  # before the drawing: no ffmpeg is found out at once

    scene = _Scene.build(results, plant, fps=fps, speed=speed, every=every, newtons_per_mm=newtons_per_mm,
                         max_frames=max_frames)
    if report is not None:
        report(scene.timing_line(fps))
    path.parent.mkdir(parents=True, exist_ok=True)
    with progress_bar(len(scene.times), "animate", unit="frame", enabled=progress) as bar:
        scene.save(path, writer, dpi, done=lambda: bar.update(1))
    return path


def frame_figure(results: Any, t: float, plant: str | None = None, newtons_per_mm: float | None = None,
                 dpi: int = 100):
    """The matplotlib ``Figure`` of the animation's frame at simulated time ``t`` (the
    plant's state held at ``t``), for looking at one frame or testing what is drawn:
    ``fig.axes[0]`` holds the hand, ``fig.texts`` the time, phase, contacts and scale."""
    scene = _Scene.build(results, plant, at=float(t), newtons_per_mm=newtons_per_mm)
    fig, draw = scene.figure(dpi)
    draw(0)
    return fig


def default_speed(span: float, target_s: float = TARGET_SECONDS) -> float:
    """A round speed (1, 2 or 5 times a power of ten, nearest on a log scale) showing
    ``span`` simulated seconds in about ``target_s`` seconds: 1 s -> 0.1, 1.2 s -> 0.1,
    30 s -> 2."""
    if not (span > 0 and math.isfinite(span)):
        return 1.0
    raw = span / target_s
    power = 10.0 ** math.floor(math.log10(raw))
    candidates = [m * power for m in (1.0, 2.0, 5.0, 10.0)]
    return min(candidates, key=lambda c: abs(math.log(c / raw)))


def ffmpeg_executable() -> str | None:
    """The ffmpeg matplotlib can write MP4 with: ``ffmpeg`` on the PATH, else the one
    ``imageio_ffmpeg`` carries; None without either."""
    found = shutil.which("ffmpeg")
    if found:
        return found
    try:
        imageio_ffmpeg = importlib.import_module("imageio_ffmpeg")
        return imageio_ffmpeg.get_ffmpeg_exe()
    except Exception:  # not installed, or its binary missing
        return None


def _check_format(path: Path) -> None:
    if path.suffix.lower() not in FORMATS:
        raise AnimationError(f"{path}: the animation is written as a GIF or an MP4; name the file *.gif or *.mp4")


def _writer(path: Path, fps: float):
    """The writer of ``path``'s format, which takes the frames one at a time."""
    from .frame_writers import GifWriter, Mp4Writer

    if path.suffix.lower() == ".gif":
        return GifWriter(path, fps)
    exe = ffmpeg_executable()
    if exe is None:
        raise AnimationError(f"{path}: writing MP4 needs ffmpeg, which was not found (install it, e.g. "
                             f"'apt install ffmpeg' or 'pip install imageio-ffmpeg'), or write a GIF: "
                             f"-o {path.with_suffix('.gif')}")
    return Mp4Writer(path, fps, exe)


# -- data ---------------------------------------------------------------------------


@dataclass
class _Scene:
    """What the frames show: per frame the time, q, object pose, forces, phase and contacts."""

    results: Any
    plant: str
    hand: Any
    times: np.ndarray
    q: np.ndarray
    obj: np.ndarray
    forces: np.ndarray | None  # (frames, 3, 6): x, y, fx, fy, fn_x, fn_y
    fn: np.ndarray | None  # (frames, 3) normal forces, NaN unknown
    contact: np.ndarray | None  # (frames, 3) bool
    phases: list[Phase]
    newtons_per_mm: float
    speed: float | None
    speed_chosen: bool
    view: tuple  # (xlim, ylim): the fingers, object and arrows of the whole run

    @classmethod
    def build(cls, results, plant, fps: float = 25, speed: float | None = None, every: int | None = None,
              newtons_per_mm: float | None = None, max_frames: int = MAX_FRAMES, at: float | None = None):
        from blocks import Results

        if not isinstance(results, Results):
            results = Results.load(results)
        name, hand = _find_plant(results, plant)
        t_q, q_all = _signal(results, name, "q", required=True)
        if not len(t_q):
            raise AnimationError(f"signal '{name}.q' has no samples; the run stopped before its first output")
        chosen = False
        if at is not None:
            frames = np.clip(held_index(t_q, [at], HOLD_RTOL), 0, len(t_q) - 1)
        else:
            if speed is None and every is None:
                speed, chosen = default_speed(float(t_q[-1] - t_q[0])), True
            frames = _frame_indices(t_q, fps, speed or 1.0, every, max_frames)
        times = t_q[frames]
        q = q_all[frames]
        obj = _held(results, f"{name}.obj", times, required=True)

        forces = _forces(results, name, hand, q, times)
        # the view and the arrow scale from the whole run (every ~400th sample), so that a
        # single frame is drawn as in the animation
        every_k = max(1, len(t_q) // 400)
        q_some = np.concatenate([q_all[::every_k], q])
        obj_some = np.concatenate([_held(results, f"{name}.obj", t_q[::every_k]), obj])
        some_forces = _forces(results, name, hand, q_all[::every_k], t_q[::every_k])
        if newtons_per_mm is None:
            # the largest force a fifth of the view's size
            (x0, x1), (y0, y1) = _limits(hand, q_some, obj_some, None, 0.0)
            longest_mm = 1e3 * 0.2 * max(x1 - x0, y1 - y0)
            newtons_per_mm = _nice_scale(some_forces, longest_mm)
        elif not (newtons_per_mm > 0 and math.isfinite(newtons_per_mm)):
            raise AnimationError(f"newtons_per_mm must be a positive number, got {newtons_per_mm!r}")
        if some_forces is not None and forces is not None:
            some_forces = np.concatenate([some_forces, forces])
        view = _limits(hand, q_some, obj_some, some_forces, 1e-3 / newtons_per_mm)
        fn = results.held(f"{name}.fn", times, HOLD_RTOL) if f"{name}.fn" in results else None
        if f"{name}.contact" in results:
            contact = results.held(f"{name}.contact", times, HOLD_RTOL) > 0.5
        else:
            contact = None if fn is None else fn > 0

        def object_pose(t: float) -> np.ndarray:
            pose = results.held(f"{name}.obj", np.array([t]), HOLD_RTOL)[0]
            return pose if np.isfinite(pose).all() else hand.object_pose0

        phases = task_phases(results.info, hand, object_pose)
        return cls(results, name, hand, times, q, obj, forces, fn, contact, phases, float(newtons_per_mm),
                   speed, chosen, view)

    def timing_line(self, fps: float) -> str:
        n = len(self.times)
        length = n / fps
        span = float(self.times[-1] - self.times[0])
        if self.speed is None:
            how = "a frame per --every samples"
        else:
            how = (f"speed {self.speed:g} (chosen for a {span:g} s run; --speed to change)" if self.speed_chosen
                   else f"speed {self.speed:g}")
            how += f": {1 / self.speed:g}x slower than real time" if self.speed < 1 else (
                "" if self.speed == 1 else f": {self.speed:g}x faster than real time")
        return f"{n} frames at {fps:g} fps, {length:.1f} s; {how}"

    # -- drawing ----------------------------------------------------------------------

    def figure(self, dpi: int = 100):
        """A new Figure and ``draw(k)`` drawing frame ``k`` on it."""
        from matplotlib.figure import Figure  # no pyplot: leaves the caller's backend alone
        from matplotlib.lines import Line2D
        from matplotlib.patches import FancyArrow

        from hierhand.model.draw import FINGER_COLOURS, draw_hand

        hand, results, plant = self.hand, self.results, self.plant
        force_scale = 1e-3 / self.newtons_per_mm  # metres of arrow per newton
        xlim, ylim = self.view
        ratio = (ylim[1] - ylim[0]) / (xlim[1] - xlim[0])
        # inches: the axes keep the data's aspect; a header for time, phase and contacts
        # above, the x label, the finger legend and the arrow scale below
        width, left, right, top, bottom = 6.4, 0.75, 0.2, 1.0, 0.95
        axes_h = float(np.clip((width - left - right) * ratio, 2.5, 7.0))
        height = axes_h + top + bottom
        fig = Figure(figsize=(width, height), dpi=dpi)
        fig.subplots_adjust(left=left / width, right=1 - right / width, top=1 - top / height, bottom=bottom / height)
        ax = fig.add_subplot()
        ax.set_xlim(*xlim)
        ax.set_ylim(*ylim)
        ax.set_aspect("equal")
        ax.set_autoscale_on(False)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.grid(True, alpha=0.25)

        def down(inches: float) -> float:  # figure fraction of a height from the top
            return 1 - inches / height

        def up(inches: float) -> float:  # from the bottom
            return inches / height

        heading = str(results.info.get("diagram") or plant)
        if not results.complete:
            heading += " (incomplete run)"
        digits = max(2, min(6, math.ceil(-math.log10(_min_step(self.times)) - 1e-9)))

        fig.text(0.02, down(0.08), heading, ha="left", va="top", fontsize=10, color="0.35")
        time_text = fig.text(0.98, down(0.06), "", ha="right", va="top", fontsize=15, fontweight="bold",
                             family="monospace")
        phase_text = fig.text(0.02, down(0.40), "", ha="left", va="top", fontsize=11, fontweight="bold",
                              color="tab:purple")
        contact_text = fig.text(0.02, down(0.68), "", ha="left", va="top", fontsize=9, color="0.15")

        if self.forces is not None:
            mm_per_n = 1.0 / self.newtons_per_mm
            note = (f"arrows: force of each fingertip on the object (red) and its normal part (dark); "
                    f"1 N = {mm_per_n:.3g} mm")
            # a key arrow: a round force in the lower left corner
            key_n = _key_force(self.newtons_per_mm)
            kx = xlim[0] + 0.04 * (xlim[1] - xlim[0])
            ky = ylim[0] + 0.05 * (ylim[1] - ylim[0])
            ax.add_patch(FancyArrow(kx, ky, key_n * force_scale, 0.0, width=0.0006, head_width=0.003,
                                    head_length=0.003, length_includes_head=True, color="tab:red", zorder=4))
            ax.text(kx + key_n * force_scale / 2, ky + 0.003, f"{key_n:g} N", ha="center", va="bottom",
                    fontsize=8, color="tab:red")
        else:
            note = f"no force arrows: log {plant}.fn, {plant}.ft and {plant}.normal to draw them"
        fig.text(0.5, up(0.06), note, ha="center", va="bottom", fontsize=8,
                 color="tab:red" if self.forces is not None else "0.4")
        fig.legend(handles=[Line2D([], [], color=FINGER_COLOURS[f % len(FINGER_COLOURS)], linewidth=2.5,
                                   label=FINGER_WORDS.get(n, n)) for f, n in enumerate(hand.names)],
                   loc="lower center", bbox_to_anchor=(0.5, up(0.22)), ncol=3, fontsize=8, frameon=False)
        drawn: list = []

        def draw(k: int):
            for artist in drawn:
                artist.remove()
            drawn.clear()
            forces = normals = None
            if self.forces is not None:
                forces, normals = self.forces[k, :, :4], self.forces[k, :, 4:]
            artists = draw_hand(ax, hand, self.q[k], self.obj[k], forces, force_scale, normal_forces=normals)
            for group in artists.values():
                drawn.extend(group)
            ax.set_xlim(*xlim)
            ax.set_ylim(*ylim)
            t = float(self.times[k])
            time_text.set_text(f"t = {t:.{digits}f} s")
            phase_text.set_text(self.phase_line(k))
            contact_text.set_text(self.contact_line(k))
            return drawn + [time_text, phase_text, contact_text]

        return fig, draw

    def phase_line(self, k: int) -> str:
        if not self.phases:
            return ""
        names = list(self.hand.names)
        touching = None
        if self.contact is not None:
            touching = lambda f: f in names and bool(self.contact[k, names.index(f)])  # noqa: E731
        return phase_at(self.phases, float(self.times[k]), touching)

    def contact_line(self, k: int) -> str:
        if self.contact is None:
            return ""
        names = [FINGER_WORDS.get(n, n) for n in self.hand.names]
        touching = [f for f in range(len(names)) if self.contact[k, f]]
        if not touching:
            return "no finger in contact"
        parts = []
        for f in touching:
            if self.fn is not None and np.isfinite(self.fn[k, f]):
                parts.append(f"{names[f]} {self.fn[k, f]:.2f} N")
            else:
                parts.append(names[f])
        return "in contact (normal force): " + ", ".join(parts)

    def frames(self, dpi: int = 100):
        """Each frame's pixels, (height, width, 4) uint8 RGBA, one at a time (the canvas's
        own buffer: valid until the next frame is drawn). What every frame
        shares (axes, grid, legend, key arrow, notes) is drawn once; each frame restores
        those pixels and draws only its own artists on them (blitting)."""
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        fig, draw = self.figure(dpi)
        canvas = FigureCanvasAgg(fig)
        canvas.draw()
        background = canvas.copy_from_bbox(fig.bbox)
        for k in range(len(self.times)):
            canvas.restore_region(background)
            for artist in sorted(draw(k), key=lambda a: a.get_zorder()):  # as a whole draw orders them
                fig.draw_artist(artist)
            yield np.asarray(canvas.buffer_rgba())

    def save(self, path: Path, writer, dpi: int, done: Callable[[], None] = lambda: None) -> None:
        """Draw the frames into ``writer`` (``hierhand.frame_writers``), which keeps none;
        ``done`` is called after each frame."""
        try:
            for rgba in self.frames(dpi):
                writer.add(rgba)
                done()
        finally:
            try:
                writer.close()
            except RuntimeError as exc:
                raise AnimationError(str(exc)) from None


def _find_plant(results, plant: str | None):
    """(name, Hand) of the plant to draw."""
    types = results.info.get("block_types")
    if not isinstance(types, dict):  # Results built in Python: go by the logged signals
        found = sorted({s.rsplit(".", 1)[0] for s in results if s.endswith(".q")
                        and s.rsplit(".", 1)[0] + ".obj" in results})
        if plant is not None:
            return plant, _load_hand(results, plant)
        if len(found) == 1:
            return found[0], _load_hand(results, found[0])
        raise AnimationError("the results record no block types (run.json); name the plant with --plant NAME")
    plants = sorted(n for n, t in types.items() if t == "HandPlant")
    fmus = sorted(n for n, t in types.items() if t == "FMU" and f"{n}.q" in results and f"{n}.obj" in results)
    if plant is not None:
        if plant not in types:
            raise AnimationError(f"--plant {plant}: no block named '{plant}' in this run; "
                                 f"HandPlant blocks: {', '.join(plants) or 'none'}")
        if types[plant] == "FMU":
            return plant, _fmu_hand(results, plant)
        if types[plant] != "HandPlant":
            raise AnimationError(f"--plant {plant}: block '{plant}' is a {types[plant]}, not a HandPlant")
        return plant, _load_hand(results, plant)
    if not plants and len(fmus) == 1:  # a plant exported by 'hierhand fmu export'
        return fmus[0], _fmu_hand(results, fmus[0])
    if not plants:
        raise AnimationError("no HandPlant block in this run (blocks: "
                             f"{', '.join(f'{n} ({t})' for n, t in types.items()) or 'none'}); "
                             "animate needs a run of a diagram with a hand plant")
    if len(plants) > 1:
        raise AnimationError(f"several HandPlant blocks in this run ({', '.join(plants)}); "
                             "choose one with --plant NAME")
    return plants[0], _load_hand(results, plants[0])


def _load_hand(results, name: str):
    from hierhand.model import HandFileError, load_hand

    params = (results.info.get("parameters") or {}).get(name) or {}
    try:
        return load_hand(params)
    except HandFileError as exc:
        raise AnimationError(f"the parameters of '{name}' in run.json are not a valid hand: "
                             + "; ".join(exc.errors)) from None


def _fmu_hand(results, name: str):
    """The hand of an exported plant FMU: read from the FMU file the run names (its path as
    given, or from the diagram's folder)."""
    from blocks.fmu import FMU

    from hierhand.model.hand_source import fmu_hand

    given = ((results.info.get("parameters") or {}).get(name) or {}).get("path")
    if not given:
        raise AnimationError(f"FMU block '{name}': run.json names no FMU path, so its hand is unknown")
    tried = [Path(given)]
    diagram_file = results.info.get("diagram_file")
    if diagram_file:
        tried.append(Path(diagram_file).parent / given)
    for candidate in tried:
        if candidate.is_file():
            try:
                return fmu_hand(FMU(path=str(candidate)))
            except Exception as exc:  # not a hand FMU, unreadable
                raise AnimationError(f"FMU block '{name}' ({candidate}): cannot read its hand: {exc}") from None
    raise AnimationError(f"FMU block '{name}': its file {given} is not found (from {Path.cwd()}); "
                         "run animate from the folder the run was made in")


def _signal(results, plant: str, port: str, required: bool = False):
    name = f"{plant}.{port}"
    if name not in results:
        if not required:
            return None
        raise AnimationError(f"signal '{name}' was not logged; animate needs {plant}.q and {plant}.obj: "
                             f"add them to the diagram's log, e.g. log: [{plant}.q, {plant}.obj, "
                             f"{plant}.fn, {plant}.ft, {plant}.normal, {plant}.tip]")
    t, v = results[name]
    return np.asarray(t, dtype=float), np.asarray(v, dtype=float).reshape(len(t), -1)


def _frame_indices(t_q: np.ndarray, fps: float, speed: float, every: int | None,
                   max_frames: int = MAX_FRAMES) -> np.ndarray:
    """Indices into q's samples: one per 1/fps of animation time (held where q is slower), plus the last."""
    n = len(t_q)
    step = speed / fps
    span = float(t_q[-1] - t_q[0])
    count = (n - 1) // every + 1 if every is not None else math.floor(span / step + 1e-9) + 1
    if count > max_frames:
        raise AnimationError(f"{count} frames is too many (at most {max_frames}); "
                             "raise --speed, lower --fps or pass a larger --every")
    if every is not None:
        idx = np.arange(0, n, every)
    else:
        targets = t_q[0] + step * np.arange(count)
        idx = np.clip(held_index(t_q, targets, HOLD_RTOL), 0, n - 1)
    if idx[-1] != n - 1:
        idx = np.append(idx, n - 1)  # always end on the final state
    return idx


def _held(results, name: str, times: np.ndarray, required: bool = False) -> np.ndarray:
    """The signal's values held at the frame times (it is sampled with q, so it has a
    sample at or before every frame)."""
    plant, port = name.rsplit(".", 1)
    t, _ = _signal(results, plant, port, required=required)
    if not len(t):
        raise AnimationError(f"signal '{name}' has no samples")
    return results.held(name, times, HOLD_RTOL)


def _forces(results, plant: str, hand, q: np.ndarray, times: np.ndarray) -> np.ndarray | None:
    """(frames, 3, 6): per finger where its force on the object acts, the force, and its
    normal part; None without ``fn`` and ``normal`` logged. Fingers with no sample yet get
    NaN (no arrow)."""
    logged = {port for port in ARROW_SIGNALS if f"{plant}.{port}" in results}
    if not {"fn", "normal"} <= logged:
        return None

    def held(port: str, width: int) -> np.ndarray:
        if port not in logged:
            return np.zeros((len(times), width))
        return results.held(f"{plant}.{port}", times, HOLD_RTOL)

    fn = held("fn", 3)
    ft = held("ft", 3)
    n = held("normal", 6).reshape(-1, 3, 2)
    tangent = np.stack([-n[..., 1], n[..., 0]], axis=-1)
    normal = fn[..., None] * n
    force = normal + ft[..., None] * tangent
    # the tip drawn is the one of the drawn q, so the arrows start on the drawn circles
    tips = np.array([hand.tip_positions(qk) for qk in q])
    at = tips + hand.tip_radius[None, :, None] * n
    return np.concatenate([at, force, normal], axis=-1)


def _nice_scale(forces: np.ndarray | None, longest_mm: float = 25.0) -> float:
    """A round N-per-mm (1, 2 or 5 times a power of ten) drawing the largest force at most
    ``longest_mm`` long (and more than 0.4 times that)."""
    if forces is None:
        return 0.1
    mags = np.hypot(forces[..., 2], forces[..., 3])
    biggest = float(np.nanmax(mags, initial=0.0)) if mags.size else 0.0
    if not biggest > 0:
        return 0.1
    raw = biggest / longest_mm
    power = 10.0 ** math.floor(math.log10(raw))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * power >= raw * 0.999:
            return m * power
    return 10.0 * power


def _key_force(newtons_per_mm: float) -> float:
    """A round force for the key arrow: about 10 mm long, at most the largest force drawn."""
    raw = 10.0 * newtons_per_mm
    power = 10.0 ** math.floor(math.log10(raw))
    return min((m * power for m in (1.0, 2.0, 5.0)), key=lambda c: abs(math.log(c / raw)))


def _limits(hand, q: np.ndarray, obj: np.ndarray, forces, force_scale: float):
    """Fixed axis limits covering the fingers, tips, object and arrows of every frame."""
    pts = [hand.joint_positions(qk).reshape(-1, 2) for qk in q]
    pts += [hand.object_corners(pose) for pose in obj]
    xy = np.concatenate(pts)
    r = float(hand.tip_radius.max())
    lo, hi = xy.min(axis=0) - r, xy.max(axis=0) + r
    if forces is not None:
        ends = forces[..., :2] + forces[..., 2:4] * force_scale
        ok = np.isfinite(ends).all(axis=-1)
        if ok.any():
            lo = np.minimum(lo, ends[ok].min(axis=0))
            hi = np.maximum(hi, ends[ok].max(axis=0))
    pad = 0.06 * float(max(hi - lo)) + 1e-3
    return (lo[0] - pad, hi[0] + pad), (lo[1] - pad, hi[1] + pad)


def _min_step(times: np.ndarray) -> float:
    steps = np.diff(times)
    steps = steps[steps > 0]
    return float(steps.min()) if steps.size else 1e-3
