"""Each task judged on one point of the spread: did it do what the paper says, and if not, why.

``judge(variation, diagrams)`` runs the shipped task diagrams carried onto the variation
(``variations.carry``) and gives each task's outcome: ``""`` when it succeeded, else the
first thing that went wrong (``"dropped"``, ``"forefinger holds on"``, ...), or
``"unreachable"`` when a pose of the task is out of the varied hand's reach. The
re-grasp without the suppresser succeeds when the forefinger never lets go and the object
stays held. ``benchmarks/robustness.py`` runs the spread; the tests run a sample of it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping

import blocks
from blocks import Results

from ..control.inverse_kinematics import UnreachableError
from ..model import load_hand
from .summaries import (POSITION_TOLERANCE, TaskBlocks, grasp_summary, grasp_succeeded, handover_time, manipulation_summary,
                        manipulation_succeeded, regrasp_events, regrasp_succeeded, regrasp_summary, withdrawal)
from .variations import Variation, carry

UNREACHABLE = "unreachable"


def grasp_outcome(results: Results) -> str:
    parameters = results.info["parameters"]
    summary = grasp_summary(results, float(parameters["push"]["time"]),
                            handover_time=handover_time(parameters, TaskBlocks.of_run(results)))
    if summary["object_dropped"]:
        return "dropped"
    return "" if grasp_succeeded(summary) else "ratio above the safety ratio at the end"


def manipulation_outcome(results: Results) -> str:
    parameters, b = results.info["parameters"], TaskBlocks.of_run(results)
    summary = manipulation_summary(results, parameters[b.block("manip")]["trajectories"],
                                   load_hand(parameters[b.plant]).object_pose0, b)
    if summary["object_dropped"]:
        return "dropped"
    if summary["position_error_m"] > POSITION_TOLERANCE:
        return "off its target position"
    if not manipulation_succeeded(summary):
        return ("off its target angle" if summary["angle_error_rad"] > math.radians(1.0)
                else "ratio above the safety ratio")
    return ""


def regrasp_outcome(results: Results) -> str:
    summary = regrasp_summary(results, withdrawal(results.info["parameters"], TaskBlocks.of_run(results)))
    if summary["object_dropped"]:
        return "dropped"
    if summary["middle_contact_time_s"] is None:
        return "middle finger never touches"
    if summary["fore_separation_time_s"] is None:
        return "forefinger holds on"
    if not summary["fore_stays_off"]:
        return "forefinger comes back"
    return "" if regrasp_succeeded(summary) else "separates outside the withdrawal"


def unsuppressed_outcome(results: Results) -> str:
    events = regrasp_events(results)
    if events["object_dropped"]:
        return "dropped"
    return "forefinger separates" if events["fore_separation_time_s"] is not None else ""


def grasp_margin(results: Results) -> float:
    """How far the grasp's |f_t|/f_n stays under its safety ratio over the last 0.2 s (plant rate)."""
    parameters = results.info["parameters"]
    summary = grasp_summary(results, float(parameters["push"]["time"]))
    return summary["safety_ratio"] - summary["steady_ratio_max"]


def manipulation_margin(results: Results) -> float:
    """How far the manipulation's |f_t|/f_n stays under its safety ratio once settled (plant rate)."""
    parameters, b = results.info["parameters"], TaskBlocks.of_run(results)
    summary = manipulation_summary(results, parameters[b.block("manip")]["trajectories"],
                                   load_hand(parameters[b.plant]).object_pose0, b)
    return summary["safety_ratio"] - summary["max_ratio_after_settle"]


@dataclass(frozen=True)
class Task:
    """A shipped task diagram, whether it moves the object, how it is judged, and the margin
    of its threshold claim (safety ratio less the ratio it is judged by; None without one)."""

    name: str
    moves_object: bool
    outcome: Callable[[Results], str]
    margin: Callable[[Results], float] | None = None


TASKS = (
    Task("grasp", False, grasp_outcome, grasp_margin),
    Task("manipulate", True, manipulation_outcome, manipulation_margin),
    Task("regrasp", False, regrasp_outcome),
    Task("regrasp_unsuppressed", False, unsuppressed_outcome),
)


def judge(variation: Variation, diagrams: Path, extra: Mapping[str, Mapping[str, Any]] | None = None,
          tasks: tuple[Task, ...] = TASKS, margins: dict[str, float | None] | None = None) -> dict[str, str]:
    """Each task's outcome on the variation; ``extra``: more ``--set`` values per task name
    (an ablation), written by role (``reflex.margin``, see ``TaskBlocks.resolve``) and
    applied after the variation's. ``margins``, when given, receives each task's threshold
    margin (``Task.margin``; None where the task has none, did not run or dropped the object)."""
    outcomes = {}
    for task in tasks:
        path = diagrams / f"{task.name}.yaml"
        diagram = blocks.load_diagram(path)
        b = TaskBlocks.of_diagram(diagram)
        try:
            overrides = carry(diagram.parameters(), variation, task.moves_object, b)
        except UnreachableError:
            outcomes[task.name] = UNREACHABLE
            continue
        overrides.update(by_name(b, (extra or {}).get(task.name, {})))
        outcomes[task.name] = _outcome(task, path, overrides, margins)
    return outcomes


def run_shipped(diagrams: Path, extra: Mapping[str, Mapping[str, Any]], tasks: tuple[Task, ...] = TASKS) -> dict[str, str]:
    """Each task's outcome at the shipped point, with ``extra`` ``--set`` values per task name
    (written by role, as for ``judge``)."""
    outcomes = {}
    for task in tasks:
        path = diagrams / f"{task.name}.yaml"
        b = TaskBlocks.of_diagram(blocks.load_diagram(path))
        outcomes[task.name] = _outcome(task, path, by_name(b, extra.get(task.name, {})))
    return outcomes


def by_name(b: TaskBlocks, values: Mapping[str, Any]) -> dict[str, Any]:
    """``--set`` values written by role, keyed as the diagram names its blocks."""
    return {b.resolve(key): value for key, value in values.items()}


def _outcome(task: Task, path: Path, overrides: dict[str, Any], margins: dict | None = None) -> str:
    results = blocks.simulate(blocks.load_diagram(path, overrides=overrides))
    outcome = task.outcome(results) if results.complete else f"run failed: {results.status}"
    if margins is not None:
        held = results.complete and outcome != "dropped" and task.margin is not None
        margins[task.name] = task.margin(results) if held else None
    return outcome
