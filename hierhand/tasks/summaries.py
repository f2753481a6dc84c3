"""Summaries of the paper's tasks: the numbers each task is judged by, from a run's Results.

Every function takes the Results of a task diagram and, optionally, its blocks by role
(``TaskBlocks``; by default found in the run's block types), so the same numbers serve the
reproduction, the tests and, as the scalar measures of ``measures``, sweeps of any diagram
that has the blocks a number needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from blocks import Results

SAFETY_RATIO = 0.6
"""The paper's friction safety ratio, the reflex's default."""
DROP_DISTANCE = 0.02
"""An object that ends more than 2 cm below where it started has been dropped."""

THUMB, FORE, MIDDLE = 0, 1, 2

CONTACT_FADE = 0.005
"""Seconds before a separation left out of the torque window: the contact force fades out
over the last milliseconds and the reflex drops the finger, so its torque there says nothing
about suppression."""


ROLES = {"reflex": "GraspReflex", "manip": "ManipulationPD", "suppress": "Suppresser", "support": "ObjectSupport"}
"""The blocks a task diagram may have besides its plant, by role, and the type of each."""
PLANTS = ("HandPlant", "FMU")
"""What a task's plant is: the hand plant, or an FMU exported from it."""


@dataclass(frozen=True)
class TaskBlocks:
    """The blocks of a task diagram by role, found by their types (``of``): the plant and at
    most one each of ``ROLES``. The names are the diagram's own: ``plant`` and, inside the
    shipped controller subsystem, ``ctrl.reflex``, ``ctrl.manip`` and ``ctrl.suppress``."""

    plant: str
    reflex: str | None = None
    manip: str | None = None
    suppress: str | None = None
    support: str | None = None

    @classmethod
    def of(cls, block_types: Mapping[str, str], parameters: Mapping[str, Any]) -> "TaskBlocks":
        """The roles of a diagram's blocks (``block_types``: name -> type, as run.json keeps
        them). The plant is the block the controllers' ``hand`` names, else the one
        HandPlant. ValueError when a role has two blocks or there is no plant."""
        found: dict[str, str | None] = {}
        for role, kind in ROLES.items():
            names = [name for name, t in block_types.items() if t == kind]
            if len(names) > 1:
                raise ValueError(f"a task diagram has at most one {kind}; this one has {len(names)} "
                                 f"({', '.join(names)})")
            found[role] = names[0] if names else None
        hands = sorted({parameters.get(name, {}).get("hand") for name in found.values() if name is not None} - {None})
        plants = [name for name, t in block_types.items() if t == "HandPlant"]
        if len(hands) > 1:
            raise ValueError(f"the task's controllers model different hands: their 'hand' names {', '.join(hands)}")
        if hands and block_types.get(hands[0]) in PLANTS:
            plant = hands[0]
        elif not hands and len(plants) == 1:
            plant = plants[0]
        elif len(plants) > 1:
            raise ValueError(f"the diagram has {len(plants)} HandPlants ({', '.join(plants)}) and no controller "
                             "whose 'hand' says which one is the task's")
        else:
            raise ValueError("a hand task needs its plant: a HandPlant block, or the exported plant FMU that "
                             "its controllers' 'hand' names; this diagram has none")
        return cls(plant=plant, **found)

    @classmethod
    def of_run(cls, results: Results) -> "TaskBlocks":
        """The roles of the blocks of the diagram a run came from (its run.json)."""
        return cls.of(results.info.get("block_types", {}), results.info.get("parameters", {}))

    @classmethod
    def of_diagram(cls, diagram) -> "TaskBlocks":
        """The roles of a loaded diagram's blocks."""
        return cls.of({name: spec.type_name for name, spec in diagram.blocks.items()}, diagram.parameters())

    def block(self, role: str) -> str:
        """The name of the block in ``role``; ValueError if the diagram has none."""
        name = self.plant if role == "plant" else getattr(self, role)
        if name is None:
            raise ValueError(f"the task needs a {ROLES[role]} block; the diagram has none")
        return name

    def signal(self, role: str, port: str) -> str:
        """The name of a role's output signal, e.g. ``signal("reflex", "tau_g")``."""
        return f"{self.block(role)}.{port}"

    def resolve(self, key: str) -> str:
        """A ``--set`` key written by role (``reflex.margin``) as the diagram names it."""
        role, _, rest = key.partition(".")
        return f"{self.block(role)}.{rest}"


def handover_time(parameters: Mapping[str, Any], b: TaskBlocks) -> float | None:
    """When the support lets the object go (the support's ``until``), or None for a
    diagram without one."""
    if b.support is None:
        return None
    value = parameters.get(b.support, {}).get("until")
    return None if value is None else float(value)


def withdrawal(parameters: Mapping[str, Any], b: TaskBlocks) -> tuple[float, float]:
    """(start, end) of the forefinger's trajectory in a re-grasp diagram."""
    waypoints = parameters[b.block("manip")]["trajectories"]["fore"]["waypoints"]
    return float(waypoints[0][0]), float(waypoints[-1][0])


def safety_ratio_of(results: Results, b: TaskBlocks | None = None) -> float:
    """The safety ratio the run's reflex kept to (its parameter, or the paper's 0.6)."""
    b = b or TaskBlocks.of_run(results)
    return float(results.info.get("parameters", {}).get(b.reflex, {}).get("safety_ratio", SAFETY_RATIO))


def _signal(results: Results, name: str) -> tuple[np.ndarray, np.ndarray]:
    try:
        return results[name]
    except KeyError as exc:
        raise ValueError(f"the task needs the logged signal {exc}") from None


def object_dropped(results: Results, b: TaskBlocks | None = None) -> bool:
    """Dropped: fewer than two fingers touch it at the end, or it fell by DROP_DISTANCE."""
    b = b or TaskBlocks.of_run(results)
    _, contact = _signal(results, f"{b.plant}.contact")
    _, obj = _signal(results, f"{b.plant}.obj")
    return bool(contact[-1].sum() < 2 or obj[0, 1] - obj[-1, 1] > DROP_DISTANCE)


def first_time(t: np.ndarray, condition: np.ndarray, after: float = -math.inf) -> float | None:
    """First sample time after ``after`` where ``condition`` holds, or None."""
    hits = np.flatnonzero(condition & (t > after))
    return float(t[hits[0]]) if hits.size else None


def grasp_summary(results: Results, disturbance_time: float, b: TaskBlocks | None = None,
                  fingers: tuple[int, ...] = (THUMB, FORE), steady_window: float = 0.2,
                  handover_time: float | None = None) -> dict:
    """Peak |f_t|/f_n after the disturbance, when it is back under the run's safety ratio
    for good, its maximum over the last ``steady_window`` seconds, how far the object moved,
    and the peak while the fingers close (before ``handover_time``, when the support lets
    the object go; None without one)."""
    b = b or TaskBlocks.of_run(results)
    safety = safety_ratio_of(results, b)
    t, ratio = _signal(results, f"{b.plant}.ratio")
    worst = ratio[:, list(fingers)].max(axis=1)
    after = t >= disturbance_time
    peak = float(worst[after].max())
    above = np.flatnonzero(after & (worst > safety))
    if above.size == 0:
        recovery = 0.0
    elif above[-1] + 1 < t.size:
        recovery = float(t[above[-1] + 1] - disturbance_time)
    else:
        recovery = None
    steady = t >= t[-1] - steady_window
    t_obj, obj = _signal(results, f"{b.plant}.obj")
    i0 = max(int(np.searchsorted(t_obj, disturbance_time)) - 1, 0)  # the last pose before the push
    closing = t < handover_time if handover_time is not None else np.zeros(t.size, dtype=bool)
    return {
        "safety_ratio": safety,
        "disturbance_time_s": float(disturbance_time),
        "peak_ratio": peak,
        "recovery_time_s": recovery,
        "steady_ratio_max": float(worst[steady].max()),
        "closing_peak_ratio": float(worst[closing].max()) if closing.any() else None,
        "object_displacement_m": float(np.linalg.norm(obj[-1, :2] - obj[i0, :2])),
        "object_dropped": object_dropped(results, b),
    }


def rigid_target(start_tips: np.ndarray, end_tips: np.ndarray, start_pose: np.ndarray) -> np.ndarray:
    """The object pose that moves rigidly with two fingertips from ``start_tips`` (2, 2) to
    ``end_tips``: the rotation of the line between them, then the matching translation."""
    d0, d1 = start_tips[1] - start_tips[0], end_tips[1] - end_tips[0]
    angle = math.atan2(d1[1], d1[0]) - math.atan2(d0[1], d0[0])
    c, s = math.cos(angle), math.sin(angle)
    rot = np.array([[c, -s], [s, c]])
    centre = end_tips.mean(axis=0) + rot @ (start_pose[:2] - start_tips.mean(axis=0))
    return np.array([centre[0], centre[1], start_pose[2] + angle])


def manipulation_summary(results: Results, trajectories: dict, initial_pose: np.ndarray,
                         b: TaskBlocks | None = None, fingers: tuple[str, str] = ("thumb", "fore")) -> dict:
    """Target pose implied by the two fingertip trajectories, the pose reached, the errors,
    and the largest |f_t|/f_n once the grasp has settled (from the first waypoint on)."""
    b = b or TaskBlocks.of_run(results)
    first = [np.asarray(trajectories[f]["waypoints"][0], dtype=float) for f in fingers]
    last = [np.asarray(trajectories[f]["waypoints"][-1], dtype=float) for f in fingers]
    target = rigid_target(np.array([w[1:3] for w in first]), np.array([w[1:3] for w in last]),
                          np.asarray(initial_pose, dtype=float))
    settle = min(w[0] for w in first)
    t, ratio = _signal(results, f"{b.plant}.ratio")
    _, obj = _signal(results, f"{b.plant}.obj")
    final = obj[-1]
    return {
        "safety_ratio": safety_ratio_of(results, b),
        "max_ratio_after_settle": float(ratio[t >= settle][:, [THUMB, FORE]].max()),
        "target_pose": [float(v) for v in target],
        "final_pose": [float(v) for v in final],
        "position_error_m": float(np.linalg.norm(final[:2] - target[:2])),
        "angle_error_rad": float(abs(final[2] - target[2])),
        "object_dropped": object_dropped(results, b),
    }


def regrasp_events(results: Results, b: TaskBlocks | None = None) -> dict:
    """When the middle finger first touches the object, when the forefinger then lets go,
    whether it stays off, and whether the object was dropped (from the contact flags)."""
    b = b or TaskBlocks.of_run(results)
    t, contact = _signal(results, f"{b.plant}.contact")
    middle = first_time(t, contact[:, MIDDLE] > 0)
    separation = first_time(t, contact[:, FORE] == 0, after=middle) if middle is not None else None
    return {
        "middle_contact_time_s": middle,
        "fore_separation_time_s": separation,
        "fore_stays_off": bool(separation is not None and not contact[t > separation, FORE].any()),
        "object_dropped": object_dropped(results, b),
    }


def holding_kept(results: Results, since: float | None, b: TaskBlocks | None = None,
                 quantile: float | None = None) -> float | None:
    """The smallest share of its grasp torque that any joint of the holding fingers (thumb
    and middle) kept through the suppresser from ``since`` on (or that ``quantile`` of the
    shares, e.g. 0.01: what they kept 99 % of the time), over the samples where that joint's
    grasp torque is at least a tenth of the largest among those joints; None without such
    samples."""
    b = b or TaskBlocks.of_run(results)
    if since is None:
        return None
    t, tau_g = _signal(results, b.signal("reflex", "tau_g"))
    _, applied = _signal(results, b.signal("suppress", "tau_g_eff"))
    joints = [*range(3 * THUMB, 3 * THUMB + 3), *range(3 * MIDDLE, 3 * MIDDLE + 3)]
    g, a = tau_g[t >= since][:, joints], applied[t >= since][:, joints]
    large = np.abs(g) >= 0.1 * np.abs(g).max() if g.size and np.abs(g).max() > 0 else np.zeros(g.shape, bool)
    if not large.any():
        return None
    kept = a[large] / g[large]
    return float(kept.min() if quantile is None else np.quantile(kept, quantile))


FACTOR_LEAVES = 0.9
"""The suppression factor below which the sigmoid counts as acting (Fig. 14)."""


def regrasp_summary(results: Results, withdrawal: tuple[float, float], b: TaskBlocks | None = None,
                    joint: int = 3 * FORE) -> dict:
    """``regrasp_events``, ``holding_kept`` from the middle finger's first contact, the
    paper's Fig. 14 on the forefinger's ``joint`` (its MP joint by default) while it
    withdraws, and how it slides before it lets go. Fig. 14: the applied grasp torque
    (``suppress.tau_g_eff``) at the start of the withdrawal, its peak and its last value
    CONTACT_FADE before separation, the share of it gone by then, its correlation with
    |tau_m| over that window (negative: the grasp torque falls as the manipulation torque
    grows), the suppresser's factor (applied over reflex torque) there, and when the factor
    first fell below FACTOR_LEAVES. ``withdrawal`` is the forefinger trajectory's (start,
    end) time."""
    b = b or TaskBlocks.of_run(results)
    events = regrasp_events(results, b)
    t_g, tau_g_eff = _signal(results, b.signal("suppress", "tau_g_eff"))
    _, tau_g = _signal(results, b.signal("reflex", "tau_g"))
    _signal(results, b.signal("manip", "tau_m"))  # a clear error if it was not logged
    held_m = np.abs(results.held(b.signal("manip", "tau_m"), t_g)[:, joint])
    separation = events["fore_separation_time_s"]
    end = separation - CONTACT_FADE if separation is not None else math.inf
    window = (t_g >= withdrawal[0]) & (t_g < end)
    grasp, manipulation = tau_g_eff[window, joint], held_m[window]
    reflex = tau_g[window, joint]
    factor = np.divide(grasp, reflex, out=np.ones_like(grasp), where=reflex != 0)
    varied = grasp.size > 2 and np.ptp(grasp) > 0 and np.ptp(manipulation) > 0
    acting = np.flatnonzero(factor < FACTOR_LEAVES)
    leaves = float(t_g[window][acting[0]]) if acting.size else None
    return {
        **events,
        "holding_grasp_torque_kept": holding_kept(results, events["middle_contact_time_s"], b),
        "holding_grasp_torque_kept_99": holding_kept(results, events["middle_contact_time_s"], b, quantile=0.01),
        "withdrawal_start_s": float(withdrawal[0]),
        "withdrawal_end_s": float(withdrawal[1]),
        "fore_grasp_torque_at_withdrawal_Nm": float(grasp[0]) if grasp.size else None,
        "fore_grasp_torque_peak_Nm": float(grasp.max()) if grasp.size else None,
        "fore_grasp_torque_last_Nm": float(grasp[-1]) if grasp.size else None,
        "fore_grasp_torque_gone": float(1.0 - grasp[-1] / grasp[0]) if grasp.size and grasp[0] else None,
        "fore_reflex_torque_last_Nm": float(reflex[-1]) if grasp.size else None,
        "fore_suppression_factor_last": float(factor[-1]) if grasp.size else None,
        "fore_factor_leaves_s": leaves,
        "fore_manipulation_torque_last_Nm": float(manipulation[-1]) if grasp.size else None,
        "grasp_vs_manipulation_correlation": float(np.corrcoef(grasp, manipulation)[0, 1]) if varied else None,
        **sliding_before_separation(results, withdrawal[0], separation, b),
    }


def sliding_before_separation(results: Results, start: float, separation: float | None,
                              b: TaskBlocks | None = None) -> dict:
    """How the forefinger's contact went between the start of its withdrawal and its
    separation: its largest |f_t|/f_n, and how long it was above the safety ratio and at
    the sliding limit (mu_d, where the contact law clips a sliding contact)."""
    b = b or TaskBlocks.of_run(results)
    t, ratio = _signal(results, f"{b.plant}.ratio")
    window = (t >= start) & (t < (separation if separation is not None else math.inf))
    fore = ratio[window, FORE]
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    mu_d = float(results.info.get("parameters", {}).get(b.plant, {}).get("contact", {}).get("mu_d", 0.9))
    return {
        "fore_ratio_peak_before_separation": float(fore.max()) if fore.size else None,
        "fore_above_safety_before_separation_s": float(np.count_nonzero(fore > safety_ratio_of(results, b)) * step),
        "fore_sliding_before_separation_s": float(np.count_nonzero(fore >= mu_d * (1 - 1e-9)) * step),
    }


def ratio_excursions(results: Results, since: float, fingers: tuple[int, ...], b: TaskBlocks | None = None,
                     until: float = math.inf) -> dict[int, dict]:
    """Per finger, over [since, until): its largest |f_t|/f_n while in contact and how long
    it was above the run's safety ratio."""
    b = b or TaskBlocks.of_run(results)
    t, ratio = _signal(results, f"{b.plant}.ratio")
    window = (t >= since) & (t < until)
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    safety = safety_ratio_of(results, b)
    return {f: {"peak": float(ratio[window, f].max()) if window.any() else None,
                "above_safety_s": float(np.count_nonzero(ratio[window, f] > safety) * step)} for f in fingers}


def reaction_times(results: Results, since: float, fingers: tuple[int, ...] = (THUMB, FORE),
                   b: TaskBlocks | None = None, window: float = 0.2, part: float = 0.1,
                   label: str = "reacts") -> dict:
    """When the grasp torque (the reflex's) and the manipulation torque (the PD's) first
    react to a disturbance at ``since`` (the paper's Fig. 10): per torque, the first time
    after ``since`` at which some joint of the ``fingers`` has moved from its value just
    before by ``part`` of its largest move within ``window`` (keys
    ``grasp_torque_<label>_s``, ``manipulation_torque_<label>_s``); None where it does not move."""
    b = b or TaskBlocks.of_run(results)
    out = {}
    for key, signal in (("grasp", b.signal("reflex", "tau_g")), ("manipulation", b.signal("manip", "tau_m"))):
        t, tau = _signal(results, signal)
        joints = [j for f in fingers for j in range(3 * f, 3 * f + 3)]
        before = tau[max(int(np.searchsorted(t, since)) - 1, 0), joints]
        after = (t >= since) & (t <= since + window)
        moved = np.abs(tau[after][:, joints] - before)
        largest = moved.max(axis=0) if moved.size else np.zeros(len(joints))
        reacting = np.flatnonzero(np.any((moved >= part * largest) & (largest > 0), axis=1))
        out[f"{key}_torque_{label}_s"] = float(t[after][reacting[0]] - since) if reacting.size else None
    return out


POSITION_TOLERANCE = 1e-3
"""m: the manipulated object ends within this of its target position ..."""
ANGLE_TOLERANCE = math.radians(1.0)
"""... and within this of its target angle."""


def grasp_succeeded(summary: dict) -> bool:
    """The grasp task as the paper describes it: the object is held through the push and
    |f_t|/f_n is back under the safety ratio by the end (over the last 0.2 s)."""
    return not summary["object_dropped"] and summary["steady_ratio_max"] <= summary["safety_ratio"]


def manipulation_succeeded(summary: dict) -> bool:
    """The manipulation task as the paper describes it: the object reaches its new position
    and posture (``POSITION_TOLERANCE``, ``ANGLE_TOLERANCE``) with |f_t|/f_n within the
    safety ratio once the grasp has settled, and is not dropped."""
    return (not summary["object_dropped"] and summary["position_error_m"] <= POSITION_TOLERANCE
            and summary["angle_error_rad"] <= ANGLE_TOLERANCE
            and summary["max_ratio_after_settle"] <= summary["safety_ratio"])


def regrasp_succeeded(summary: dict) -> bool:
    """The re-grasp as the paper describes it: the middle finger touches, the forefinger
    then lets go while it withdraws and stays off, and the object is not dropped."""
    sep = summary["fore_separation_time_s"]
    return (summary["middle_contact_time_s"] is not None and sep is not None
            and summary["withdrawal_start_s"] <= sep <= summary["withdrawal_end_s"]
            and summary["fore_stays_off"] and not summary["object_dropped"])
