"""Lookup tables: LookupTable1D (y = f(u)) and LookupTable2D (y = f(u0, u1)), linearly
interpolated between breakpoints, clipped or extrapolated outside them, elementwise over
the inputs. Kernels in lib_math.c."""

from __future__ import annotations

from typing import Any

import numpy as np

from blocks.arrays import float_array
from blocks.library import _params
from blocks.library.kernel_block import KernelBlock

EXTRAPOLATIONS = ("clip", "linear")


def _breakpoints(name: str, value: Any) -> np.ndarray:
    x = float_array(value, name, ndim=1)
    if x.size < 2:
        raise ValueError(f"parameter '{name}' needs at least 2 breakpoints, got {x.size}")
    if np.any(x[1:] <= x[:-1]):
        raise ValueError(f"parameter '{name}' must be strictly increasing")
    with np.errstate(over="ignore"):
        finite_gaps = np.all(np.isfinite(x[1:] - x[:-1]))
    if not finite_gaps:  # interpolation divides by the gap: an infinite one answers nonsense
        raise ValueError(f"parameter '{name}': the gaps between breakpoints must be finite numbers (breakpoints "
                         "of +-1e308 are more than a float's range apart)")
    return x


class LookupTable1D(KernelBlock):
    """y = table(u), linear between breakpoints; outside them the end values ('clip') or the
    end segments' lines ('linear'), as Simulink's 1-D Lookup Table with linear
    interpolation. NaN in, NaN out.

    Parameters
    ----------
    breakpoints : vector
        the input values, strictly increasing (at least 2)
    table : vector
        the output at each breakpoint
    extrapolation : {'clip', 'linear'}
        what happens outside [first, last breakpoint]
    """

    kernel_name = "lookup1d"

    def __init__(self, breakpoints: Any, table: Any, extrapolation: str = "clip"):
        self.breakpoints = _breakpoints("breakpoints", breakpoints)
        self.table = float_array(table, "table", ndim=1)
        if self.table.size != self.breakpoints.size:
            raise ValueError(f"parameter 'table' must have one value per breakpoint ({self.breakpoints.size}), "
                             f"got {self.table.size}")
        self.extrapolation = _params.choice("extrapolation", extrapolation, EXTRAPOLATIONS)
        self.inputs, self.outputs = {"u": None}, {"y": None}
        self.feedthrough = True

    @classmethod
    def example(cls) -> "LookupTable1D":
        return cls([0.0, 1.0], [0.0, 1.0])

    def context_numbers(self):
        return (self.breakpoints.size, float(self.extrapolation == "linear"), self.breakpoints, self.table)


class LookupTable2D(KernelBlock):
    """y = table(u0, u1), bilinear between breakpoints, clipped or extrapolated outside.

    ``u0`` indexes the rows, ``u1`` the columns; outside them the edge values ('clip') or the edge cells' planes extended
    ('linear'). Elementwise over the two inputs. NaN in, NaN out.

    Parameters
    ----------
    row_breakpoints : vector
        values of u0 at the table's rows, strictly increasing (at least 2)
    column_breakpoints : vector
        values of u1 at the table's columns, strictly increasing (at least 2)
    table : matrix
        the output at each (row, column) breakpoint pair
    extrapolation : {'clip', 'linear'}
        what happens outside the breakpoints
    """

    kernel_name = "lookup2d"

    def __init__(self, row_breakpoints: Any, column_breakpoints: Any, table: Any, extrapolation: str = "clip"):
        self.row_breakpoints = _breakpoints("row_breakpoints", row_breakpoints)
        self.column_breakpoints = _breakpoints("column_breakpoints", column_breakpoints)
        self.table = float_array(table, "table", ndim=2)
        shape = (self.row_breakpoints.size, self.column_breakpoints.size)
        if self.table.shape != shape:
            raise ValueError(f"parameter 'table' must have shape {shape} (rows x columns of breakpoints), "
                             f"got {self.table.shape}")
        self.extrapolation = _params.choice("extrapolation", extrapolation, EXTRAPOLATIONS)
        self.inputs, self.outputs = {"u0": None, "u1": None}, {"y": None}
        self.feedthrough = True

    @classmethod
    def example(cls) -> "LookupTable2D":
        return cls([0.0, 1.0], [0.0, 1.0], [[0.0, 1.0], [1.0, 2.0]])

    def context_numbers(self):
        return (self.row_breakpoints.size, self.column_breakpoints.size, float(self.extrapolation == "linear"),
                self.row_breakpoints, self.column_breakpoints, self.table)
