"""The grasping reflex (the paper's lower level): hold the object with internal forces.

At every hit (1 ms in the paper) the reflex

1. finds the fingers in contact from the fingertip force sensors (``fn``), so it follows
   the grasp through a re-grasp; fingers listed in ``grasp`` that are not touching are
   pushed towards the touching ones with ``approach_force`` until they do (again, after a
   bounce), unless the reflex was letting go of them when they last touched;
2. takes the internal ("squeeze") forces among the touching fingers (Yoshikawa-Nagai): the
   internal force nearest to every finger pushing along its contact normal,
   ``(I - G^+ G) n``, with G the grasp matrix of the contact points (tip centre plus tip
   radius along the normal); for two contacts this is the squeeze along the line between
   them. An approaching finger is no part of it: it does not touch the object;
3. finds the contact that is most short of the normal force it needs,
   ``need_i = max(min_force * |g_i|, |f_t,i| / ratio_target)`` (the sensor form of the
   friction scaling at the safety ratio);
4. realises it with integral control of one grasp force scale ``s``:
   ``s += ki * dt * max_i hold_i (need_i - fn_i) / (n_i . g_i)`` (with ``catch_up`` c, plus
   c times that shortfall where it is positive), the fingertip forces
   ``s g_i`` mapped to joint torques by ``J_i^T`` at the contact points. One integrator for
   the whole grasp, not one per finger: in a pinch both normal forces respond alike to a
   difference between the fingers' pushes (the object just moves), so per-finger
   integrators would drift apart.

The hand-over to voluntary motion follows the suppresser (input ``share``: per finger,
what the suppresser lets through of its grasping torque). Two touching fingers are the
grasp: the two the suppresser spares most are held whole (``hold`` 1), and the reflex makes
up with squeeze what the suppresser takes from them. A third touching finger is held by 1
while its share is at least ``hold_share`` (the sigmoid at rest lets a little less than the
whole grasp torque through), falling linearly to 0 as its share falls to ``release_share``: it
drives the integrator by that much, and from the next hit shares the squeeze by that
much (the internal force of all three, blended toward that of the other two). Without this
the reflex winds up while voluntary motion pulls a finger off the object (its ``|f_t| /
f_n`` climbs as it lets go of its load), raising the squeeze of every finger and the
leaving finger's own grasp torque. With the suppresser off (share 1) nothing is handed
over; ``follow_suppression: false`` is the paper's reflex, which knows nothing of the
suppresser.

The minimum force: a grasp that must take a load suddenly (the hand-over of the object
at 0.1 s in the task diagrams) needs its squeeze in place beforehand, ``m g / (k
safety_ratio)`` per finger for k fingers carrying weight m g by friction (2.45 N for the
0.3 kg object in a two-finger pinch); the task diagrams use 3 N. The default 1 N closes
the fingers just as cleanly, but at the hand-over the ratio then reaches the sliding limit
before the integrator catches up, and the object slips out.

Why a margin: an integral loop approaches its target exponentially, so aiming exactly at
the safety ratio would leave ``|f_t| / f_n`` just above it for ever; aiming at
``safety_ratio / (1 + margin)`` brings it below the safety ratio in finite time.

How: ``output`` and ``update`` each make one native call through ``reflex_law`` (the
law in C, ``hierhand/csrc/reflex.c``: the grasp matrix solve written out by hand, the tip
Jacobians from the plant's own kinematics); ``internal_forces.project_internal`` and
``internal_directions`` call the same C. The parameters are packed for the native calls
when the block is made and bound.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from blocks import Block
from blocks.engine.kernel import Kernel, Tunable

from ..layouts import REFLEX_GIVEN as GIVEN, REFLEX_INPUTS, REFLEX_OUT, REFLEX_PARAMS, REFLEX_RECORD
from ..layouts import port_columns, ports
from ..model.hand_source import ModelsTheHand, hand_link, hand_of
from ..model.port_info import DescribesHandPorts
from ..records import KERNELS, context_of, hand_segment, record
from .internal_forces import _COINCIDENT_RTOL
from .reflex_law import (
    WHOLE_SHARE,
    pack_params,
    reflex_directions,
    reflex_failure,
    reflex_forces,
    reflex_output,
    reflex_update,
)

_PORTS = port_columns(REFLEX_OUT)
"""The output ports (tau_g, force, active) and their columns of the law's output."""


def finger_indices(names: tuple[str, ...], chosen: Any, what: str) -> np.ndarray:
    """Boolean mask over the hand's fingers for a list of finger names."""
    chosen = [chosen] if isinstance(chosen, str) else list(chosen or [])
    unknown = [c for c in chosen if c not in names]
    if unknown:
        raise ValueError(f"{what}: unknown finger(s) {', '.join(map(str, unknown))}; fingers are "
                         f"{', '.join(names)}")
    return np.array([n in chosen for n in names])


class GraspReflex(DescribesHandPorts, ModelsTheHand, Block):
    """Grasping reflex: internal forces among the fingers in contact, kept inside the
    friction cone at the safety ratio by integral control of the fingertip forces.

    Its hand (finger geometry for the tip Jacobians, finger names) is the plant's:
    ``hand: plant`` names the block that simulates the hand (see ``hand_of``).

    Parameters
    ----------
    grasp : list of finger names
        fingers that close on the object at the start, e.g. [thumb, fore]
    ki : float
        integral gain of the fingertip force loop, 1/s (30-100 gives a 10-30 ms recovery)
    safety_ratio : float
        largest |f_t|/f_n the reflex allows (the paper's 0.6)
    margin : float
        the loop aims at safety_ratio / (1 + margin), so that it settles below the safety
        ratio
    min_force : float
        smallest normal force per contact, N, even without tangential load
    max_force : float
        largest commanded force per fingertip, N (anti-windup limit)
    approach_force : float
        force, N, that pushes a 'grasp' finger towards the others until it touches
    contact_threshold : float
        normal force, N, above which a finger counts as in contact
    release_share : float
        share (input 'share', from the suppresser) at which a third touching finger is
        wholly handed to voluntary motion (two fingers are always held whole: they are the
        grasp)
    hold_share : float
        share down to which a third touching finger is held whole; in proportion between
        it and release_share
    follow_suppression : bool
        hand fingers over as the suppresser switches their grasp off (the hold above);
        false: the paper's reflex, which holds every touching finger whole
    squeeze_from_weight : bool
        raise min_force to the squeeze the object's weight needs when the fingers of
        'grasp' alone carry it at the ratio target, m |g| / (k ratio_target) for k fingers
        (derived from the hand in C, hierhand/csrc/control_params.c, so an exported FMU
        follows a changed object mass)
    friction_cap : bool
        keep to a safety ratio of at most 0.9 of the plant's sliding friction mu_d, so that a
        sliding contact always calls for more squeeze
    catch_up : float
        share, 0-1, of a positive shortfall (a contact short of the normal force it needs)
        the force scale closes at once each hit, besides the integral step; 0: the paper's
        integral control alone. A sudden push can take an object out of a light grasp before
        an integral loop at ki has built the squeeze the push needs
    """

    type_name = "GraspReflex"

    def __init__(self, hand, grasp=("thumb", "fore"), ki: float = 50.0, safety_ratio: float = 0.6,
                 margin: float = 0.05, min_force: float = 1.0, max_force: float = 30.0,
                 approach_force: float = 0.5, contact_threshold: float = 0.05, release_share: float = 0.5,
                 hold_share: float = 0.9, follow_suppression: bool = True, squeeze_from_weight: bool = False,
                 friction_cap: bool = False, catch_up: float = 0.0):
        self.hand = hand_of(hand)
        self._links = hand_link(hand, REFLEX_RECORD.SEGMENT)
        self.initial = finger_indices(self.hand.names, grasp, "grasp")
        for name, value in (("ki", ki), ("safety_ratio", safety_ratio), ("min_force", min_force),
                            ("max_force", max_force), ("contact_threshold", contact_threshold),
                            ("margin", margin), ("approach_force", approach_force),
                            ("release_share", release_share), ("hold_share", hold_share), ("catch_up", catch_up)):
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ValueError(f"parameter '{name}' must be a number, got {value!r}")
        self.squeeze_from_weight, self.friction_cap = bool(squeeze_from_weight), bool(friction_cap)
        given = np.empty(GIVEN.size)
        given[GIVEN.KI], given[GIVEN.SAFETY_RATIO], given[GIVEN.MARGIN] = ki, safety_ratio, margin
        given[GIVEN.MIN_FORCE], given[GIVEN.MAX_FORCE], given[GIVEN.APPROACH] = min_force, max_force, approach_force
        given[GIVEN.THRESHOLD], given[GIVEN.RELEASE_SHARE] = contact_threshold, release_share
        given[GIVEN.HOLD_SHARE] = hold_share
        given[GIVEN.CATCH_UP] = catch_up
        given[GIVEN.SQUEEZE_FROM_WEIGHT], given[GIVEN.FRICTION_CAP] = self.squeeze_from_weight, self.friction_cap
        self.catch_up = float(catch_up)
        given[GIVEN.FOLLOW] = 1.0 if follow_suppression else 0.0
        given[GIVEN.slice("GRASP")] = self.initial
        given[GIVEN.COINCIDENT_RTOL] = _COINCIDENT_RTOL
        self._given = given
        # the native calls' flat parameter array, its checks and derived values in C; the
        # period (REFLEX_PARAMS.DT) is set by bind
        self._params = pack_params(given, self.hand.vector, np.nan)
        self.ki, self.max_force = float(ki), float(max_force)
        self.min_force = float(self._params[REFLEX_PARAMS.MIN_FORCE])  # with squeeze_from_weight, from the hand
        self.ratio_target = float(self._params[REFLEX_PARAMS.RATIO])
        self.approach_force, self.threshold = float(approach_force), float(contact_threshold)
        self.release_share = float(release_share)
        self.hold_share = float(hold_share)
        self.follow_suppression = bool(follow_suppression)
        self.inputs = dict(REFLEX_INPUTS)
        self.input_defaults = {"share": WHOLE_SHARE}
        self.outputs = dict(ports(REFLEX_OUT))
        self.feedthrough = {"tau_g": {"q", "tip", "fn", "normal"}, "force": {"tip", "fn", "normal"},
                            "active": {"fn"}}

    def bind(self, period) -> None:
        if period is None:
            raise ValueError("GraspReflex needs an explicit period (the paper's is 1 ms)")
        super().bind(period)
        self.dt = float(period)
        self._params[REFLEX_PARAMS.DT] = self.dt
        self._kernel = None

    def kernel(self) -> Kernel | None:
        """``output`` and ``update`` in C (kernel type ``GraspReflex``: the same reflex
        law, hierhand/csrc/reflex.c), in a context its constructor builds from the record
        ``[hand segment, dt, given]``; None before ``bind``. In an exported FMU the
        gains, forces and shares are tunable, and the hand follows the plant's."""
        if not self._params[REFLEX_PARAMS.DT] > 0:
            return None
        held = getattr(self, "_kernel", None)
        if held is None:
            rec = record("GraspReflex", hand_segment(self.hand, False), [self.dt], self._given,
                         tunables=_TUNABLES, links=self._links)
            ctx = context_of(rec)
            held = self._kernel = Kernel(context=ctx.address, output=KERNELS["GraspReflex.output"],
                                         update=KERNELS["GraspReflex.update"], owners=(ctx,), error=_kernel_error,
                                         nogil=True, record=rec)
        return held

    def initial_state(self) -> np.ndarray:
        """[grasp force scale s (N), per finger 1 where voluntary motion had taken it over when it
        last touched, else 0 (3), per finger how much the reflex holds it (3, 1 at the start)]."""
        return np.concatenate(([self.approach_force], np.zeros(3), np.ones(3)))

    def directions(self, state: np.ndarray, tip: np.ndarray, normal: np.ndarray,
                   fn: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(3, 2) internal force per finger at unit scale (largest row length 1), the
        fingers in the grasp and the fingers touching.

        The internal force is the one nearest to every finger pushing along its contact
        normal: ``(I - G^+ G) n``. It keeps each contact's force close to its normal, so
        raising the scale lowers ``|f_t| / f_n`` wherever the faces allow it (a focus-point
        squeeze can point a contact's force along the face instead). A finger still
        approaching pushes towards the others' centroid. Should the projection leave a
        finger not pushing (``g_i . push_i <= 0``), the grasp falls back to the centroid
        squeeze ``internal_directions``. Computed by ``reflex_law.reflex_directions``
        (``G^+ = G^T (G G^T)^-1`` solved by hand, as ``project_internal`` does).
        """
        return reflex_directions(self._params, state, tip, normal, fn)

    def forces(self, state: np.ndarray, inputs: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """(3, 2) fingertip force commands and the fingers in the grasp: ``s g_i`` for a
        touching finger, ``g_i`` scaled to ``approach_force`` for an approaching one."""
        return reflex_forces(self._params, state, inputs["tip"], inputs["normal"], inputs["fn"])

    def output(self, t: float, state: np.ndarray, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """``tau_g = J_i^T f_i`` per finger (tip Jacobians at ``q``), ``|f_i|`` and the grasp
        flags; one native call, the ports are views of one fresh array."""
        out = reflex_output(self.hand.native, self._params, state, inputs["q"], inputs["tip"], inputs["normal"],
                            inputs["fn"])
        return {port: out[columns] for port, columns in _PORTS}

    def update(self, t: float, state: np.ndarray, inputs: Mapping[str, np.ndarray]) -> np.ndarray:
        """The integral step of the grasp force scale and the hand-over scales (a fresh array)."""
        return reflex_update(self._params, state, inputs["tip"], inputs["normal"], inputs["fn"], inputs["ft"],
                             inputs.get("share", WHOLE_SHARE))


_TUNABLES = tuple(Tunable(name, REFLEX_RECORD.GIVEN + slot, text, unit, minimum=0.0, maximum=top)
                  for name, slot, text, unit, top in (
    ("ki", GIVEN.KI, "integral gain of the fingertip force loop", "1/s", None),
    ("safety_ratio", GIVEN.SAFETY_RATIO, "largest |f_t|/f_n the reflex allows", "1", None),
    ("margin", GIVEN.MARGIN, "the loop aims at safety_ratio / (1 + margin)", "1", 1.0),
    ("min_force", GIVEN.MIN_FORCE, "smallest normal force per contact", "N", None),
    ("max_force", GIVEN.MAX_FORCE, "largest commanded force per fingertip", "N", None),
    ("approach_force", GIVEN.APPROACH, "force pushing a 'grasp' finger towards the others", "N", None),
    ("contact_threshold", GIVEN.THRESHOLD, "normal force above which a finger counts as in contact", "N", None),
    ("release_share", GIVEN.RELEASE_SHARE, "share at which a third touching finger is wholly handed over", "1", 1.0),
    ("hold_share", GIVEN.HOLD_SHARE, "share down to which a third touching finger is held whole", "1", 1.0)))
"""GraspReflex's parameters an exported FMU lets an importer set, with the ranges its
constructor (``hh_reflex_pack``) holds them to."""


def _kernel_error(code: int, which: int, t: float, phase: str) -> BaseException:
    """The kernel's failure as the Python methods raise it (the native calls' exception)."""
    return reflex_failure(code)
