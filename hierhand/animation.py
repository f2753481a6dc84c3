"""Animated GIF of a run: the hand, the object and the contact forces over time.

``animate_run(results, "hand.gif")`` draws the ``HandPlant`` of a results folder (see
``blocks.Results``) frame by frame with ``hierhand.model.draw.draw_hand`` and writes a GIF
with matplotlib's Pillow writer. It needs the plant's ``q`` and ``obj`` logged; with
``fn`` and ``normal`` (and ``ft``) logged too it draws the force each fingertip applies to
the object, ``fn * n + ft * t`` with ``t`` the normal ``n`` turned +90 degrees, at the
contact point (tip centre + tip radius * n).

Frames are samples of ``<plant>.q``: one every ``speed / fps`` seconds of simulated time
(or every ``every``-th sample), plus the last one. Every other signal keeps its own
sample times and is taken at a frame's time by zero-order hold.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from blocks.results import held_index

__all__ = ["AnimationError", "animate_run"]

MAX_FRAMES = 1000
ARROW_SIGNALS = ("fn", "ft", "normal")
HOLD_RTOL = 1e-9
"""Frame times are sums of float steps: a sample this close (relative) after one is at it."""


class AnimationError(ValueError):
    """A run that cannot be animated (no hand plant, a signal not logged, bad options)."""


def animate_run(results: Any, path: str | Path, fps: float = 25, speed: float = 1.0,
                plant: str | None = None, every: int | None = None,
                newtons_per_mm: float | None = None, max_frames: int = MAX_FRAMES,
                dpi: int = 80) -> Path:
    """Write an animated GIF of the hand plant in ``results`` to ``path``; return the path.

    ``results``: a ``blocks.Results`` or its folder. ``fps``: GIF frames per second.
    ``speed``: simulated seconds per second of GIF (0.1 = ten times slower than real
    time). ``every``: instead, a frame at every ``every``-th sample of ``<plant>.q``.
    ``plant``: the ``HandPlant`` block's name (needed only if the run has several).
    ``newtons_per_mm``: arrow scale (default: a round number making the largest force
    about 25 mm long). Raises ``AnimationError`` with a one-line message for runs that
    cannot be animated.
    """
    from blocks import Results

    if not isinstance(results, Results):
        results = Results.load(results)
    path = Path(path)
    if path.suffix.lower() != ".gif":
        raise AnimationError(f"{path}: the animation is written as a GIF; name the file *.gif")
    if not (isinstance(fps, (int, float)) and math.isfinite(fps) and fps > 0):
        raise AnimationError(f"fps must be a positive number, got {fps!r}")
    if not (isinstance(speed, (int, float)) and math.isfinite(speed) and speed > 0):
        raise AnimationError(f"speed must be a positive number, got {speed!r}")
    if every is not None and (isinstance(every, bool) or not isinstance(every, int) or every < 1):
        raise AnimationError(f"every must be a positive integer, got {every!r}")

    name = _find_plant(results, plant)
    hand = _load_hand(results, name)
    t_q, q_all = _signal(results, name, "q", required=True)
    if not len(t_q):
        raise AnimationError(f"signal '{name}.q' has no samples; the run stopped before its first output")
    frames = _frame_indices(t_q, fps, speed, every, max_frames)
    times = t_q[frames]
    q = q_all[frames]
    obj = _held(results, f"{name}.obj", times, required=True)

    forces = _forces(results, name, hand, q, times)  # (frames, 3, 4) x, y, fx, fy or None
    if newtons_per_mm is None:
        newtons_per_mm = _nice_scale(forces)
    elif not (newtons_per_mm > 0 and math.isfinite(newtons_per_mm)):
        raise AnimationError(f"newtons_per_mm must be a positive number, got {newtons_per_mm!r}")
    force_scale = 1e-3 / newtons_per_mm  # metres of arrow per newton

    path.parent.mkdir(parents=True, exist_ok=True)
    _write_gif(results, name, hand, times, q, obj, forces, force_scale, newtons_per_mm,
               path, fps, dpi)
    return path


# -- data ---------------------------------------------------------------------------


def _find_plant(results, plant: str | None) -> str:
    types = results.info.get("block_types")
    if not isinstance(types, dict):  # Results built in Python: go by the logged signals
        found = sorted({s.rsplit(".", 1)[0] for s in results if s.endswith(".q")
                        and s.rsplit(".", 1)[0] + ".obj" in results})
        if plant is not None:
            return plant
        if len(found) == 1:
            return found[0]
        raise AnimationError("the results record no block types (run.json); name the plant with --plant NAME")
    plants = sorted(n for n, t in types.items() if t == "HandPlant")
    if plant is not None:
        if plant not in types:
            raise AnimationError(f"--plant {plant}: no block named '{plant}' in this run; "
                                 f"HandPlant blocks: {', '.join(plants) or 'none'}")
        if types[plant] != "HandPlant":
            raise AnimationError(f"--plant {plant}: block '{plant}' is a {types[plant]}, not a HandPlant")
        return plant
    if not plants:
        raise AnimationError("no HandPlant block in this run (blocks: "
                             f"{', '.join(f'{n} ({t})' for n, t in types.items()) or 'none'}); "
                             "animate needs a run of a diagram with a hand plant")
    if len(plants) > 1:
        raise AnimationError(f"several HandPlant blocks in this run ({', '.join(plants)}); "
                             "choose one with --plant NAME")
    return plants[0]


def _load_hand(results, name: str):
    from hierhand.model import HandFileError, load_hand

    params = (results.info.get("parameters") or {}).get(name) or {}
    try:
        return load_hand(params)
    except HandFileError as exc:
        raise AnimationError(f"the parameters of '{name}' in run.json are not a valid hand: "
                             + "; ".join(exc.errors)) from None


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
    """Indices into q's samples: one per 1/fps of GIF time (held where q is slower), plus the last."""
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
    """(frames, 3, 4): per finger where its force on the object acts and the force; None
    without ``fn`` and ``normal`` logged. Fingers with no sample yet get NaN (no arrow)."""
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
    force = fn[..., None] * n + ft[..., None] * tangent
    # the tip drawn is the one of the drawn q, so the arrows start on the drawn circles
    tips = np.array([hand.tip_positions(qk) for qk in q])
    at = tips + hand.tip_radius[None, :, None] * n
    return np.concatenate([at, force], axis=-1)


def _nice_scale(forces: np.ndarray | None, longest_mm: float = 25.0) -> float:
    """A round N-per-mm (1, 2 or 5 times a power of ten) drawing the largest force about ``longest_mm``."""
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


def _limits(hand, q: np.ndarray, obj: np.ndarray, forces, force_scale: float):
    """Fixed axis limits covering the fingers, tips, object and arrows of every frame."""
    pts = [hand.joint_positions(qk).reshape(-1, 2) for qk in q]
    pts += [hand.object_corners(pose) for pose in obj]
    xy = np.concatenate(pts)
    r = float(hand.tip_radius.max())
    lo, hi = xy.min(axis=0) - r, xy.max(axis=0) + r
    if forces is not None:
        ends = forces[..., :2] + forces[..., 2:] * force_scale
        ok = np.isfinite(ends).all(axis=-1)
        if ok.any():
            lo = np.minimum(lo, ends[ok].min(axis=0))
            hi = np.maximum(hi, ends[ok].max(axis=0))
    pad = 0.06 * float(max(hi - lo)) + 1e-3
    return (lo[0] - pad, hi[0] + pad), (lo[1] - pad, hi[1] + pad)


# -- drawing ------------------------------------------------------------------------


def _write_gif(results, plant, hand, times, q, obj, forces, force_scale, newtons_per_mm,
               path, fps, dpi) -> None:
    from matplotlib.animation import FuncAnimation, PillowWriter
    from matplotlib.figure import Figure  # no pyplot: leaves the caller's backend alone
    from matplotlib.lines import Line2D

    from hierhand.model.draw import FINGER_COLOURS, draw_hand

    xlim, ylim = _limits(hand, q, obj, forces, force_scale)
    ratio = (ylim[1] - ylim[0]) / (xlim[1] - xlim[0])
    fig = Figure(figsize=(6.0, float(np.clip(5.0 * ratio + 1.6, 3.0, 9.0))), dpi=dpi)
    ax = fig.add_subplot()
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_aspect("equal")
    ax.set_autoscale_on(False)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(True, alpha=0.25)
    heading = results.info.get("diagram") or plant
    if not results.complete:
        heading += " (incomplete run)"
    digits = max(3, min(6, 1 - math.floor(math.log10(_min_step(times)))))
    note = (f"contact forces on the object: {newtons_per_mm:g} N per mm" if forces is not None else
            f"no force arrows: log {plant}.fn, {plant}.ft and {plant}.normal to draw them")
    fig.text(0.5, 0.012, note, ha="center", va="bottom", fontsize=9,
             color="tab:red" if forces is not None else "0.4")
    fig.legend(handles=[Line2D([], [], color=FINGER_COLOURS[f % len(FINGER_COLOURS)], linewidth=2.5, label=n)
                        for f, n in enumerate(hand.names)],
               loc="lower center", bbox_to_anchor=(0.5, 0.045), ncol=3, fontsize=8, frameon=False)
    drawn: list = []

    def draw(k: int):
        for artist in drawn:
            artist.remove()
        drawn.clear()
        artists = draw_hand(ax, hand, q[k], obj[k], None if forces is None else forces[k], force_scale)
        for group in artists.values():
            drawn.extend(group)
        ax.set_xlim(*xlim)
        ax.set_ylim(*ylim)
        ax.set_title(f"{heading}   t = {times[k]:.{digits}f} s")
        return drawn

    fig.tight_layout(rect=(0, 0.09, 1, 1))
    anim = FuncAnimation(fig, draw, frames=len(times), init_func=lambda: [], blit=False,
                         repeat=False, cache_frame_data=False)
    anim.save(path, writer=PillowWriter(fps=fps), dpi=dpi)


def _min_step(times: np.ndarray) -> float:
    steps = np.diff(times)
    steps = steps[steps > 0]
    return float(steps.min()) if steps.size else 1.0
