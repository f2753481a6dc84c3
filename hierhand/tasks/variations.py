"""The paper's tasks carried onto other hands, objects and gains: the spread they are checked over.

A ``Variation`` is one point of ``SPREAD``: the object's mass and size, the link lengths,
friction, contact stiffness and damping, the reflex's integral gain and safety ratio, the
PD's and the suppresser's gains, and the grasp task's push. ``carry`` turns it into the
``--set`` values of one task diagram: the hand and gains changed, and every fingertip pose
the task names (the fingers' start poses ``q0`` and the trajectories' waypoints) moved
with the object's faces, so that the task stays the same task on the new hand: a tip
that touches a face keeps its gap to that face, a position along a face keeps its part of
the face, and the new joint angles come from the exact inverse kinematics. A task that
moves the object (``moves_object``) keeps its motion: its final waypoints are the same
rigid motion of the object applied to its carried start. A pose out of the new hand's
reach raises ``UnreachableError``; such a point is left out of the task's rate.
"""

from __future__ import annotations

import copy
import inspect
import math
from dataclasses import asdict, dataclass
from typing import Any, Mapping

import numpy as np

from ..control.grasp_reflex import GraspReflex
from ..control.manipulation_pd import ManipulationPD
from ..control.suppresser import Suppresser
from ..control.inverse_kinematics import finger_ik_near
from ..model import Hand, load_hand
from .summaries import TaskBlocks, rigid_target

SPREAD: dict[str, tuple[float, float]] = {
    "mass": (0.15, 0.45),  # kg
    "size": (0.8, 1.2),  # factor on each side of the object
    "links": (0.9, 1.1),  # factor on each link length
    "mu_s": (0.6, 1.4),  # static friction; mu_d = 0.9 mu_s
    "stiffness": (0.5, 2.0),  # factor on k_n and k_t, drawn log-uniformly
    "damping": (0.5, 2.0),  # factor on c_n and c_t, log-uniformly
    "ki": (0.5, 2.0),  # factor on the reflex's ki, log-uniformly
    "safety_ratio": (0.45, 0.75),
    "kp": (0.7, 1.4),  # factor on the PD's kp, log-uniformly
    "kd": (0.7, 1.4),  # factor on the PD's kd, log-uniformly
    "S_a": (0.7, 1.4),  # factor on the suppresser's S_a
    "S_b": (0.7, 1.4),  # factor on the suppresser's S_b
    "push": (1.0, 4.0),  # N, in a direction drawn uniformly
}
"""The ranges of the spread: those of the audit that found the tasks fragile (issue 24)."""
WIDE: dict[str, tuple[float, float]] = {
    **SPREAD,
    "mass": (0.15, 0.6),  # kg: up to twice the paper's object
    "mu_s": (0.6, 1.2),
    "ki": (0.4, 1.6),  # the gains +-60 %
    "kp": (0.4, 1.6),
    "kd": (0.4, 1.6),
    "S_a": (0.7, 1.3),  # the suppresser +-30 %
    "S_b": (0.7, 1.3),
    "push": (1.0, 5.0),
    "torque": (-0.05, 0.05),  # N m about the object's centre with the push (2 N at its edge)
}
"""A wider spread (issue 45): heavier and more slippery objects, larger pushes with a torque,
the gains +-60 % and the suppresser +-30 %."""
SPREADS = {"shipped": SPREAD, "wide": WIDE}
"""The spreads by name (``benchmarks/robustness.py --spread``)."""
LOG_UNIFORM = frozenset({"stiffness", "damping", "ki", "kp", "kd"})
MU_D_PER_MU_S = 0.9
"""The sliding friction of a varied hand, as a share of its static friction (the default hand's)."""


@dataclass(frozen=True)
class Variation:
    """One point of the spread (see ``SPREAD`` for the units and ranges)."""

    mass: float
    size: tuple[float, float]
    links: tuple[float, ...]
    mu_s: float
    stiffness: float
    damping: float
    ki: float
    safety_ratio: float
    kp: float
    kd: float
    S_a: float
    S_b: float
    push: tuple[float, float]
    torque: float = 0.0

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)

    @property
    def sees_slip(self) -> bool:
        """Whether the reflex can tell a sliding contact from a held one: a contact slides
        at |f_t| / f_n = mu_d, so a safety ratio at or above mu_d never calls for more
        squeeze while the object slides."""
        return self.safety_ratio < MU_D_PER_MU_S * self.mu_s


def draw(rng: np.random.Generator, spread: Mapping[str, tuple[float, float]] = SPREAD) -> Variation:
    """One point, each quantity uniform in its range (log-uniform for the factors of
    ``LOG_UNIFORM``), each side, link and push drawn on its own."""

    def value(name: str, n: int | None = None):
        lo, hi = spread[name]
        if name in LOG_UNIFORM:
            v = np.exp(rng.uniform(math.log(lo), math.log(hi), n))
        else:
            v = rng.uniform(lo, hi, n)
        return tuple(float(x) for x in v) if n else float(v)

    angle = rng.uniform(0.0, 2.0 * math.pi)
    magnitude = value("push")
    torque = value("torque") if "torque" in spread else 0.0  # drawn last: the other spreads' points stay
    return Variation(mass=value("mass"), size=value("size", 2), links=value("links", 9), mu_s=value("mu_s"),
                     stiffness=value("stiffness"), damping=value("damping"), ki=value("ki"),
                     safety_ratio=value("safety_ratio"), kp=value("kp"), kd=value("kd"), S_a=value("S_a"),
                     S_b=value("S_b"), push=(magnitude * math.cos(angle), magnitude * math.sin(angle)),
                     torque=torque)


def sample(n: int, seed: int, spread: Mapping[str, tuple[float, float]] = SPREAD) -> list[Variation]:
    """``n`` points drawn with ``numpy.random.default_rng(seed)``."""
    rng = np.random.default_rng(seed)
    return [draw(rng, spread) for _ in range(n)]


def varied_hand(sections: Mapping[str, Any], v: Variation) -> dict[str, Any]:
    """The hand file of the task's plant (its ``sections``) with the variation's object,
    links and contact (the links' centres of mass scaled with them; q0 still the old)."""
    hand = copy.deepcopy(dict(load_hand(dict(sections)).params.to_dict()))
    for f, finger in enumerate(hand["fingers"]):
        for i, link in enumerate(finger["links"]):
            scale = v.links[3 * f + i]
            link["length"] *= scale
            link["com"] = [link["com"][0] * scale, link["com"][1]]
    obj = hand["object"]
    obj["size"] = [obj["size"][0] * v.size[0], obj["size"][1] * v.size[1]]
    obj["mass"] = v.mass
    obj.pop("inertia", None)  # a uniform plate of the new mass and size
    contact = hand["contact"]
    contact.update(mu_s=v.mu_s, mu_d=MU_D_PER_MU_S * v.mu_s, k_n=contact["k_n"] * v.stiffness,
                   k_t=contact["k_t"] * v.stiffness, c_n=contact["c_n"] * v.damping, c_t=contact["c_t"] * v.damping)
    return hand


class FaceMap:
    """Tip centres near the old object carried to the same place relative to the new one:
    along an axis where the point is outside the object (beside a face), its distance from
    that face is kept; inside its extent, its part of the object's half size."""

    def __init__(self, old: Hand, new: Hand):
        self.c0, self.c1 = old.object_pose0[:2], new.object_pose0[:2]
        self.h0 = np.asarray(old.params.object.size, dtype=float) / 2
        self.h1 = np.asarray(new.params.object.size, dtype=float) / 2

    def __call__(self, point) -> np.ndarray:
        d = np.asarray(point[:2], dtype=float) - self.c0
        beside = np.abs(d) > self.h0
        moved = np.where(beside, np.sign(d) * (self.h1 + np.abs(d) - self.h0), d * self.h1 / self.h0)
        return self.c1 + moved


def carry(parameters: Mapping[str, Any], v: Variation, moves_object: bool, b: TaskBlocks) -> dict[str, Any]:
    """The ``--set`` values that put a task diagram (its ``parameters``) on the variation:
    the plant's hand, the gains, the start poses and waypoints carried (``FaceMap``), the
    push where the diagram has one (block ``push``). ``UnreachableError`` (naming the
    finger) when a pose is out of the new hand's reach."""
    old = load_hand(dict(parameters[b.plant]))
    sections = varied_hand(parameters[b.plant], v)
    carried = FaceMap(old, load_hand(sections))
    tips = old.tip_poses(old.q0)
    q0 = np.concatenate([_ik(load_hand(sections), f, (*carried(tips[f]), tips[f, 2]), old.q0[3 * f:3 * f + 3])
                         for f in range(3)])
    for f, finger in enumerate(sections["fingers"]):
        finger["q0"] = [float(x) for x in q0[3 * f:3 * f + 3]]
    new = load_hand(sections)
    manip, suppress, reflex = (parameters[b.block(role)] for role in ("manip", "suppress", "reflex"))
    overrides: dict[str, Any] = {
        **{f"{b.plant}.{section}": sections[section] for section in ("fingers", "object", "contact")},
        b.resolve("reflex.ki"): _number(_given(reflex, GraspReflex, "ki")) * v.ki,
        b.resolve("reflex.safety_ratio"): v.safety_ratio,
        b.resolve("manip.kp"): _scaled(_given(manip, ManipulationPD, "kp"), v.kp),
        b.resolve("manip.kd"): _scaled(_given(manip, ManipulationPD, "kd"), v.kd),
        b.resolve("suppress.S_a"): _scaled(_given(suppress, Suppresser, "S_a"), v.S_a),
        b.resolve("suppress.S_b"): _scaled(_given(suppress, Suppresser, "S_b"), v.S_b),
    }
    trajectories = copy.deepcopy(dict(manip.get("trajectories") or {}))
    if moves_object:
        _carry_motion(trajectories, old, new, carried)
    else:
        for spec in trajectories.values():
            spec["waypoints"] = [[w[0], *map(float, carried(w[1:3])), w[3]] for w in spec["waypoints"]]
    for name, spec in trajectories.items():
        f = new.names.index(name)
        for w in spec["waypoints"]:
            _ik(new, f, w[1:4], q0[3 * f:3 * f + 3])
    if trajectories:
        overrides[b.resolve("manip.trajectories")] = trajectories
    if "push" in parameters:
        after = list(parameters["push"].get("after", [0.0, 0.0, 0.0]))
        overrides["push.after"] = [v.push[0], v.push[1], after[2] + v.torque if len(after) > 2 else v.torque]
    return overrides


def _carry_motion(trajectories: dict, old: Hand, new: Hand, carried: FaceMap) -> None:
    """Each trajectory from its first waypoint to its last: the start carried, the end the
    same rigid motion of the object (about its centre) as on the old hand."""
    names = list(trajectories)
    first = {f: np.asarray(trajectories[f]["waypoints"][0], dtype=float) for f in names}
    last = {f: np.asarray(trajectories[f]["waypoints"][-1], dtype=float) for f in names}
    pose0 = old.object_pose0
    target = rigid_target(np.array([first[f][1:3] for f in names[:2]]), np.array([last[f][1:3] for f in names[:2]]),
                          pose0)
    turn, shift = target[2] - pose0[2], target[:2] - pose0[:2]
    c, s = math.cos(turn), math.sin(turn)
    rotation = np.array([[c, -s], [s, c]])
    centre = new.object_pose0[:2]
    for f in names:
        start = carried(first[f][1:3])
        end = rotation @ (start - centre) + centre + shift
        trajectories[f]["waypoints"] = [[float(first[f][0]), *map(float, start), float(first[f][3])],
                                        [float(last[f][0]), *map(float, end), float(first[f][3] + turn)]]


def _ik(hand: Hand, finger: int, pose, near) -> np.ndarray:
    return finger_ik_near(hand, finger, [float(x) for x in pose], near)


def _given(parameters: Mapping[str, Any], block_type: type, name: str) -> Any:
    """A block's parameter as the diagram gives it, else the block type's default."""
    if name in parameters:
        return parameters[name]
    return inspect.signature(block_type).parameters[name].default


def _number(value: Any) -> float:
    return float(np.mean(value))


def _scaled(value: Any, factor: float) -> Any:
    """A gain (scalar or per joint) times a factor, in the form it was given."""
    if np.ndim(value) == 0:
        return float(value) * factor
    return [float(x) * factor for x in value]
