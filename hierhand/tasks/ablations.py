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
    mechanism: bool = True
    """True for an addition to the paper's control mechanism (off in ``PAPER_ONLY``); False
    for a modelling choice the paper leaves open (the hand's armature, how the run starts),
    kept in the paper-only configuration but ablated all the same."""

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
             {"support.until": 0.0}, mechanism=False),
    Ablation("squeeze set up beforehand", "reflex.squeeze_from_weight false, min_force 0.1 N",
             "when the support lets go two fingers must carry m g by friction at once, m g / (2 x the ratio "
             "target) each (2.6 N for 0.3 kg), more than the integrator builds up in time: the squeeze is set "
             "up beforehand, from the object's weight, at least 3 N (a light object's squeeze must still hold "
             "the forefinger on against its withdrawal without the suppresser)",
             {"reflex.squeeze_from_weight": False, "reflex.min_force": 0.1}),
    Ablation("ratio target below sliding friction", "reflex.friction_cap false",
             "a contact slides at |f_t|/f_n = mu_d, so a safety ratio at or above mu_d never calls for more "
             "squeeze while the object slides: the reflex aims at most at 0.9 mu_d (no change where mu_d is "
             "above the safety ratio / 0.9, as at the shipped point)",
             {"reflex.friction_cap": False}),
    Ablation("reflex catches up on a shortfall", "reflex.catch_up 0 (integral control alone)",
             "a sudden push can take an object out of a light grasp before an integral loop at ki has built the "
             "squeeze the push needs: a quarter of a contact's shortfall is closed at once each hit (a half or all "
             "of it turned more objects in a tilted pinch)",
             {"reflex.catch_up": 0.0}),
    Ablation("armature 1e-4 kg m^2", "plant armature 0 on every joint",
             "a geared motor's reflected inertia; bare human-scale links leave a 10 ms PD almost no "
             "stiffness to work with",
             {f"plant.fingers.{f}.armature": [0.0, 0.0, 0.0] for f in range(3)}, mechanism=False),
    Ablation("PD gains matched to the 10 ms sample", "manip.discretization held",
             "kp and kd applied as they are and held for 10 ms are unstable once kd T / J > 2 (the shipped "
             "kd = 0.04 N m s/rad gives 4 on the distal joints)",
             {"manip.discretization": "held"}),
    Ablation("PD aimed at the squeezed contact", "manip.contact_compensation false",
             "a PD aimed at the surface pushes back against the squeeze, which the suppresser reads as voluntary "
             "motion against the grasp; aimed three times as deep as the tip sits, the PD adds a press the "
             "re-grasp's thumb-middle pinch needs",
             {"manip.contact_compensation": False}),
    Ablation("suppression low-passed (20 ms)", "suppress.time_constant 0 (the paper's static law)",
             "the sigmoid closes a loop through the grasping torque and the finger of gain |tau_g| S_a / 4, "
             "several times what the 10 ms PD tolerates",
             {"suppress.time_constant": 0.0}),
    Ablation("suppression signed against the grasp", "suppress.mode magnitude (the paper's prose, not its formula)",
             "the shipped mode is the paper's formula with tau_m signed against the grasp; by magnitude, "
             "voluntary motion pushing along the grasp suppresses it too",
             {"suppress.mode": "magnitude"}),
    Ablation("per-task S_b (0.1 N m but in the re-grasp)", "suppress.S_b 0.02 N m in the grasp and manipulation tasks",
             "the grasp and manipulation tasks use S_b = 0.1 N m: the PD's resistance to a push or its drive "
             "of the object is not to release a finger there",
             {"suppress.S_b": 0.02}, tasks=("grasp", "manipulate")),
)
"""The additions beyond the paper, in the order the report tables them: each one's switch
is declared here once (its ``--set`` values); the task diagrams switch it on."""

MECHANISMS = tuple(a for a in ABLATIONS if a.mechanism)
"""The additions to the paper's control mechanism: all off is the paper-only configuration."""


def by_name(name: str) -> Ablation:
    """The ablation called ``name`` (KeyError listing the names otherwise)."""
    for ablation in ABLATIONS:
        if ablation.name == name:
            return ablation
    raise KeyError(f"no addition called {name!r}; they are: {', '.join(a.name for a in ABLATIONS)}")


def switched_off(ablations) -> dict[str, dict[str, Any]]:
    """Per task name, the ``--set`` values (by role) that switch every one of ``ablations`` off."""
    extra: dict[str, dict[str, Any]] = {task: {} for task in ALL}
    for ablation in ablations:
        for task in ALL:
            extra[task].update(ablation.for_task(task))
    return extra


def paper_only(keep=()) -> dict[str, dict[str, Any]]:
    """Per task, the ``--set`` values of the paper-only configuration: every addition to the
    paper's mechanism off (``MECHANISMS``) except those named in ``keep``; the modelling
    choices (armature, the support) stay as shipped."""
    kept = set(keep)
    unknown = kept - {a.name for a in ABLATIONS}
    if unknown:
        raise KeyError(f"no addition called {', '.join(sorted(unknown))}")
    return switched_off([a for a in MECHANISMS if a.name not in kept])


PAPER_ONLY = "paper only"
"""The name of the paper-only configuration's row (``shipped_outcomes``)."""


def shipped_outcomes(diagrams: Path, ablations=ABLATIONS, tasks: tuple[Task, ...] = TASKS,
                     done: Callable[[], None] = lambda: None) -> list[dict[str, Any]]:
    """Each ablation's outcomes at the shipped point: rows ``{name, off, why, <task>: outcome}``
    (``""`` for success), first the shipped diagrams as they are, then the paper-only
    configuration (``paper_only``). ``done`` is called after
    each row (its tasks run)."""
    from .robustness import run_shipped

    rows = [{"name": "as shipped", "off": "", "why": "", **run_shipped(diagrams, {}, tasks)}]
    done()
    rows.append({"name": PAPER_ONLY, "off": "every addition to the mechanism (the rows marked *)",
                 "why": "the paper's controller alone, on this model of the hand",
                 **run_shipped(diagrams, paper_only(), tasks)})
    done()
    for ablation in ablations:
        rows.append({"name": ablation.name + (" *" if ablation.mechanism else ""), "off": ablation.off, "why": ablation.why,
                     **run_shipped(diagrams, ablation.extra(), tasks)})
        done()
    return rows


def smallest_set(succeeds: Callable[[frozenset[str]], float], tolerance: float = 0.0) -> frozenset[str]:
    """The additions to the mechanism one task keeps after backward elimination: from the
    shipped set, each addition in table order is switched off for good when the task's score
    with it off as well (``succeeds(names switched off)``: a success rate, or 1/0 at one
    point) falls by no more than ``tolerance`` below the shipped score."""
    everything = frozenset(a.name for a in MECHANISMS)
    full = succeeds(frozenset())
    off: frozenset[str] = frozenset()
    for addition in MECHANISMS:
        trial = off | {addition.name}
        if succeeds(trial) >= full - tolerance:
            off = trial
    return everything - off


def needed_at_shipped_point(diagrams: Path, task: Task, done: Callable[[], None] = lambda: None) -> frozenset[str]:
    """``smallest_set`` of one task at the shipped point (one run per addition tried)."""
    from .robustness import run_shipped

    def succeeds(off: frozenset[str]) -> float:
        outcome = run_shipped(diagrams, switched_off([a for a in MECHANISMS if a.name in off]), (task,))[task.name]
        done()
        return float(outcome == "")

    return smallest_set(succeeds)
