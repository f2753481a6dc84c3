"""The paper's figures 9-14 drawn from the runs of the shipped task diagrams."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from blocks import Results

from .summaries import FORE, THUMB, TaskBlocks, safety_ratio_of

FINGER_NAMES = ("thumb", "forefinger", "middle finger")


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _ratio_axes(ax, results: Results, fingers, title: str, styles=("-", "-")) -> None:
    t, ratio = results[f"{TaskBlocks.of_run(results).plant}.ratio"]
    for f, style in zip(fingers, styles):
        ax.plot(t, ratio[:, f], style, lw=1.2, label=FINGER_NAMES[f])
    safety = safety_ratio_of(results)
    ax.axhline(safety, color="k", ls="--", lw=0.8, label=f"safety ratio {safety:g}")
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("|f_t| / f_n")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper right", fontsize="small")


def _torque_axes(ax, results: Results, joint: int, title: str) -> None:
    b = TaskBlocks.of_run(results)
    t_g, tau_g = results[b.signal("reflex", "tau_g")]
    t_m, tau_m = results[b.signal("manip", "tau_m")]
    applied = b.signal("suppress", "tau_g_eff")
    suppressing = results.info.get("parameters", {}).get(b.suppress, {}).get("enabled", True) is not False
    if applied in results and suppressing:
        ax.plot(t_g, tau_g[:, joint], lw=0.8, ls="--", color="C0", label="grasp torque from the reflex")
        t_a, tau_a = results[applied]
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
    ax.legend(loc="best", fontsize="small")


def _mark(ax, t: float | None, text: str, height: float = 0.98) -> None:
    if t is not None:
        ax.axvline(t, color="0.5", ls=":", lw=1)
        ax.annotate(text, (t, height), xycoords=("data", "axes fraction"), fontsize=8, ha="left", va="top")


def _save(fig, path: Path) -> Path:
    fig.axes[-1].set_xlabel("time (s)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    _pyplot().close(fig)
    return path


def draw_figures(runs: dict[str, Results], summary: dict, out: Path) -> list[Path]:
    """fig09.png ... fig14.png in ``out`` from the runs 'grasp', 'manipulate', 'regrasp' and
    'regrasp_unsuppressed'."""
    plt = _pyplot()
    fore_joint1 = 3 * FORE
    written = []
    g = summary["grasp"]

    fig, ax = plt.subplots(figsize=(8, 3.6))
    _ratio_axes(ax, runs["grasp"], (THUMB, FORE), "Fig. 9: friction ratio, grasp under disturbance")
    _mark(ax, g["disturbance_time_s"], " disturbance")
    written.append(_save(fig, out / "fig09.png"))

    fig, ax = plt.subplots(figsize=(8, 3.6))
    _torque_axes(ax, runs["grasp"], fore_joint1, "Fig. 10: forefinger joint 1, grasp under disturbance")
    _mark(ax, g["disturbance_time_s"], " disturbance")
    written.append(_save(fig, out / "fig10.png"))

    m = summary["manipulation"]
    fig, ax = plt.subplots(figsize=(8, 3.6))
    _ratio_axes(ax, runs["manipulate"], (THUMB, FORE), "Fig. 11: friction ratio, manipulation")
    written.append(_save(fig, out / "fig11.png"))

    fig, axes = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
    t, obj = runs["manipulate"][f"{TaskBlocks.of_run(runs['manipulate']).plant}.obj"]
    target = m["target_pose"]
    for j, label in enumerate(("x", "y")):
        axes[0].plot(t, 1000 * obj[:, j], lw=1.2, label=f"object {label}")
        axes[0].axhline(1000 * target[j], ls="--", lw=0.8, color=f"C{j}", label=f"target {label}")
    axes[0].set_ylabel("position (mm)")
    axes[0].set_title("Fig. 12: object position and posture, manipulation")
    axes[0].legend(fontsize="small", ncol=2)
    axes[1].plot(t, np.degrees(obj[:, 2]), lw=1.2, color="C2", label="object angle")
    axes[1].axhline(np.degrees(target[2]), ls="--", lw=0.8, color="C2", label="target angle")
    axes[1].set_ylabel("posture (deg)")
    axes[1].legend(fontsize="small")
    for ax in axes:
        ax.grid(alpha=0.3)
    written.append(_save(fig, out / "fig12.png"))

    r = summary["regrasp"]
    fig, axes = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
    for ax, key, label in ((axes[0], "regrasp", "with suppresser"),
                           (axes[1], "regrasp_unsuppressed", "without suppresser")):
        _ratio_axes(ax, runs[key], (FORE,), f"Fig. 13 ({label}): forefinger friction ratio, re-grasp")
        run_key = "suppressed" if key == "regrasp" else "unsuppressed"
        _mark(ax, r[run_key]["middle_contact_time_s"], " middle touches")
        _mark(ax, r[run_key]["fore_separation_time_s"], " forefinger leaves")
    written.append(_save(fig, out / "fig13.png"))

    written.append(_fig14(runs, r, out, fore_joint1))
    return written


def _fig14(runs: dict[str, Results], r: dict, out: Path, joint: int) -> Path:
    """Fig. 14: the forefinger's grasp torque before and after the suppresser, its |tau_m|
    against S_b and the suppresser's factor while it withdraws; below, the same run without
    the suppresser."""
    plt = _pyplot()
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
    fig, axes = plt.subplots(3, 1, figsize=(8.5, 8.5), gridspec_kw={"height_ratios": [3, 1.6, 3]})
    ax = axes[0]
    ax.plot(t[shown], tau_g[shown, joint], ls="--", lw=1.0, color="C0", label="grasp torque from the reflex")
    ax.plot(t[shown], applied[shown, joint], lw=1.6, color="C0", label="grasp torque applied (after the suppresser)")
    ax.plot(t[shown], tau_m[shown], lw=1.2, color="C1", label="|manipulation torque| (PD)")
    ax.axhline(s_b, color="C1", ls=":", lw=1.0, label=f"S_b = {s_b:g} N m")
    ax.set_ylabel("torque (N m)")
    ax.set_title("Fig. 14: forefinger joint 1 while it withdraws, re-grasp with suppresser")
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    axes[1].plot(t[shown], factor[shown], lw=1.4, color="C3")
    axes[1].axhline(0.5, color="k", ls=":", lw=0.8)
    axes[1].set_ylim(0, 1.05)
    axes[1].set_ylabel("suppression\nfactor")
    for ax in axes[:2]:
        ax.set_xlim(start, end)
        ax.grid(alpha=0.3)
        _mark(ax, s["withdrawal_start_s"], " withdrawal starts")
        _mark(ax, s["fore_factor_leaves_s"], " factor < 0.9", height=0.86)
        _mark(ax, s["fore_separation_time_s"], " forefinger leaves", height=0.74)
    _torque_axes(axes[2], runs["regrasp_unsuppressed"], joint,
                 "Fig. 14, below: the same joint, re-grasp without suppresser")
    axes[2].legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    _mark(axes[2], r["unsuppressed"]["withdrawal_start_s"], " withdrawal starts")
    return _save(fig, out / "fig14.png")
