"""Controller mathematics of the hierarchical hand controller, on its compiled laws.

The laws are C (``hierhand/csrc/reflex.c``, ``manipulation.c``, ``suppresser.c``); the
blocks call them once per hit and these functions call the same C, so each law has one
implementation (its readable numpy form lives in the tests, as the oracle it is checked
against).

- ``internal_forces``: grasp matrix, internal (squeeze) force directions, the projection
  onto internal forces, and the friction-cone scaling used by the grasping reflex.
- ``inverse_kinematics``: exact three-joint finger IK/FK and whole-hand IK.
- ``trajectory``: timed fingertip waypoints with linear or minimum-jerk segments.
- ``suppresser_law``: the suppresser's sigmoid gain on the grasping torque.

The blocks that use them (reflex, manipulation, suppresser, and the small ``JointLowPass``
filter) live beside these modules, with the laws' bindings that pack their parameters
(``reflex_law``, ``manipulation_law``).
"""

from .internal_forces import (
    friction_scale,
    grasp_matrix,
    internal_directions,
    project_internal,
    required_scale_from_sensors,
)
from .inverse_kinematics import UnreachableError, finger_fk, finger_ik, finger_ik_near, hand_ik, wrap_angle
from .suppresser_law import finger_shares, sigmoid, suppress
from .trajectory import Trajectory

__all__ = [
    "Trajectory",
    "UnreachableError",
    "finger_fk",
    "finger_ik",
    "finger_ik_near",
    "finger_shares",
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
