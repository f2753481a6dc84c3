"""LookupTable1D against numpy.interp (clip) and scipy's interp1d (extrapolate), and
LookupTable2D against scipy's RegularGridInterpolator, at random points in and around
the breakpoints, at the breakpoints themselves and at NaN."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import RegularGridInterpolator, interp1d

from blocks.library import LookupTable1D, LookupTable2D

from .stepping import step

RNG = np.random.default_rng(8)
X = np.array([-1.0, 0.0, 0.5, 2.0, 3.5])
Y = np.array([2.0, -1.0, 0.0, 4.0, 3.0])


def points(x: np.ndarray, n: int = 300) -> np.ndarray:
    span = x[-1] - x[0]
    return np.concatenate((RNG.uniform(x[0] - span, x[-1] + span, n), x))


def test_1d_clip_is_numpy_interp():
    u = points(X)
    y = step(LookupTable1D(X, Y), {"u": u[:, None]})["y"][:, 0]
    np.testing.assert_allclose(y, np.interp(u, X, Y), rtol=0, atol=1e-14)
    np.testing.assert_array_equal(y[-len(X):], Y)  # exactly the table at the breakpoints


def test_1d_linear_extrapolates_the_end_segments_as_scipy():
    u = points(X)
    y = step(LookupTable1D(X, Y, extrapolation="linear"), {"u": u[:, None]})["y"][:, 0]
    np.testing.assert_allclose(y, interp1d(X, Y, fill_value="extrapolate")(u), rtol=1e-13, atol=1e-13)


def test_1d_is_elementwise_and_passes_nan():
    u = np.array([[0.25, 3.0, np.nan]])
    y = step(LookupTable1D(X, Y), {"u": u})["y"]
    np.testing.assert_allclose(y[0, :2], np.interp(u[0, :2], X, Y))
    assert np.isnan(y[0, 2])


ROWS = np.array([0.0, 1.0, 3.0])
COLS = np.array([-2.0, -1.0, 0.5, 1.0])
TABLE = RNG.normal(size=(3, 4))


@pytest.mark.parametrize("extrapolation", ["clip", "linear"])
def test_2d_is_bilinear_as_scipy(extrapolation):
    a, b = points(ROWS, 200), points(COLS, 200)[:len(points(ROWS, 200))]
    grid = RegularGridInterpolator((ROWS, COLS), TABLE, method="linear", bounds_error=False, fill_value=None)
    if extrapolation == "clip":
        expected = grid(np.column_stack((np.clip(a, ROWS[0], ROWS[-1]), np.clip(b, COLS[0], COLS[-1]))))
    else:
        expected = grid(np.column_stack((a, b)))
    y = step(LookupTable2D(ROWS, COLS, TABLE, extrapolation), {"u0": a[:, None], "u1": b[:, None]})["y"][:, 0]
    np.testing.assert_allclose(y, expected, rtol=1e-13, atol=1e-13)


def test_2d_hits_the_table_at_its_breakpoints():
    a, b = np.meshgrid(ROWS, COLS, indexing="ij")
    y = step(LookupTable2D(ROWS, COLS, TABLE), {"u0": a.reshape(1, -1), "u1": b.reshape(1, -1)})["y"]
    np.testing.assert_array_equal(y.reshape(3, 4), TABLE)


@pytest.mark.parametrize("cls, params, word", [
    (LookupTable1D, dict(breakpoints=[0.0], table=[1.0]), "at least 2"),
    (LookupTable1D, dict(breakpoints=[0.0, 0.0], table=[1.0, 2.0]), "strictly increasing"),
    (LookupTable1D, dict(breakpoints=[0.0, 1.0], table=[1.0]), "one value per breakpoint"),
    (LookupTable1D, dict(breakpoints=[0.0, 1.0], table=[1.0, 2.0], extrapolation="nearest"), "'extrapolation'"),
    (LookupTable2D, dict(row_breakpoints=[0, 1], column_breakpoints=[0, 1, 2], table=[[1, 2], [3, 4]]),
     "shape \\(2, 3\\)"),
    (LookupTable2D, dict(row_breakpoints=[1, 0], column_breakpoints=[0, 1], table=[[1, 2], [3, 4]]),
     "'row_breakpoints'"),
])
def test_bad_parameters_are_named(cls, params, word):
    with pytest.raises(ValueError, match=word):
        cls(**params)
