"""The paper's figures 9-14 drawn from the runs of the shipped task diagrams."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from blocks import Results

from .summaries import FORE, THUMB, TaskBlocks, safety_ratio_of

FINGER_NAMES = ("thumb", "forefinger", "middle finger")
SAME_TORQUE = 1e-3
"""A torque the suppresser changes by at most this part of its peak is drawn once: two
lines one under the other would show as one while the legend names two."""


def _figure(rows: int = 1, height: float = 3.6, **kw):
    """A new Figure (no pyplot) of ``rows`` axes sharing time, laid out so that the legends
    right of the axes and the titles fit."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.5, height), layout="constrained")
    axes = fig.subplots(rows, 1, sharex=True, squeeze=False, **kw)[:, 0]
    return fig, list(axes)


def _legend(ax) -> None:
    """The axis's legend right of it, off the data."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False, borderaxespad=0.0)


def _phases(axes, results: Results) -> None:
    """The task's phases, read from its diagram as ``hierhand plot`` marks them (the
    support's hand-over, each fingertip trajectory's span, Step times)."""
    from blocks.plot.markers import draw_markers
    from blocks.plot.markers import markers

    draw_markers(axes, markers(results.info)[0])


def _ratio_axes(ax, results: Results, fingers, title: str, styles=("-", "-")) -> None:
    t, ratio = results[f"{TaskBlocks.of_run(results).plant}.ratio"]
    for f, style in zip(fingers, styles):
        ax.plot(t, ratio[:, f], style, lw=1.2, color=f"C{f}", label=FINGER_NAMES[f])
    safety = safety_ratio_of(results)
    ax.axhline(safety, color="k", ls="--", lw=0.8, label=f"safety ratio {safety:g}")
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("|f_t| / f_n")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    _legend(ax)


def _torque_axes(ax, results: Results, joint: int, title: str) -> None:
    """The grasp torque (from the reflex, and applied after the suppresser where it changes
    it: one line where the two are the same to ``SAME_TORQUE``) and the manipulation torque."""
    b = TaskBlocks.of_run(results)
    t_g, tau_g = results[b.signal("reflex", "tau_g")]
    t_m, tau_m = results[b.signal("manip", "tau_m")]
    applied = b.signal("suppress", "tau_g_eff")
    suppressing = results.info.get("parameters", {}).get(b.suppress, {}).get("enabled", True) is not False
    if applied in results and suppressing:
        t_a, tau_a = results[applied]
        if len(t_a) == len(t_g) and np.abs(tau_a[:, joint] - tau_g[:, joint]).max() <= \
                SAME_TORQUE * np.abs(tau_g[:, joint]).max():
            ax.plot(t_g, tau_g[:, joint], lw=1.2, color="C0",
                    label=f"grasp torque (reflex; the suppresser changes it by < {100 * SAME_TORQUE:g} %)")
        else:
            ax.plot(t_g, tau_g[:, joint], lw=0.8, ls="--", color="C0", label="grasp torque from the reflex")
            ax.plot(t_a, tau_a[:, joint], lw=1.2, color="C0", label="grasp torque applied (after the suppresser)")
    elif not suppressing:  # the reflex's torque is applied as it is
        ax.plot(t_g, tau_g[:, joint], lw=1.2, color="C0", label="grasp torque (reflex, applied unsuppressed)")
    else:
        ax.plot(t_g, tau_g[:, joint], lw=1.2, color="C0", label="grasp torque (reflex)")
    ax.step(t_m, tau_m[:, joint], where="post", lw=1.2, color="C1", label="manipulation torque (PD)")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_ylabel("torque (N m)")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    _legend(ax)


def _mark(ax, t: float | None, text: str, height: float = 0.98) -> None:
    """A measured event (the push, the middle finger's touch, the forefinger letting go):
    a dotted line and its words."""
    if t is not None:
        ax.axvline(t, color="0.3", ls=":", lw=1)
        ax.annotate(text, (t, height), xycoords=("data", "axes fraction"), fontsize=8, ha="left", va="top",
                    bbox={"boxstyle": "square,pad=0.1", "facecolor": "white", "alpha": 0.8, "linewidth": 0})


def _save(fig, path: Path) -> Path:
    if not fig.axes[-1].get_xlabel():
        fig.axes[-1].set_xlabel("time (s)")
    fig.savefig(path, dpi=110)
    return path


def _object_target(results: Results, trajectories: dict, fingers=("thumb", "fore")) -> tuple[np.ndarray, np.ndarray]:
    """(times, poses): the object pose the two fingertips' planned trajectories imply over
    the run, moving rigidly with them from the pose they start at (``rigid_target``)."""
    from hierhand.control.trajectory import Trajectory
    from hierhand.model import load_hand

    from .summaries import rigid_target

    b = TaskBlocks.of_run(results)
    start_pose = load_hand(results.info["parameters"][b.plant]).object_pose0
    plans = [Trajectory(trajectories[f]["waypoints"], trajectories[f].get("interpolation", "minjerk"))
             for f in fingers]
    t = results[f"{b.plant}.obj"][0]
    first = np.array([p.points[0, :2] for p in plans])
    poses = np.array([rigid_target(first, np.array([p.sample(float(x))[:2] for p in plans]), start_pose) for x in t])
    return t, poses


def draw_figures(runs: dict[str, Results], summary: dict, out: Path) -> list[Path]:
    """fig09.png ... fig14.png in ``out`` from the runs 'grasp', 'manipulate', 'regrasp' and
    'regrasp_unsuppressed'. Every time axis marks the task's phases from its diagram, and
    the measured events the figure is about."""
    fore_joint1 = 3 * FORE
    written = []
    g = summary["grasp"]

    fig, (ax,) = _figure()
    _ratio_axes(ax, runs["grasp"], (THUMB, FORE), "Fig. 9: friction ratio, grasp under disturbance")
    _phases([ax], runs["grasp"])
    _mark(ax, g["disturbance_time_s"], " disturbance", height=0.6)
    written.append(_save(fig, out / "fig09.png"))

    fig, (ax,) = _figure()
    _torque_axes(ax, runs["grasp"], fore_joint1, "Fig. 10: forefinger joint 1, grasp under disturbance")
    _phases([ax], runs["grasp"])
    _mark(ax, g["disturbance_time_s"], " disturbance", height=0.6)
    written.append(_save(fig, out / "fig10.png"))

    fig, (ax,) = _figure()
    _ratio_axes(ax, runs["manipulate"], (THUMB, FORE), "Fig. 11: friction ratio, manipulation")
    _phases([ax], runs["manipulate"])
    written.append(_save(fig, out / "fig11.png"))

    written.append(_fig12(runs["manipulate"], summary["manipulation"], out))

    r = summary["regrasp"]
    fig, axes = _figure(2, 6.0)
    fig.suptitle("Fig. 13: the forefinger's friction ratio in the re-grasp")
    for ax, key, label in ((axes[0], "regrasp", "with the suppresser"),
                           (axes[1], "regrasp_unsuppressed", "without the suppresser")):
        _ratio_axes(ax, runs[key], (FORE,), label)
        _phases([ax], runs[key])
        run_key = "suppressed" if key == "regrasp" else "unsuppressed"
        _mark(ax, r[run_key]["middle_contact_time_s"], " middle touches", height=0.6)
        _mark(ax, r[run_key]["fore_separation_time_s"], " forefinger leaves", height=0.45)
    written.append(_save(fig, out / "fig13.png"))

    written.append(_fig14(runs, r, out, fore_joint1))
    return written


def _fig12(run: Results, m: dict, out: Path) -> Path:
    """Fig. 12: the object's x, y (mm) and angle (deg) against the pose the fingertip plans
    imply, over the time the object moves (from shortly before the first waypoint)."""
    b = TaskBlocks.of_run(run)
    trajectories = run.info["parameters"][b.block("manip")]["trajectories"]
    t, obj = run[f"{b.plant}.obj"]
    t_target, target = _object_target(run, trajectories)
    starts = [w["waypoints"][0][0] for w in trajectories.values()]
    ends = [w["waypoints"][-1][0] for w in trajectories.values()]
    start = max(float(t[0]), min(starts) - 0.1 * (max(ends) - min(starts)))
    shown = t >= start
    fig, axes = _figure(3, 7.5)
    fig.suptitle("Fig. 12: object position and posture in the manipulation, against the target")
    for ax, j, scale, name, unit in ((axes[0], 0, 1000, "x", "mm"), (axes[1], 1, 1000, "y", "mm"),
                                     (axes[2], 2, 180 / np.pi, "angle", "deg")):
        ax.plot(t[shown], scale * obj[shown, j], lw=1.4, color="C0", label=f"object {name}")
        keep = t_target >= start
        ax.plot(t_target[keep], scale * target[keep, j], ls="--", lw=1.0, color="k",
                label=f"target {name} (from the fingertip plans)")
        ax.set_ylabel(f"{name} ({unit})")
        ax.grid(alpha=0.3)
        _legend(ax)
    axes[0].set_xlim(start, float(t[-1]))
    _phases(axes, run)
    axes[-1].set_xlabel(f"time (s); final error {1000 * m['position_error_m']:.2f} mm, "
                        f"{np.degrees(m['angle_error_rad']):.2f} deg")
    return _save(fig, out / "fig12.png")


def _fig14(runs: dict[str, Results], r: dict, out: Path, joint: int) -> Path:
    """Fig. 14: the forefinger's grasp torque before and after the suppresser, its |tau_m|
    against S_b and the suppresser's factor while it withdraws; below, the same run without
    the suppresser."""
    from matplotlib.figure import Figure

    s = r["suppressed"]
    run = runs["regrasp"]
    b = TaskBlocks.of_run(run)
    t, tau_g = run[b.signal("reflex", "tau_g")]
    _, applied = run[b.signal("suppress", "tau_g_eff")]
    tau_m = np.abs(run.held(b.signal("manip", "tau_m"), t)[:, joint])
    factor = np.divide(applied[:, joint], tau_g[:, joint], out=np.full(t.size, np.nan), where=tau_g[:, joint] != 0)
    s_b = float(np.mean(run.info["parameters"][b.suppress]["S_b"]))
    start = s["withdrawal_start_s"] - 0.05
    end = (s["fore_separation_time_s"] or s["withdrawal_end_s"]) + 0.05
    shown = (t >= start) & (t <= end)
    fig = Figure(figsize=(10, 9), layout="constrained")
    fig.suptitle("Fig. 14: forefinger joint 1 while it withdraws in the re-grasp")
    top, middle, bottom = fig.subplots(3, 1, gridspec_kw={"height_ratios": [3, 1.6, 3]})
    top.plot(t[shown], tau_g[shown, joint], ls="--", lw=1.0, color="C0", label="grasp torque from the reflex")
    top.plot(t[shown], applied[shown, joint], lw=1.6, color="C0", label="grasp torque applied (after the suppresser)")
    top.plot(t[shown], tau_m[shown], lw=1.2, color="C1", label="|manipulation torque| (PD)")
    top.axhline(s_b, color="C1", ls=":", lw=1.0, label=f"S_b = {s_b:g} N m")
    top.set_ylabel("torque (N m)")
    top.set_title("with the suppresser: torques")
    _legend(top)
    middle.plot(t[shown], factor[shown], lw=1.4, color="C3", label="applied / reflex grasp torque")
    middle.axhline(0.5, color="k", ls=":", lw=0.8, label="one half")
    middle.set_ylim(0, 1.05)
    middle.set_ylabel("suppression\nfactor")
    middle.set_title("with the suppresser: the factor it applies")
    _legend(middle)
    for ax in (top, middle):
        ax.set_xlim(start, end)
        ax.grid(alpha=0.3)
        _mark(ax, s["withdrawal_start_s"], " withdrawal starts")
        _mark(ax, s["fore_factor_leaves_s"], " factor < 0.9", height=0.8)
        _mark(ax, s["fore_separation_time_s"], " forefinger leaves", height=0.62)
    _phases([top, middle], run)
    middle.set_xlabel("time (s)")
    _torque_axes(bottom, runs["regrasp_unsuppressed"], joint, "without the suppresser: the whole run")
    _phases([bottom], runs["regrasp_unsuppressed"])
    _mark(bottom, r["unsuppressed"]["withdrawal_start_s"], " withdrawal starts", height=0.6)
    bottom.set_xlabel("time (s)")
    return _save(fig, out / "fig14.png")
