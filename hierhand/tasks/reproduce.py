"""``hierhand reproduce``: run the paper's three tasks and write figures, numbers and a report.

The tasks are the shipped diagrams grasp.yaml, manipulate.yaml, regrasp.yaml and
regrasp_unsuppressed.yaml. Each run is saved under ``OUT/runs/<task>`` (so it can be
plotted or animated later); ``OUT/summary.json``, ``OUT/fig09.png`` ... ``fig14.png`` and
``OUT/report.md`` hold the results.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Callable

import blocks
from blocks import Results

from .figures import draw_figures
from .metrics import TaskBlocks, grasp_summary, manipulation_summary, regrasp_summary

TASKS = ("grasp", "manipulate", "regrasp", "regrasp_unsuppressed")
DEFAULT_DIAGRAMS = Path(__file__).resolve().parents[2] / "diagrams"


class ReproduceError(Exception):
    """A task that could not be run or measured."""


def run_tasks(diagrams: Path, out: Path, report: Callable[[str], None] = lambda s: None) -> dict[str, Results]:
    runs = {}
    for task in TASKS:
        path = diagrams / f"{task}.yaml"
        if not path.is_file():
            raise ReproduceError(f"{path}: task diagram not found (pass --diagrams DIR, the folder "
                                 "holding grasp.yaml, manipulate.yaml, regrasp.yaml, regrasp_unsuppressed.yaml)")
        diagram = blocks.load_diagram(path)
        results = blocks.simulate(diagram)
        results.save(out / "runs" / task)
        if not results.complete:
            raise ReproduceError(f"{path}: {results.status} (partial results in {out / 'runs' / task})")
        report(f"{task}: {results.info['t_end']:g} s simulated in {results.info['wall_time_s']:.2f} s")
        runs[task] = results
    return runs


def summarize(runs: dict[str, Results], b: TaskBlocks = TaskBlocks()) -> dict:
    """summary.json's content from the four runs."""
    grasp_params = runs["grasp"].info["parameters"]
    manipulate_params = runs["manipulate"].info["parameters"]
    return {
        "grasp": grasp_summary(runs["grasp"], float(grasp_params["push"]["time"]), b),
        "manipulation": manipulation_summary(runs["manipulate"], manipulate_params[b.manipulation]["trajectories"],
                                             run_hand(manipulate_params, b).object_pose0, b),
        "regrasp": {"suppressed": regrasp_summary(runs["regrasp"], b),
                    "unsuppressed": regrasp_summary(runs["regrasp_unsuppressed"], b)},
    }


def run_hand(parameters: dict, b: TaskBlocks = TaskBlocks()):
    """The hand of a task run, from its run.json parameters: the hand of the plant that
    the manipulation controller refers to (``hand: plant``), whose parameters are the
    hand file's sections."""
    from ..model import load_hand

    return load_hand(parameters[parameters[b.manipulation]["hand"]])


def reproduce(out: Path, diagrams: Path = DEFAULT_DIAGRAMS, report: Callable[[str], None] = lambda s: None) -> dict:
    """Run the tasks, write summary.json, the figures and report.md; return the summary."""
    out.mkdir(parents=True, exist_ok=True)
    runs = run_tasks(diagrams, out, report)
    summary = summarize(runs)
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    draw_figures(runs, summary, out)
    (out / "report.md").write_text(report_markdown(summary, runs), encoding="utf-8")
    return summary


def _num(value, unit: str = "", digits: int = 3) -> str:
    if value is None:
        return "never"
    if isinstance(value, bool):
        return "yes" if value else "no"
    return f"{value:.{digits}g}{unit}"


def report_markdown(summary: dict, runs: dict[str, Results]) -> str:
    """The paper's claims beside the measured numbers, with the figures."""
    g, m, r = summary["grasp"], summary["manipulation"], summary["regrasp"]
    s, u = r["suppressed"], r["unsuppressed"]
    rows = [
        ("Grasp: after the step force f_t/f_n peaks, then returns to <= 0.6",
         f"peak {_num(g['peak_ratio'])} at the disturbance ({_num(g['disturbance_time_s'], ' s')}); back "
         f"under 0.6 for good {_num(g['recovery_time_s'], ' s')} later; max over the last 0.2 s "
         f"{_num(g['steady_ratio_max'])}"),
        ("Grasp: the object is held", f"dropped: {_num(g['object_dropped'])}; moved "
         f"{_num(1000 * g['object_displacement_m'], ' mm')} under the 2 N push"),
        ("Manipulation: the object reaches its new position and posture",
         f"position error {_num(1000 * m['position_error_m'], ' mm')}, angle error "
         f"{_num(57.29578 * m['angle_error_rad'], ' deg')}"),
        ("Manipulation: f_t/f_n stays <= 0.6", f"max after settling {_num(m['max_ratio_after_settle'])}"),
        ("Re-grasp with suppresser: forefinger separates at 0.55 s",
         f"middle finger touches at {_num(s['middle_contact_time_s'], ' s')}, forefinger separates at "
         f"{_num(s['fore_separation_time_s'], ' s')}; dropped: {_num(s['object_dropped'])}"),
        ("Re-grasp without suppresser: forefinger never separates; torques grow against each other",
         f"middle finger touches at {_num(u['middle_contact_time_s'], ' s')}, forefinger separates: "
         f"{_num(u['fore_separation_time_s'], ' s')} (run ends at "
         f"{runs['regrasp_unsuppressed'].info['t_end']:g} s); dropped: {_num(u['object_dropped'])}"),
    ]
    table = "\n".join(f"| {claim} | {measured} |" for claim, measured in rows)
    timing = "\n".join(f"| {task} | {res.info['t_end']:g} s | {res.info['wall_time_s']:.2f} s |"
                       for task, res in runs.items())
    return f"""# Reproduction of the paper's tasks

Hierarchical control of a three-fingered hand: a grasping reflex (1 ms, internal forces,
friction safety ratio 0.6, integral control), a manipulation PD on fingertip
trajectories (10 ms), a suppresser, and the hand/object plant (0.1 ms). Each task is a
shipped diagram in `diagrams/`; its run is saved under `runs/`.

| the paper | measured here |
|---|---|
{table}

The hand's dimensions are researched defaults (the paper's Fig. 6 is lost), so the
numbers are this model's, not the paper's; the behaviour is what is compared.

## Figures

![Fig. 9](fig09.png)

![Fig. 10](fig10.png)

![Fig. 11](fig11.png)

![Fig. 12](fig12.png)

![Fig. 13](fig13.png)

![Fig. 14](fig14.png)

## Runs

| task | simulated | wall time |
|---|---|---|
{timing}
"""
