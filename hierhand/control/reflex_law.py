"""The grasping reflex's compiled law (``GraspReflex``): one native call per output / update.

The reflex runs every 1 ms, so a hit must cost about a microsecond. The law lives in C
(``hierhand/csrc/reflex.c``, reached through ``hierhand._native``): the grasp matrix
solve written out by hand, the tip Jacobians from the plant's own kinematics, no
allocation. ``internal_forces`` calls the same C for its ``project_internal`` and
``internal_directions``.

Parameters travel packed in one array (``REFLEX_PARAMS``, built by ``pack_params`` from the
block's numbers as given, ``REFLEX_GIVEN``) so that a call costs little to dispatch. The
slots are declared once, in ``hierhand/csrc/layouts.h`` (``hierhand.layouts``).

The functions here return fresh arrays. Inputs the native call refuses for their type
(lists, other dtypes, non-contiguous arrays) are converted to float64 and passed again;
inputs of the wrong width raise ``ValueError`` naming the port.
"""

from __future__ import annotations

import numpy as np

from blocks.arrays import flat_float64

from .. import _native
from ..layouts import REFLEX_OUT, REFLEX_STATE

_directions = _native.reflex_directions
_forces = _native.reflex_forces
_output = _native.reflex_output
_update = _native.reflex_update

reflex_failure = _native.reflex_failure
"""``reflex_failure(code)``: the exception (not raised) that the native reflex calls raise
for a failure status: the error of ``GraspReflex``'s kernel."""

WHOLE_SHARE = np.ones(3)
"""The ``share`` input when nothing overrides the reflex: every finger's command keeps its whole grasping torque."""


pack_params = _native.reflex_pack
"""``pack_params(given, hand_vector, dt) -> params``: the block's parameters (``REFLEX_GIVEN``)
checked and packed into the native calls' flat array (``REFLEX_PARAMS``: the ratio target
``safety_ratio / (1 + margin)``, the hand's tip radii, the period ``dt``); ValueError
naming a bad parameter. The checks are hierhand/csrc/control_params.c's, which an exported
FMU applies too."""


def reflex_directions(params, state, tip, normal, fn) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(g (3, 2), grasp (3,) bool, touching (3,) bool): ``GraspReflex.directions``.

    ``touching``: ``fn > contact_threshold``; ``grasp``: touching, or listed in 'grasp',
    not handed over when it last touched (state[1 + i] == 0) and not touching. With fewer
    than two fingers in the grasp ``g`` is 0. With two or more touching, ``g`` is
    ``(I - G^+ G) push`` over them at their contact points (tip centre plus radius along the
    normal), each pushing along its normal, blended toward the internal force of the other
    two by the hold (state[4 + i]) of a third one held in part; an approaching finger gets a
    unit push toward the touching ones. With fewer touching, the projection is over the
    whole grasp, an approaching finger pushing toward the others' centroid. Where the
    projection leaves some finger not pushing (``g_i . push_i <= 0``), the centroid squeeze
    ``c - p_i``; largest row length 1 (of the members).
    """
    g = np.empty((3, 2))
    flags = np.empty(6)
    try:
        _directions(params, state, tip, normal, fn, g, flags)
    except TypeError:
        _directions(params, *map(flat_float64, (state, tip, normal, fn)), g, flags)
    return g, flags[:3] != 0.0, flags[3:] != 0.0


def reflex_forces(params, state, tip, normal, fn) -> tuple[np.ndarray, np.ndarray]:
    """(f (3, 2), grasp (3,) bool): ``GraspReflex.forces``; ``g_i`` times the scale for a
    touching finger, else scaled to ``approach_force`` (zero where ``g_i`` is)."""
    f = np.empty((3, 2))
    grasp = np.empty(3)
    try:
        _forces(params, state, tip, normal, fn, f, grasp)
    except TypeError:
        _forces(params, *map(flat_float64, (state, tip, normal, fn)), f, grasp)
    return f, grasp != 0.0


def reflex_output(model, params, state, q, tip, normal, fn) -> np.ndarray:
    """(15,) fresh array ``[tau_g (9), |f_i| (3), in grasp (3, 0/1)]``.

    ``tau_g`` stacks ``J_i^T f_i``, ``J_i`` the Jacobian of finger i's tip centre at ``q``
    (``model``: the hand's ``hierhand._native.Model``, ``Hand.native``).
    """
    out = np.empty(REFLEX_OUT.size)
    try:
        _output(model, params, state, tip, normal, fn, q, out)
    except TypeError:
        _output(model, params, *map(flat_float64, (state, tip, normal, fn, q)), out)
    return out


def reflex_update(params, state, tip, normal, fn, ft, share=WHOLE_SHARE) -> np.ndarray:
    """(7,) fresh next state ``[scale, handed over (3), hold (3)]``.

    Each touching finger's hold: 1 for the two with the largest ``share`` (3 values: the
    suppresser's output), for a third 1 down to ``hold_share`` falling linearly to 0 at
    ``release_share`` (all 1 without ``follow_suppression``); a finger out of contact keeps
    its hold. With at least two fingers touching, the scale moves by ``ki * dt * max_i
    hold_i (need_i - fn_i) / max(g_i . n_i, 1e-3)`` over them, ``need_i = max(min_force
    |g_i|, |ft_i| / ratio_target)``, clipped to ``[0, max_force]``. A touching finger is
    marked handed over (1.0) while its hold is below 1; one out of contact keeps its mark.
    """
    new = np.empty(REFLEX_STATE.size)
    try:
        _update(params, state, tip, normal, fn, ft, share, new)
    except TypeError:
        _update(params, *map(flat_float64, (state, tip, normal, fn, ft, share)), new)
    return new

