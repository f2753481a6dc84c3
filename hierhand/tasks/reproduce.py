"""``hierhand reproduce``: run the paper's three tasks and write figures, numbers and a report.

The tasks are the shipped diagrams grasp.yaml, manipulate.yaml, regrasp.yaml and
regrasp_unsuppressed.yaml. Each run is saved under ``OUT/runs/<task>`` (so it can be
plotted or animated later); ``OUT/summary.json``, ``OUT/fig09.png`` ... ``fig14.png`` and
``OUT/report.md`` hold the results, the report with every addition beyond the paper
switched off alone (``ablations``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Callable

import blocks
from blocks import Results
from blocks.process.progress import above, progress_bar

from ..examples import SHIPPED
from ..model import load_hand
from .ablations import ABLATIONS, MECHANISMS, needed_at_shipped_point, shipped_outcomes
from .robustness import TASKS as JUDGED
from .figures import draw_figures
from .report import report_markdown
from .separation import RUNS as SEPARATION_RUNS, separation_relation
from .summaries import (FORE, MIDDLE, THUMB, TaskBlocks, grasp_summary, handover_time, manipulation_summary,
                        ratio_excursions, reaction_times, regrasp_succeeded, regrasp_summary, withdrawal)

TASKS = ("grasp", "manipulate", "regrasp", "regrasp_unsuppressed")


DEFAULT_DIAGRAMS = SHIPPED
REACTION_SHARES = (0.05, 0.1, 0.5)
"""Shares of their moves at which Fig. 10's torques are compared besides the first change."""
SETTLED = 0.01
"""Seconds after the hand-over, the middle finger's first touch or the push from which the
ratio excursions are counted (the contact's first milliseconds settle its anchors)."""


class ReproduceError(Exception):
    """A task that could not be run or measured."""


class MissingDiagram(ReproduceError):
    """A task diagram is not in the diagrams folder: bad input, found before anything runs."""


def check_diagrams(diagrams: Path) -> None:
    """MissingDiagram unless ``diagrams`` holds every task's diagram."""
    for task in TASKS:
        path = diagrams / f"{task}.yaml"
        if not path.is_file():
            raise MissingDiagram(f"{path}: task diagram not found (hint: pass --diagrams DIR, the folder "
                                 f"holding {', '.join(f'{t}.yaml' for t in TASKS)})")


def run_tasks(diagrams: Path, out: Path, report: Callable[[str], None] = lambda s: None,
              done: Callable[[], None] = lambda: None) -> dict[str, Results]:
    """Run and save each task's diagram; ``done`` is called after each."""
    check_diagrams(diagrams)
    runs = {}
    for task in TASKS:
        path = diagrams / f"{task}.yaml"
        diagram = blocks.load_diagram(path)
        results = blocks.simulate(diagram)
        results.save(out / "runs" / task)
        if not results.complete:
            raise ReproduceError(f"{path}: {results.status} (partial results in {out / 'runs' / task})")
        report(f"{task}: {results.info['t_end']:g} s simulated in {results.info['wall_time_s']:.2f} s")
        runs[task] = results
        done()
    return runs


def summarize(runs: dict[str, Results]) -> dict:
    """summary.json's content from the four runs."""
    roles = {task: TaskBlocks.of_run(results) for task, results in runs.items()}
    grasp_params = runs["grasp"].info["parameters"]
    manipulate_params = runs["manipulate"].info["parameters"]
    push = float(grasp_params["push"]["time"])
    regrasp = {key: regrasp_summary(runs[task], withdrawal(runs[task].info["parameters"], roles[task]))
               for key, task in (("suppressed", "regrasp"), ("unsuppressed", "regrasp_unsuppressed"))}
    for case in regrasp.values():
        case["succeeded"] = regrasp_succeeded(case)
    handover = handover_time(grasp_params, roles["grasp"])
    grasp = grasp_summary(runs["grasp"], push, handover_time=handover)
    grasp.update(reaction_times(runs["grasp"], push))
    grasp.update(reaction_times(runs["grasp"], push, part=0.01, label="first_moves"))
    grasp["reaction_shares"] = {f"{round(100 * part)} %": reaction_times(runs["grasp"], push, part=part, label="at")
                                for part in REACTION_SHARES}
    trajectories = manipulate_params[roles["manipulate"].block("manip")]["trajectories"]
    manipulation = manipulation_summary(runs["manipulate"], trajectories,
                                        load_hand(manipulate_params[roles["manipulate"].plant]).object_pose0)
    settle = min(w["waypoints"][0][0] for w in trajectories.values())
    middle = regrasp["suppressed"]["middle_contact_time_s"]
    names = {THUMB: "thumb", FORE: "forefinger", MIDDLE: "middle finger"}

    def excursions(results: Results, since: float, fingers, until: float = float("inf")) -> dict:
        return {names[f]: v for f, v in ratio_excursions(results, since, fingers, until=until).items()}

    start = regrasp["suppressed"]["withdrawal_start_s"]
    unsuppressed = regrasp["unsuppressed"]
    return {
        "grasp": grasp,
        "manipulation": manipulation,
        "regrasp": regrasp,
        "ratio_excursions": {
            "grasp while the fingers close, before the hand-over": excursions(runs["grasp"], 0.0, (THUMB, FORE), handover),
            f"grasp, the hand-over's first {1000 * SETTLED:g} ms": excursions(
                runs["grasp"], handover, (THUMB, FORE), handover + SETTLED),
            "grasp after the hand-over, before the push": excursions(
                runs["grasp"], handover + SETTLED, (THUMB, FORE), push),
            "grasp after the push": excursions(runs["grasp"], push, (THUMB, FORE)),
            "manipulation from its first waypoint": excursions(runs["manipulate"], settle, (THUMB, FORE)),
            "re-grasp, as the middle finger lands (from its first touch to the withdrawal's start)": excursions(
                runs["regrasp"], middle or 0.0, (THUMB, FORE, MIDDLE), start),
            "re-grasp, the holding fingers after the middle finger's first touch": excursions(
                runs["regrasp"], (middle or 0.0) + SETTLED, (THUMB, MIDDLE)),
            "re-grasp without the suppresser, from the withdrawal's start": excursions(
                runs["regrasp_unsuppressed"], unsuppressed["withdrawal_start_s"], (THUMB, FORE, MIDDLE)),
        },
    }


def reproduce(out: Path, diagrams: Path = DEFAULT_DIAGRAMS, report: Callable[[str], None] = lambda s: None,
              progress: bool = False) -> dict:
    """Run the tasks, write summary.json, the figures and report.md; return the summary.
    ``progress``: a bar on a terminal, a step per run of a task, of the separation
    relation and of each ablation row, and one for the figures and report."""
    check_diagrams(diagrams)
    out.mkdir(parents=True, exist_ok=True)
    steps = len(TASKS) + SEPARATION_RUNS + 2 + len(ABLATIONS) + len(JUDGED) * (len(MECHANISMS) + 1) + 1
    with progress_bar(steps, "reproduce", unit="step", enabled=progress) as bar:
        say, done = above(bar, report), lambda: bar.update(1)
        runs = run_tasks(diagrams, out, say, done)
        summary = summarize(runs)
        summary["separation_relation"] = separation_relation(diagrams / "regrasp.yaml", done)
        summary["ablations"] = shipped_outcomes(diagrams, done=done)
        say(f"ablations: the paper-only configuration, {len(summary['ablations']) - 2} additions switched off one by one")
        summary["needed_at_shipped_point"] = {}
        for task in JUDGED:
            needed = needed_at_shipped_point(diagrams, task, done)
            summary["needed_at_shipped_point"][task.name] = [a.name for a in MECHANISMS if a.name in needed]
        (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
        draw_figures(runs, summary, out)
        (out / "report.md").write_text(report_markdown(summary, runs), encoding="utf-8")
        done()
    return summary
