"""The compiled laws' Python entry points name the argument they cannot take."""

from __future__ import annotations

import numpy as np
import pytest

from hierhand import _native
from hierhand.model import Hand

GEOMETRY = np.array([0.0, 0.0, 0.0, 0.04, 0.03, 0.01])


@pytest.mark.parametrize(
    "call, error, match",
    [
        (lambda: _native.project_internal(np.zeros(3), np.zeros(3), np.zeros(3)), ValueError,
         r"^points must hold k x 2 values \(k >= 1\), got 3 values$"),
        (lambda: _native.project_internal(np.zeros(4), np.zeros(6), np.zeros(4)), ValueError,
         "^f must hold 4 values, got 6$"),
        (lambda: _native.project_internal(np.zeros(4), np.zeros(4), np.zeros(2)), ValueError,
         "^out must hold 4 values, got 2$"),
        (lambda: _native.centroid_squeeze(np.zeros(4), 1e-12, np.zeros(4)), ValueError,
         "^internal forces are undefined: all contact points coincide$"),
        (lambda: _native.centroid_squeeze(np.zeros(4), "tight", np.zeros(4)), TypeError, "coincident_rtol"),
        (lambda: _native.finger_fk(GEOMETRY[:5], np.zeros(3), np.zeros(3)), ValueError,
         "^geometry must hold 6 values, got 5$"),
        (lambda: _native.finger_ik(GEOMETRY, 1e-9, 0.05, 0.0, 0.0, 0, np.zeros(3), np.zeros(3)), ValueError,
         "^elbow must be"),
        (lambda: _native.finger_ik(GEOMETRY, 1e-9, 0.05, 0.0, 0.0, 1, np.zeros(2), np.zeros(3)), ValueError,
         "^q must hold 3 values"),
        (lambda: _native.ik_near(Hand.default().native, 1, 1e-9, 0.05, 0.0, 0.0, np.zeros(2), np.zeros(3),
                                 np.zeros(3)), ValueError, "^ref must hold 3 values"),
        (lambda: _native.wrap_angles(np.zeros(3), np.zeros(2)), ValueError, "^out must hold 3 values, got 2$"),
        (lambda: _native.wrap_angles(np.zeros(3, dtype=np.float32), np.zeros(3)), TypeError, "^a must hold float64"),
        (lambda: _native.sigmoid([0.0], np.zeros(1)), TypeError, "^x must be a C-contiguous float64 array"),
        (lambda: _native.suppress_joints(*np.zeros((4, 2)), 7, np.zeros(2)), ValueError, "^mode must be"),
        (lambda: _native.suppress_joints(np.zeros(2), np.zeros(2), np.zeros(1), np.zeros(2), 1, np.zeros(2)),
         ValueError, "^S_a must hold 2 values, got 1$"),
        (lambda: _native.finger_shares(np.zeros(9), np.zeros(9), np.zeros(9)), ValueError,
         "^share must hold 3 values, got 9$"),
        (lambda: _native.trajectory_velocity(np.zeros(4), 1, 0.0, np.zeros(4)), ValueError,
         "^out must hold 3 values, got 4$"),
    ],
)
def test_bad_arguments_are_named(call, error, match):
    with pytest.raises(error, match=match):
        call()
