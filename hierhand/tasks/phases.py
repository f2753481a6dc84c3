"""The phases of a hand task, read from its diagram's blocks, in words for a frame's title.

``task_phases(run_info)`` finds them in the blocks' parameters as run.json keeps them: an
``ObjectSupport``'s hand-over time, a ``Step``'s time, and each ``ManipulationPD``
fingertip trajectory's span from its first to its last waypoint, worded by what the tip
does (moves in, withdraws, moves the object). ``phase_at(phases, t)`` says which applies
at time ``t``; nothing is keyed to a diagram's name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

FINGER_WORDS = {"thumb": "thumb", "fore": "forefinger", "middle": "middle finger", "ring": "ring finger",
                "little": "little finger"}
"""How the hand's finger names read in a sentence (other names as they are)."""
MOVE_MM = 5.0
"""A trajectory whose tip ends this much (mm) nearer the object's centre than it starts
moves in; this much farther, it withdraws."""
OBJECT_MOVED_MM = 1.0


@dataclass(frozen=True)
class Phase:
    """Something the diagram makes happen from ``start`` to ``end`` (equal for an instant):
    ``during`` reads while it lasts, ``after`` once it is over."""

    start: float
    end: float
    during: str
    after: str
    fingers: tuple[str, ...] = ()
    verb: str = ""


def task_phases(info: dict, hand=None, object_pose: Callable[[float], np.ndarray] | None = None) -> list[Phase]:
    """The phases of a task from a run's ``run.json`` info (``block_types`` and
    ``parameters``): per ``ObjectSupport`` the object on its support until ``until``; per
    ``Step`` its switch at ``time``; per ``ManipulationPD`` fingertip trajectory the span
    from its first to its last waypoint, as "moving in", "withdrawing" (the tip ends
    ``MOVE_MM`` nearer or farther from the object's centre than it starts), "moving the
    object" (the object moves meanwhile) or "moving". ``object_pose(t)``: the object's
    pose (x, y, angle) at t, from the run; without it the hand's initial object pose.
    Trajectories over the same span with the same verb are one phase ("thumb and
    forefinger moving the object")."""
    types = info.get("block_types") or {}
    params = info.get("parameters") or {}
    phases: list[Phase] = []
    moves: dict[tuple[float, float, str], list[str]] = {}
    for name, kind in types.items():
        p = params.get(name) or {}
        if kind == "ObjectSupport":
            until = _number(p.get("until", 0.1))
            if until is not None:
                phases.append(Phase(0.0, until, f"object on its support (released at {until:g} s)",
                                    "support released"))
        elif kind == "Step":
            at = _number(p.get("time"))
            if at is not None:
                phases.append(Phase(at, at, "", f"{name}: step at {at:g} s"))
        elif kind == "ManipulationPD":
            for finger, spec in (p.get("trajectories") or {}).items():
                w = _waypoints(spec)
                if w is None or len(w) < 2:
                    continue
                t0, t1 = float(w[0, 0]), float(w[-1, 0])
                verb = _verb(w, hand, object_pose)
                moves.setdefault((t0, t1, verb), []).append(finger)
    done = {"moving in": "in place", "withdrawing": "withdrawn", "moving the object": "done moving the object",
            "moving": "done moving"}
    for (t0, t1, verb), fingers in moves.items():
        who = _and([FINGER_WORDS.get(f, f) for f in fingers])
        phases.append(Phase(t0, t1, f"{who} {verb} ({t0:g}-{t1:g} s)", f"{who} {done[verb]}", tuple(fingers), verb))
    return sorted(phases, key=lambda ph: (ph.start, ph.end))


def phase_at(phases: Sequence[Phase], t: float, in_contact: Callable[[str], bool] | None = None) -> str:
    """The phase text at time ``t``: what is under way (joined by "; "), else what ended
    last, else "start". ``in_contact(finger)``: whether a finger touches the object at
    ``t``; with it a withdrawal that is over says so when the finger has not let go, and
    a move in when the finger has not arrived."""
    eps = 1e-9
    active = [ph.during for ph in phases if ph.start - eps <= t < ph.end - eps and ph.during]
    if active:
        return "; ".join(active)
    over = [ph for ph in phases if ph.end - eps <= t]
    if not over:
        return "start"
    last = max(ph.end for ph in over)
    return "; ".join(_after(ph, in_contact) for ph in over if ph.end == last)


def _after(phase: Phase, in_contact) -> str:
    if in_contact is None or not phase.fingers:
        return phase.after
    if phase.verb == "withdrawing":
        held = [f for f in phase.fingers if in_contact(f)]
        if held:
            return (f"{_and([FINGER_WORDS.get(f, f) for f in held])} told to withdraw "
                    f"(by {phase.end:g} s) but still in contact")
    if phase.verb == "moving in":
        away = [f for f in phase.fingers if not in_contact(f)]
        if away:
            return f"{_and([FINGER_WORDS.get(f, f) for f in away])} moved in (by {phase.end:g} s) but not in contact"
    return phase.after


def _number(value) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    return float(value)


def _waypoints(spec) -> np.ndarray | None:
    rows = spec.get("waypoints") if isinstance(spec, dict) else spec
    try:
        w = np.asarray(rows, dtype=float)
    except (TypeError, ValueError):
        return None
    return w if w.ndim == 2 and w.shape[1] == 4 and np.isfinite(w).all() else None


def _verb(w: np.ndarray, hand, object_pose) -> str:
    t0, t1 = float(w[0, 0]), float(w[-1, 0])
    if object_pose is not None:
        p0, p1 = np.asarray(object_pose(t0), float), np.asarray(object_pose(t1), float)
    elif hand is not None:
        p0 = p1 = np.asarray(hand.object_pose0, float)
    else:
        return "moving"
    d0 = math.hypot(*(w[0, 1:3] - p0[:2]))
    d1 = math.hypot(*(w[-1, 1:3] - p1[:2]))
    if d1 < d0 - MOVE_MM * 1e-3:
        return "moving in"
    if d1 > d0 + MOVE_MM * 1e-3:
        return "withdrawing"
    moved = 1e3 * math.hypot(*(p1[:2] - p0[:2])) >= OBJECT_MOVED_MM or abs(math.degrees(p1[2] - p0[2])) >= 1.0
    return "moving the object" if moved else "moving"


def _and(words: list[str]) -> str:
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]
