"""What the project adds to the paper's controller, each addition switched off alone.

``ABLATIONS`` lists every mechanism of the shipped task diagrams that the paper does not
have, with the ``--set`` values that switch it off, keyed by the role of the block
(``reflex.margin``: ``ctrl.reflex.margin`` in the task diagrams, see ``TaskBlocks.resolve``;
per task, the same for all where the task has the block) and why it is there. ``reproduce`` runs each at the shipped point and
tables the tasks' outcomes (``report.md``); ``benchmarks/robustness.py --ablations`` runs
them over the spread.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping

from .robustness import TASKS, Task

ALL = tuple(task.name for task in TASKS)


@dataclass(frozen=True)
class Ablation:
    """One addition beyond the paper: its name, what switching it off means, why it is there."""

    name: str
    off: str
    why: str
    overrides: Mapping[str, Any]
    tasks: tuple[str, ...] = field(default=ALL)

    def for_task(self, task: str) -> dict[str, Any]:
        """The ``--set`` values of this ablation in one task's diagram."""
        return dict(self.overrides) if task in self.tasks else {}

    def extra(self) -> dict[str, dict[str, Any]]:
        """Per task name, the values ``robustness.judge`` applies."""
        return {task: self.for_task(task) for task in ALL}


ABLATIONS = (
    Ablation("load and gravity feedforward", "manip.gravity_compensation and load_compensation false",
             "the soft 10 ms PD alone lets a held object sag by millimetres and the fingers carry the "
             "object's weight with posture errors",
             {"manip.gravity_compensation": False, "manip.load_compensation": False}),
    Ablation("5 % margin", "reflex.margin 0",
             "an integral loop approaches its target from one side only: aimed at the safety ratio itself, "
             "|f_t|/f_n stays just above it",
             {"reflex.margin": 0.0}),
    Ablation("hand-over to voluntary motion", "reflex.follow_suppression false (the paper's reflex)",
             "the anti-windup that remains: a finger the suppresser is switching off no longer drives the "
             "reflex's one integrator, nor shares its squeeze; without it the withdrawing forefinger's climbing "
             "|f_t|/f_n winds the squeeze of every finger up",
             {"reflex.follow_suppression": False}),
    Ablation("object support until 0.1 s", "support.until 0",
             "the paper starts with the object held; here the fingers start 0.1 mm off it and close while a "
             "support carries its weight",
             {"support.until": 0.0}),
    Ablation("minimum squeeze of 3 N", "reflex.min_force 0.1 N",
             "at the hand-over two fingers must carry m g by friction at once: m g / (2 x 0.6) = 2.45 N each, "
             "more than the integrator builds up in time",
             {"reflex.min_force": 0.1}),
    Ablation("armature 1e-4 kg m^2", "plant armature 0 on every joint",
             "a geared motor's reflected inertia; bare human-scale links leave a 10 ms PD almost no "
             "stiffness to work with",
             {f"plant.fingers.{f}.armature": [0.0, 0.0, 0.0] for f in range(3)}),
    Ablation("PD gains matched to the 10 ms sample", "manip.discretization held",
             "kp and kd applied as they are and held for 10 ms are unstable once kd T / J > 2 (the shipped "
             "kd = 0.04 N m s/rad gives 4 on the distal joints)",
             {"manip.discretization": "held"}),
    Ablation("PD aimed at the squeezed contact", "manip.contact_compensation false",
             "a PD aimed at the surface pushes back against the squeeze (fn / k_n deep), which the suppresser "
             "reads as voluntary motion against the grasp",
             {"manip.contact_compensation": False}),
    Ablation("suppression low-passed (20 ms)", "suppress.time_constant 0 (the paper's static law)",
             "the sigmoid closes a loop through the grasping torque and the finger of gain |tau_g| S_a / 4, "
             "several times what the 10 ms PD tolerates",
             {"suppress.time_constant": 0.0}),
    Ablation("suppression by |tau_m|", "suppress.mode magnitude (the paper's prose, not its formula)",
             "the shipped mode is the paper's formula with tau_m signed against the grasp; by magnitude, "
             "voluntary motion pushing along the grasp suppresses it too",
             {"suppress.mode": "magnitude"}),
    Ablation("the re-grasp's S_b in every task", "suppress.S_b 0.02 N m in the grasp and manipulation tasks",
             "the grasp and manipulation tasks use S_b = 0.1 N m: the PD's resistance to a push or its drive "
             "of the object is not to release a finger there",
             {"suppress.S_b": 0.02}, tasks=("grasp", "manipulate")),
)
"""The additions beyond the paper, in the order the report tables them."""


def shipped_outcomes(diagrams: Path, ablations=ABLATIONS, tasks: tuple[Task, ...] = TASKS,
                     done: Callable[[], None] = lambda: None) -> list[dict[str, Any]]:
    """Each ablation's outcomes at the shipped point: rows ``{name, off, why, <task>: outcome}``
    (``""`` for success), first the shipped diagrams as they are. ``done`` is called after
    each row (its tasks run)."""
    from .robustness import run_shipped

    rows = [{"name": "as shipped", "off": "", "why": "", **run_shipped(diagrams, {}, tasks)}]
    done()
    for ablation in ablations:
        rows.append({"name": ablation.name, "off": ablation.off, "why": ablation.why,
                     **run_shipped(diagrams, ablation.extra(), tasks)})
        done()
    return rows
