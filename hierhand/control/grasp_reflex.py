"""The grasping reflex (the paper's lower level): hold the object with internal forces.

At every hit (1 ms in the paper) the reflex

1. finds the fingers in contact from the fingertip force sensors (``fn``), so it follows
   the grasp through a re-grasp; fingers listed in ``grasp`` that have not touched yet
   are pushed towards the others with ``approach_force`` until they do;
2. takes the internal ("squeeze") forces among those fingertips (Yoshikawa-Nagai): the
   internal force nearest to every finger pushing along its contact normal,
   ``(I - G^+ G) n``; for two contacts this is the squeeze along their line;
3. finds the contact that is most short of the normal force it needs,
   ``need_i = max(min_force * w_i, |f_t,i| / ratio_target)`` (the sensor form of the
   friction scaling at the safety ratio);
4. realises it with integral control of one grasp force scale ``s``:
   ``s += ki * dt * max_i (need_i - fn_i) / (n_i . g_i)``, the fingertip forces ``s g_i``
   mapped to joint torques by ``J_i^T``. One integrator for the whole grasp, not one per
   finger: in a pinch both normal forces respond alike to a difference between the
   fingers' pushes (the object just moves), so per-finger integrators would drift apart.

Why a margin: an integral loop approaches its target exponentially, so aiming exactly at
the safety ratio would leave ``|f_t| / f_n`` just above it for ever; aiming at
``safety_ratio / (1 + margin)`` brings it below the safety ratio in finite time.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from blocks import Block

from ..model import load_hand
from .internal_forces import internal_directions, project_internal


def finger_indices(names: tuple[str, ...], chosen: Any, what: str) -> np.ndarray:
    """Boolean mask over the hand's fingers for a list of finger names."""
    chosen = [chosen] if isinstance(chosen, str) else list(chosen or [])
    unknown = [c for c in chosen if c not in names]
    if unknown:
        raise ValueError(f"{what}: unknown finger(s) {', '.join(map(str, unknown))}; fingers are "
                         f"{', '.join(names)}")
    return np.array([n in chosen for n in names])


class GraspReflex(Block):
    """Grasping reflex: internal forces among the fingers in contact, kept inside the
    friction cone at the safety ratio by integral control of the fingertip forces."""

    type_name = "GraspReflex"
    param_docs = {
        "gravity": "hand file section (the reflex uses the finger geometry; default hand if omitted)",
        "fingers": "hand file section: the three fingers",
        "object": "hand file section (unused by the reflex; accepted so one params_file serves all blocks)",
        "contact": "hand file section (unused by the reflex)",
        "grasp": "fingers that close on the object at the start, e.g. [thumb, fore]",
        "ki": "integral gain of the fingertip force loop, 1/s (30-100 gives a 10-30 ms recovery)",
        "safety_ratio": "largest |f_t|/f_n the reflex allows (the paper's 0.6)",
        "margin": "the loop aims at safety_ratio / (1 + margin), so that it settles below the safety ratio",
        "min_force": "smallest normal force per contact, N, even without tangential load",
        "max_force": "largest commanded force per fingertip, N (anti-windup limit)",
        "approach_force": "force, N, that pushes a 'grasp' finger towards the others until it touches",
        "contact_threshold": "normal force, N, above which a finger counts as in contact",
    }

    def __init__(self, gravity=None, fingers=None, object=None, contact=None,  # noqa: A002
                 grasp=("thumb", "fore"), ki: float = 50.0, safety_ratio: float = 0.6,
                 margin: float = 0.05, min_force: float = 1.0, max_force: float = 30.0,
                 approach_force: float = 0.5, contact_threshold: float = 0.05):
        self.hand = load_hand({"gravity": gravity, "fingers": fingers, "object": object, "contact": contact})
        self.initial = finger_indices(self.hand.names, grasp, "grasp")
        for name, value in (("ki", ki), ("safety_ratio", safety_ratio), ("min_force", min_force),
                            ("max_force", max_force), ("contact_threshold", contact_threshold)):
            if not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
                raise ValueError(f"parameter '{name}' must be a positive number, got {value!r}")
        if not 0 <= margin < 1:
            raise ValueError(f"parameter 'margin' must be in [0, 1), got {margin!r}")
        if not 0 <= approach_force <= max_force:
            raise ValueError("parameter 'approach_force' must be in [0, max_force]")
        if min_force > max_force:
            raise ValueError("parameter 'min_force' must not exceed 'max_force'")
        self.ki, self.min_force, self.max_force = float(ki), float(min_force), float(max_force)
        self.ratio_target = float(safety_ratio) / (1.0 + float(margin))
        self.approach_force, self.threshold = float(approach_force), float(contact_threshold)
        self.inputs = {"q": 9, "tip": 9, "fn": 3, "ft": 3, "normal": 6}
        self.outputs = {"tau_g": 9, "force": 3, "active": 3}
        self.feedthrough = {"tau_g": {"q", "tip", "fn", "normal"}, "force": {"tip", "fn", "normal"},
                            "active": {"fn"}}

    def bind(self, period) -> None:
        if period is None:
            raise ValueError("GraspReflex needs an explicit period (the paper's is 1 ms)")
        super().bind(period)
        self.dt = float(period)

    def initial_state(self) -> np.ndarray:
        """[grasp force scale s (N), has touched the object (3)]."""
        return np.concatenate(([self.approach_force], np.zeros(3)))

    def members(self, state: np.ndarray, fn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(fingers in the grasp, fingers in contact)."""
        touching = fn > self.threshold
        approaching = self.initial & (state[1:] == 0.0) & ~touching
        return touching | approaching, touching

    def directions(self, state: np.ndarray, tip: np.ndarray, normal: np.ndarray,
                   fn: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(3, 2) internal force per finger at unit scale (largest row length 1), the
        fingers in the grasp and the fingers touching.

        The internal force is the one nearest to every finger pushing along its contact
        normal: ``(I - G^+ G) n``. It keeps each contact's force close to its normal, so
        raising the scale lowers ``|f_t| / f_n`` wherever the faces allow it (a focus-point
        squeeze can point a contact's force along the face instead). A finger still
        approaching pushes towards the others' centroid.
        """
        grasp, touching = self.members(state, fn)
        g = np.zeros((3, 2))
        if grasp.sum() < 2:
            return g, grasp, touching
        points = tip.reshape(3, 3)[:, :2]
        push = normal.reshape(3, 2).copy()
        for i in np.flatnonzero(grasp & ~touching):
            toward = points[grasp & (np.arange(3) != i)].mean(axis=0) - points[i]
            push[i] = toward / max(np.linalg.norm(toward), 1e-12)
        idx = np.flatnonzero(grasp)
        internal = project_internal(points[idx], points[idx].mean(axis=0), push[idx].ravel()).reshape(-1, 2)
        if np.any(np.einsum("ij,ij->i", internal, push[idx]) <= 0):
            internal = internal_directions(points[idx])
        g[idx] = internal / np.max(np.linalg.norm(internal, axis=1))
        return g, grasp, touching

    def forces(self, state: np.ndarray, inputs: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """(3, 2) fingertip force commands and the fingers in the grasp."""
        g, grasp, touching = self.directions(state, inputs["tip"], inputs["normal"], inputs["fn"])
        length = np.linalg.norm(g, axis=1)
        scale = np.where(touching, state[0], self.approach_force / np.maximum(length, 1e-300))
        return g * scale[:, None], grasp

    def output(self, t: float, state: np.ndarray, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        f, grasp = self.forces(state, inputs)
        jac = self.hand.tip_jacobians(inputs["q"])
        tau = np.concatenate([jac[i].T @ f[i] for i in range(3)])
        return {"tau_g": tau, "force": np.linalg.norm(f, axis=1), "active": grasp.astype(float)}

    def update(self, t: float, state: np.ndarray, inputs: Mapping[str, np.ndarray]) -> np.ndarray:
        fn, ft = inputs["fn"], inputs["ft"]
        g, grasp, touching = self.directions(state, inputs["tip"], inputs["normal"], fn)
        held = grasp & touching
        scale = state[0]
        if held.sum() >= 2:
            normal = inputs["normal"].reshape(3, 2)[held]
            gain = np.einsum("ij,ij->i", g[held], normal)  # normal force per unit of scale
            need = np.maximum(self.min_force * np.linalg.norm(g[held], axis=1),
                              np.abs(ft[held]) / self.ratio_target)
            shortfall = float(np.max((need - fn[held]) / np.maximum(gain, 1e-3)))
            scale = min(max(scale + self.ki * self.dt * shortfall, 0.0), self.max_force)
        return np.concatenate(([scale], np.maximum(state[1:], touching)))
