"""The manipulation controller's compiled output: trajectories, IK, PD and feedforward.

``manipulation_output`` is ``ManipulationPD.output`` in one native call: sample the
fingertip trajectories, turn the samples into joint targets by the exact three-joint
inverse kinematics (the elbow branch nearest ``q0``, each angle as its representative
nearest ``q0``), differentiate those centrally in time for the velocity target, track
both with the joint PD, and add the gravity and load feedforward. The law lives in C
(``hierhand/csrc/manipulation.c``); ``inverse_kinematics`` and ``trajectory`` call the
same C for their functions, and the gravity and Jacobians are the plant's.

Everything comes in flat float64 arrays whose layouts are declared once, in
``hierhand/csrc/layouts.h`` (``hierhand.layouts``: ``MANIP_PARAMS``, ``MANIP_WAYPOINT``,
``MANIP_META``, ``MANIP_OUT``, ``MANIP_STATUS``); ``pack_params`` and ``pack_trajectories``
build them.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .. import _native
from ..layouts import DIMENSIONS, MANIP_META, MANIP_WAYPOINT
from .trajectory import INTERPOLATIONS

manipulation_output = _native.manipulation_output
"""``manipulation_output(model, params, waypoints, meta, t, q, qd, fn, support, normal, obj, out) -> status``: fill
``out`` (``MANIP_OUT``: tau_m, tau_ff, q_ref) and return a ``MANIP_STATUS`` code (``out``
incomplete unless ``OK``; ``UNREACHABLE + f``: a target of finger f is out of reach,
``NO_PERIOD``: matched gains without a period).
Takes C-contiguous float64 arrays only (``TypeError`` otherwise)."""


matched_gains = _native.matched_gains
"""``matched_gains(inertia, kp, kd, period) -> (kp_T, kd_T)``: the gains a torque held for each
period needs to give a joint of that inertia the closed-loop poles of the continuous PD
(pole matching under a zero-order hold; hierhand/csrc/control.h)."""


pack_params = _native.manip_pack
"""``pack_params(given, hand_vector, dt) -> params``: the block's parameters (``MANIP_GIVEN``)
checked and packed into ``manipulation_output``'s vector (``MANIP_PARAMS``: q0 and gravity from the
hand, the weight its object's mass times gravity, the period ``dt``, NaN for none, set
again by the block's ``bind``); ValueError naming a bad parameter (control_params.c)."""


def pack_trajectories(trajectories: Sequence) -> tuple[np.ndarray, np.ndarray]:
    """``(waypoints, meta)`` of three ``Trajectory`` objects or ``None`` (no trajectory)."""
    n_max = max([1] + [traj.times.size for traj in trajectories if traj is not None])
    fingers = DIMENSIONS["FINGERS"]
    waypoints = np.zeros((fingers, n_max, MANIP_WAYPOINT.size))
    meta = np.zeros((fingers, MANIP_META.size))
    for f, traj in enumerate(trajectories):
        if traj is None:
            continue
        n = traj.times.size
        waypoints[f, :n, MANIP_WAYPOINT.T] = traj.times
        waypoints[f, :n, MANIP_WAYPOINT.X:MANIP_WAYPOINT.PHI + 1] = traj.points
        meta[f, MANIP_META.COUNT] = n
        meta[f, MANIP_META.INTERP] = INTERPOLATIONS[traj.interpolation]
    return waypoints, meta

