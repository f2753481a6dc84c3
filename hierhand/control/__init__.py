"""Controller mathematics of the hierarchical hand controller, as pure numpy functions.

- ``internal_forces``: grasp matrix, internal (squeeze) force directions, the projection
  onto internal forces, and the friction-cone scaling used by the grasping reflex.
- ``inverse_kinematics``: exact three-joint finger IK/FK and whole-hand IK.
- ``trajectory``: timed fingertip waypoints with linear or minimum-jerk segments.
- ``suppression``: the suppresser's sigmoid gain on the grasping torque.

The blocks that use them (reflex, manipulation, suppresser) live beside these modules.
"""

from .internal_forces import (
    friction_scale,
    grasp_matrix,
    internal_directions,
    project_internal,
    required_scale_from_sensors,
)
from .inverse_kinematics import UnreachableError, finger_fk, finger_ik, finger_ik_near, hand_ik, wrap_angle
from .suppression import sigmoid, suppress
from .trajectory import Trajectory

__all__ = [
    "Trajectory",
    "UnreachableError",
    "finger_fk",
    "finger_ik",
    "finger_ik_near",
    "friction_scale",
    "grasp_matrix",
    "hand_ik",
    "internal_directions",
    "project_internal",
    "required_scale_from_sensors",
    "sigmoid",
    "suppress",
    "wrap_angle",
]
