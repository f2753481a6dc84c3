"""The manipulation controller's compiled output: trajectories, IK, PD and feedforward.

``manipulation_output`` is ``ManipulationPD.output`` in one native call: sample the
fingertip trajectories, turn the samples into joint targets by the exact three-joint
inverse kinematics (the elbow branch nearest ``q0``, each angle as its representative
nearest ``q0``), differentiate those centrally in time for the velocity target, track
both with the joint PD, and add the gravity and load feedforward. The law lives in C
(``hierhand/csrc/manipulation.c``); ``inverse_kinematics`` and ``trajectory`` call the
same C for their functions, and the gravity and Jacobians are the plant's.

Everything comes in flat float64 arrays whose layouts are defined once, in
``hierhand/csrc/control.h`` (``hierhand._native.LAYOUT``); ``pack_params`` and
``pack_trajectories`` build them.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .. import _native
from .trajectory import INTERPOLATIONS

_L = _native.LAYOUT

# -- params: one float64 vector --------------------------------------------------------
P_Q0: int = _L["MANIP_P_Q0"]  # 9 initial joint angles (held by fingers without a trajectory; IK reference)
P_KP: int = _L["MANIP_P_KP"]  # 9 joint stiffnesses
P_KD: int = _L["MANIP_P_KD"]  # 9 joint dampings
P_GX: int = _L["MANIP_P_GX"]  # gravity
P_GY: int = _L["MANIP_P_GY"]
P_WX: int = _L["MANIP_P_WX"]  # object weight m g
P_WY: int = _L["MANIP_P_WY"]
P_THRESHOLD: int = _L["MANIP_P_THRESHOLD"]  # normal force above which a finger carries the object
P_GRAVITY_COMP: int = _L["MANIP_P_GRAVITY_COMP"]  # 1.0: add the fingers' gravity torques
P_LOAD_COMP: int = _L["MANIP_P_LOAD_COMP"]  # 1.0: add J^T of the shared object weight
P_STEP: int = _L["MANIP_P_STEP"]  # seconds either side of t for the velocity target
P_REACH_RTOL: int = _L["MANIP_P_REACH_RTOL"]  # inverse_kinematics._REACH_RTOL
P_DT: int = _L["MANIP_P_DT"]  # the controller's period, s (set by bind)
P_MATCHED: int = _L["MANIP_P_MATCHED"]  # 1.0: kp, kd realised for the period (matched_gains)
P_CONTACT_COMP: int = _L["MANIP_P_CONTACT_COMP"]  # 1.0: aim fingers in contact fn / k_n into the object
N_PARAMS: int = _L["MANIP_N_PARAMS"]

# -- trajectories: waypoints (3, n_max, 4) rows (t, x, y, phi); meta (3, 2) float64 ------
M_COUNT: int = _L["MANIP_M_COUNT"]  # waypoints of the finger's trajectory (0: none, the finger holds q0)
M_INTERP: int = _L["MANIP_M_INTERP"]  # trajectory.INTERPOLATIONS' code

# -- output: rows tau_m, tau_ff, q_ref -------------------------------------------------
N_OUT: int = _L["MANIP_N_OUT"]

OK: int = _L["MANIP_OK"]
"""Status of ``manipulation_output``; ``UNREACHABLE + f`` means finger f's target is out of reach,
``NO_PERIOD`` that matched gains were asked for without a period (``P_DT``)."""
UNREACHABLE: int = _L["MANIP_UNREACHABLE"]
NO_PERIOD: int = _L["MANIP_NO_PERIOD"]

manipulation_output = _native.manipulation_output
"""``manipulation_output(model, params, waypoints, meta, t, q, qd, fn, support, normal, obj, out) -> status``: fill
``out`` (3, 9) with the rows tau_m, tau_ff, q_ref (``out`` incomplete unless ``OK``).
Takes C-contiguous float64 arrays only (``TypeError`` otherwise)."""


matched_gains = _native.matched_gains
"""``matched_gains(inertia, kp, kd, period) -> (kp_T, kd_T)``: the gains a torque held for each
period needs to give a joint of that inertia the closed-loop poles of the continuous PD
(pole matching under a zero-order hold; hierhand/csrc/control.h)."""


G_KP: int = _L["MANIP_G_KP"]  # -- the block's parameters as given: given[G_*] (control.h); nine
G_KD: int = _L["MANIP_G_KD"]  # nine
G_THRESHOLD: int = _L["MANIP_G_THRESHOLD"]
G_GRAVITY_COMP: int = _L["MANIP_G_GRAVITY_COMP"]
G_LOAD_COMP: int = _L["MANIP_G_LOAD_COMP"]
G_MATCHED: int = _L["MANIP_G_MATCHED"]  # discretization 'matched'
G_CONTACT_COMP: int = _L["MANIP_G_CONTACT_COMP"]
G_STEP: int = _L["MANIP_G_STEP"]  # manipulation_pd.DERIVATIVE_STEP
G_REACH_RTOL: int = _L["MANIP_G_REACH_RTOL"]  # inverse_kinematics._REACH_RTOL
N_GIVEN: int = _L["MANIP_N_GIVEN"]

pack_params = _native.manip_pack
"""``pack_params(given, hand_vector, dt) -> params``: the block's parameters (``G_*``)
checked and packed into ``manipulation_output``'s vector (``P_*``: q0 and gravity from the
hand, the weight its object's mass times gravity, the period ``dt``, NaN for none, set
again by the block's ``bind``); ValueError naming a bad parameter (control_params.c)."""


def pack_trajectories(trajectories: Sequence) -> tuple[np.ndarray, np.ndarray]:
    """``(waypoints, meta)`` of three ``Trajectory`` objects or ``None`` (no trajectory)."""
    n_max = max([1] + [traj.times.size for traj in trajectories if traj is not None])
    waypoints = np.zeros((3, n_max, 4))
    meta = np.zeros((3, 2))
    for f, traj in enumerate(trajectories):
        if traj is None:
            continue
        n = traj.times.size
        waypoints[f, :n, 0] = traj.times
        waypoints[f, :n, 1:] = traj.points
        meta[f, M_COUNT] = n
        meta[f, M_INTERP] = INTERPOLATIONS[traj.interpolation]
    return waypoints, meta

