"""The manipulation controller (the paper's upper level): voluntary fingertip motion.

Fingertip trajectories are given beforehand as timed waypoints (x, y, phi) per finger.
Every hit (10 ms in the paper) samples them, turns the samples into joint targets by
exact three-joint inverse kinematics and tracks them with a joint PD. Fingers without a
trajectory hold their initial joint angles.

All of that runs in one native call per hit (``manipulation_kernel.manipulation_output``,
the law in C over flat arrays packed once at load time). When a target turns out
unreachable during the run, the Python API on the same C (``finger_ik_near``) names the
finger and the distance.

Outputs: ``tau_m``, the PD torque of the voluntary motion (what the suppresser weighs
against the grasping torque), and ``tau_ff``, a feedforward that keeps the 10 ms loop's
gains small: the fingers' own gravity torques and the object's load shared equally by
the fingers in contact (``J^T`` of ``-(m g + f_support) / k``); without it the soft PD lets
a held object sag by millimetres. The optional input ``support`` is the force something
else applies to the object (the support that carries it until the hand takes it over):
the fingers carry only the rest, or they would lift the object a second time and load
every contact tangentially while the grasp closes. The suppresser adds ``tau_ff`` to the actuator command after
suppression. Keeping the feedforward out of ``tau_m`` matters: it is not voluntary
motion, and a finger that merely carries the object must not have its grasp suppressed.
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from blocks import Block
from blocks.arrays import flat_float64, float_array
from blocks.kernel import Kernel, address

from ..kernels import KERNELS, context, model_address
from ..model.hand_source import ModelsTheHand, hand_of
from ..model.port_info import DescribesHandPorts
from .inverse_kinematics import UnreachableError, finger_ik_near
from .manipulation_kernel import OK, UNREACHABLE, manipulation_output, pack_params, pack_trajectories
from .trajectory import Trajectory

DERIVATIVE_STEP = 1e-3
"""Seconds either side of t for the joint-velocity target (central difference of the IK)."""


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
        joint stiffness, N m/rad
    kd : scalar or 9 values
        joint damping, N m s/rad
    gravity_compensation : bool
        add the fingers' own gravity torques
    load_compensation : bool
        add J^T of the object's load (weight plus input support) shared by the fingers in
        contact
    contact_threshold : float
        normal force, N, above which a finger carries part of the object
    """

    type_name = "ManipulationPD"
    time_varying = True

    def __init__(self, hand, trajectories: Mapping[str, Any] | None = None, kp: Any = 2.0, kd: Any = 0.01,
                 gravity_compensation: bool = True, load_compensation: bool = True,
                 contact_threshold: float = 0.05):
        self.hand = hand_of(hand)
        self.kp = float_array(kp, "kp", ndim=1, width=9, broadcast=True)
        self.kd = float_array(kd, "kd", ndim=1, width=9, broadcast=True)
        if np.any(self.kp < 0) or np.any(self.kd < 0):
            raise ValueError("kp and kd must be non-negative")
        self.gravity_compensation = bool(gravity_compensation)
        self.load_compensation = bool(load_compensation)
        self.threshold = float(contact_threshold)
        self.weight = self.hand.params.object.mass * self.hand.gravity
        self.trajectories = self.parse_trajectories(trajectories or {})
        self.inputs = {"q": 9, "qd": 9, "fn": 3, "support": 3}
        self.input_defaults = {"support": np.zeros(3)}
        self.outputs = {"tau_m": 9, "tau_ff": 9, "q_ref": 9}
        self.feedthrough = True
        # the native output's flat arrays (built from the attributes above, once)
        self._model = self.hand.native
        self._params = pack_params(self.hand.q0, self.kp, self.kd, self.hand.gravity, self.weight, self.threshold,
                                   self.gravity_compensation, self.load_compensation, DERIVATIVE_STEP)
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

    def joint_targets_for(self, finger: int, point: np.ndarray) -> np.ndarray:
        """Joint angles (3,) of one finger for a tip target, on the branch nearest q0."""
        return finger_ik_near(self.hand, finger, point, self.hand.q0[3 * finger:3 * finger + 3])

    def output(self, t: float, state: Any, inputs: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
        """One native call on the arrays packed in ``__init__`` (so parameters changed on
        the object afterwards are not seen). Inputs the native call refuses for their type
        (lists, other dtypes, strided views) are converted to float64 first; inputs of the
        wrong width raise ``ValueError`` naming the port, a target out of reach
        ``UnreachableError`` naming the finger."""
        out = np.empty((3, 9))
        q, qd, fn, support = inputs["q"], inputs["qd"], inputs["fn"], inputs.get("support", self.input_defaults["support"])
        try:
            status = manipulation_output(self._model, self._params, self._waypoints, self._meta, t, q, qd, fn, support, out)
        except TypeError:
            status = manipulation_output(self._model, self._params, self._waypoints, self._meta, t, flat_float64(q),
                                         flat_float64(qd), flat_float64(fn), flat_float64(support), out)
        if status != OK:
            raise self.unreachable(status - UNREACHABLE, t)
        return {"tau_m": out[0], "tau_ff": out[1], "q_ref": out[2]}

    def kernel(self) -> Kernel | None:
        """``output`` in C: the same native call on the arrays packed in ``__init__``
        (stateless; the period does not enter)."""
        model, params, waypoints, meta = self._model, self._params, self._waypoints, self._meta
        ctx = context(model_address(model), address(params), address(waypoints), address(meta),
                      waypoints.shape[1])
        return Kernel(
            context=address(ctx),
            output=KERNELS["ManipulationPD.output"],
            owners=(ctx, model, params, waypoints, meta),
            error=self._kernel_error,
            nogil=True,
        )

    def _kernel_error(self, code: int, which: int, t: float, phase: str) -> BaseException:
        """The kernel's failure (a target out of reach) as ``output`` raises it."""
        return self.unreachable(code - UNREACHABLE, t)

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
