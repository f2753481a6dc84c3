"""The manipulation controller (the paper's upper level): voluntary fingertip motion.

Fingertip trajectories are given beforehand as timed waypoints (x, y, phi) per finger.
Every hit (10 ms in the paper) samples them, turns the samples into joint targets by
exact three-joint inverse kinematics and tracks them with a joint PD. Fingers without a
trajectory hold their initial joint angles.

All of that runs in one native call per hit (``manipulation_law.manipulation_output``,
the law in C over flat arrays packed once at load time). When a target turns out
unreachable during the run, the Python API on the same C (``finger_ik_near``) names the
finger and the distance.

Beyond the paper's PD, each a parameter (and a row of the report's ablation):

- ``discretization: matched``: kp and kd are the continuous joint PD, realised at the
  block's period for each joint's own inertia (the diagonal of its finger's mass matrix,
  armature included) by pole matching under the zero-order hold, so the 10 ms loop is
  stable for any kp, kd > 0. Applied as they are and held for 10 ms (``held``), a joint PD
  goes unstable once kd T / J exceeds 2: kd = 0.02 N m s/rad for the distal joints.
- ``contact_compensation``: a finger in contact aims deeper into the object along the
  contact normal, so that posture holding does not push back against the squeeze:
  ``contact_aim`` times the depth at which the plant's contact law holds the tip at the
  measured normal force, or without it (null) fn / k_n, the summed depth of all the surface
  points under the tip.
- ``gravity_compensation`` and ``load_compensation`` (output ``tau_ff``, added after the
  suppresser): the fingers' own gravity torques, and J^T of the object's load shared among
  the fingers in contact by the grasp matrix at their contact points (``G^+ w``), so that
  the shares balance the load's moment about the object's centre as well as its weight
  (input ``obj``: the object's pose; ``normal``: the contact normals). The load is the
  object's weight less the force on input ``support`` (what carries the object before the
  hand-over; without it the fingers would lift the object a second time while they close).
  Without the feedforward the soft PD lets a held object sag by millimetres.

Outputs: ``tau_m``, the PD torque of the voluntary motion (what the suppresser weighs
against the grasping torque), and ``tau_ff``. Keeping the feedforward out of ``tau_m``
matters: it is not voluntary motion, and a finger that merely carries the object must not
have its grasp suppressed.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from blocks import Block
from blocks.arrays import flat_float64, float_array
from blocks.engine.kernel import Kernel, Tunable

from ..layouts import MANIP_GIVEN as GIVEN, MANIP_INPUTS, MANIP_OUT, MANIP_PARAMS, MANIP_RECORD, MANIP_STATUS
from ..layouts import port_columns, ports
from ..model.hand_source import ModelsTheHand, hand_link, hand_of
from ..model.port_info import DescribesHandPorts
from ..records import KERNELS, context_of, hand_segment, record
from .inverse_kinematics import UnreachableError, finger_ik_near
from .inverse_kinematics import _REACH_RTOL
from .manipulation_law import manipulation_output, pack_params, pack_trajectories
from .trajectory import Trajectory

DERIVATIVE_STEP = 1e-3
"""Seconds either side of t for the joint-velocity target (central difference of the IK)."""
DISCRETIZATIONS = ("matched", "held")
"""How kp and kd become the torque of a sampled PD (see the class docstring)."""
_PORTS = port_columns(MANIP_OUT)
"""The output ports (tau_m, tau_ff, q_ref) and their columns of the law's output."""


class ManipulationPD(DescribesHandPorts, ModelsTheHand, Block):
    """Manipulation controller: fingertip trajectories -> inverse kinematics -> joint PD.

    Its hand (finger geometry and q0, gravity, the object's mass for the load
    feedforward) is the plant's: ``hand: plant`` names the block that simulates the hand
    (see ``hand_of``).

    Parameters
    ----------
    trajectories : mapping
        per finger name: {waypoints: [[t, x, y, phi], ...], interpolation: minjerk|linear}
    kp : scalar or 9 values
        joint stiffness, N m/rad, of the continuous PD (see discretization)
    kd : scalar or 9 values
        joint damping, N m s/rad, of the continuous PD (see discretization)
    gravity_compensation : bool
        add the fingers' own gravity torques
    load_compensation : bool
        add J^T of the object's load (weight plus input support) shared by the fingers in
        contact through the grasp matrix at their contact points (the shares balance the
        load's moment too)
    contact_threshold : float
        normal force, N, above which a finger carries part of the object
    discretization : str
        'matched' (default): kp and kd are the continuous joint PD, realised at the block's
        period by pole matching on each joint's own inertia, stable for any kp, kd > 0;
        'held': kp and kd applied as they are and held for the period (unstable once
        kd T / J > 2, about kd = 0.02 N m s/rad for the distal joints at 10 ms)
    contact_compensation : bool
        aim a finger in contact as deep into the object as its measured normal force presses
        it (along the contact normal), so that the PD does not resist the squeeze
    contact_aim : float or null
        how deep: that many times the depth at which the contact law holds the tip at the
        measured normal force (a circle on a face of surface points, fn / k_n =
        4/3 depth^1.5 sqrt(2 r) / spacing); null: fn / k_n, the summed depth of the points
        under the tip, several times its own, which grows with fn and lifts a heavy object
        squeezed hard
    """

    type_name = "ManipulationPD"
    time_varying = True

    def __init__(self, hand, trajectories: Mapping[str, Any] | None = None, kp: Any = 3.0, kd: Any = 0.04,
                 gravity_compensation: bool = True, load_compensation: bool = True,
                 contact_threshold: float = 0.05, discretization: str = "matched",
                 contact_compensation: bool = True, contact_aim: float | None = None):
        self.hand = hand_of(hand)
        self.kp = float_array(kp, "kp", ndim=1, width=9, broadcast=True)
        self.kd = float_array(kd, "kd", ndim=1, width=9, broadcast=True)
        if np.any(self.kp < 0) or np.any(self.kd < 0):
            raise ValueError("kp and kd must be non-negative")
        self.gravity_compensation = bool(gravity_compensation)
        self.load_compensation = bool(load_compensation)
        self.threshold = float(contact_threshold)
        if discretization not in DISCRETIZATIONS:
            raise ValueError(f"parameter 'discretization' must be one of {', '.join(DISCRETIZATIONS)}, "
                             f"got {discretization!r}")
        self.discretization = discretization
        self.contact_compensation = bool(contact_compensation)
        self._links = hand_link(hand, MANIP_RECORD.SEGMENT)
        self.trajectories = self.parse_trajectories(trajectories or {})
        self.inputs = dict(MANIP_INPUTS)
        self.input_defaults = {"support": np.zeros(3)}
        self.outputs = dict(ports(MANIP_OUT))
        self.feedthrough = True
        # the native output's flat arrays (built from the attributes above, once; the
        # checks and the values taken from the hand in C)
        self._model = self.hand.native
        given = np.empty(GIVEN.size)
        given[GIVEN.slice("KP")], given[GIVEN.slice("KD")] = self.kp, self.kd
        given[GIVEN.THRESHOLD] = self.threshold
        given[GIVEN.GRAVITY_COMP], given[GIVEN.LOAD_COMP] = self.gravity_compensation, self.load_compensation
        given[GIVEN.MATCHED], given[GIVEN.CONTACT_COMP] = discretization == "matched", self.contact_compensation
        given[GIVEN.STEP], given[GIVEN.REACH_RTOL] = DERIVATIVE_STEP, _REACH_RTOL
        if contact_aim is not None and (isinstance(contact_aim, bool) or not isinstance(contact_aim, (int, float))):
            raise ValueError(f"parameter 'contact_aim' must be a number or null, got {contact_aim!r}")
        self.contact_aim = None if contact_aim is None else float(contact_aim)
        given[GIVEN.CONTACT_AIM] = self.contact_aim or 0.0
        self._given = given
        self._params = pack_params(given, self.hand.vector, np.nan)
        self.weight = self._params[[MANIP_PARAMS.WX, MANIP_PARAMS.WY]]
        self._waypoints, self._meta = pack_trajectories(self.trajectories)

    def parse_trajectories(self, config: Mapping[str, Any]) -> list[Trajectory | None]:
        """One trajectory or None per finger; every waypoint checked for reachability."""
        if not isinstance(config, Mapping):
            raise ValueError("trajectories must map finger names to {waypoints: [...]}")
        unknown = [k for k in config if k not in self.hand.names]
        if unknown:
            raise ValueError(f"trajectories: unknown finger(s) {', '.join(map(str, unknown))}; "
                             f"fingers are {', '.join(self.hand.names)}")
        out: list[Trajectory | None] = []
        for f, name in enumerate(self.hand.names):
            if name not in config:
                out.append(None)
                continue
            try:
                traj = Trajectory.from_config(config[name])
            except ValueError as exc:
                raise ValueError(f"trajectory of finger '{name}': {exc}") from None
            for t, point in zip(traj.times, traj.points):
                try:
                    self.joint_targets_for(f, point)
                except UnreachableError as exc:
                    raise ValueError(f"finger '{name}': the waypoint at t = {t:g} s "
                                     f"(x={point[0]:g}, y={point[1]:g}, phi={point[2]:g}) is unreachable: {exc}") from None
            out.append(traj)
        return out

    def bind(self, period) -> None:
        """Take the period the matched gains are realised for (a 'matched' PD needs one)."""
        if period is None and self.discretization == "matched":
            raise ValueError("ManipulationPD needs an explicit period (the paper's is 10 ms) to realise its gains "
                             "for it; or give discretization: held")
        super().bind(period)
        self._params[MANIP_PARAMS.DT] = float(period) if period is not None else np.nan
        self._kernel = None

    def joint_targets_for(self, finger: int, point: np.ndarray) -> np.ndarray:
        """Joint angles (3,) of one finger for a tip target, on the branch nearest q0."""
        return finger_ik_near(self.hand, finger, point, self.hand.q0[3 * finger:3 * finger + 3])

    def output(self, t: float, state: Any, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """One native call on the arrays packed in ``__init__`` (so parameters changed on
        the object afterwards are not seen). Inputs the native call refuses for their type
        (lists, other dtypes, strided views) are converted to float64 first; inputs of the
        wrong width raise ``ValueError`` naming the port, a target out of reach
        ``UnreachableError`` naming the finger; matched gains need ``bind``'s period first."""
        out = np.empty(MANIP_OUT.size)
        values = (inputs["q"], inputs["qd"], inputs["fn"], inputs.get("support", self.input_defaults["support"]),
                  inputs["normal"], inputs["obj"])
        try:
            status = manipulation_output(self._model, self._params, self._waypoints, self._meta, t, *values, out)
        except TypeError:
            status = manipulation_output(self._model, self._params, self._waypoints, self._meta, t,
                                         *(flat_float64(v) for v in values), out)
        if status != MANIP_STATUS.OK:
            raise self._kernel_error(status, 0, t, "output")
        return {port: out[columns] for port, columns in _PORTS}

    def kernel(self) -> Kernel | None:
        """``output`` in C (kernel type ``ManipulationPD``: the same native call), in a
        context its constructor builds from the record ``[hand segment, dt, given,
        waypoint rows, waypoints, meta]`` (stateless). In an exported FMU the gains and
        the contact threshold are tunable, and the hand follows the plant's."""
        held = getattr(self, "_kernel", None)
        if held is None:
            waypoints, meta = self._waypoints, self._meta
            rec = record("ManipulationPD", hand_segment(self.hand, False), [self._params[MANIP_PARAMS.DT]], self._given,
                         [waypoints.shape[1]], waypoints, meta, tunables=_TUNABLES, links=self._links)
            ctx = context_of(rec)
            held = self._kernel = Kernel(context=ctx.address, output=KERNELS["ManipulationPD.output"], owners=(ctx,),
                                         error=self._kernel_error, nogil=True, record=rec)
        return held

    def _kernel_error(self, code: int, which: int, t: float, phase: str) -> BaseException:
        """A failure of the native output (a target out of reach, no period to match the gains
        to) as ``output`` raises it."""
        if code == MANIP_STATUS.NO_PERIOD:
            return ValueError("ManipulationPD: its gains are matched to its period, and it has none yet "
                              "(hint: give the block a period, or discretization: held)")
        return self.unreachable(code - MANIP_STATUS.UNREACHABLE, t)

    def unreachable(self, finger: int, t: float) -> UnreachableError:
        """The error of the first target of ``finger`` out of reach at time t: its pose at
        t, or a derivative step ahead or behind (the targets ``output`` needs)."""
        trajectory = self.trajectories[finger]
        for when in (t, t + DERIVATIVE_STEP, t - DERIVATIVE_STEP):
            try:
                self.joint_targets_for(finger, trajectory.sample(when))
            except UnreachableError as err:
                return err
        raise RuntimeError(f"ManipulationPD: finger '{self.hand.names[finger]}' was found out of reach at "
                           f"t = {t:g} s, but none of its targets is")


_GIVEN_AT = MANIP_RECORD.GIVEN
_TUNABLES = (
    *(Tunable(f"kp[{j + 1}]", _GIVEN_AT + GIVEN.KP + j, f"joint {j + 1} stiffness", "N m/rad", minimum=0.0)
      for j in range(9)),
    *(Tunable(f"kd[{j + 1}]", _GIVEN_AT + GIVEN.KD + j, f"joint {j + 1} damping", "N m s/rad", minimum=0.0)
      for j in range(9)),
    Tunable("contact_threshold", _GIVEN_AT + GIVEN.THRESHOLD, "normal force above which a finger carries the object",
            "N"),
)
"""ManipulationPD's parameters an exported FMU lets an importer set."""
