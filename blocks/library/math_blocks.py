"""Memoryless arithmetic blocks: gain, signed sum, saturation."""

from __future__ import annotations

from typing import Any

import numpy as np

from blocks.arrays import float_array
from blocks.library import _kernels
from blocks.library.kernel_block import HEADER, KernelBlock


class Gain(KernelBlock):
    """Multiplies the input by ``k``: scalar, elementwise vector, or matrix (y = K @ u).

    Parameters
    ----------
    k : scalar, vector or matrix
        gain: a scalar (any width), a vector (elementwise) or a matrix (y = K @ u)
    """

    kernel_name = "gain"

    def __init__(self, k: Any = 1.0):
        arr = float_array(k, "k", allow_empty=False)
        if arr.ndim > 2:
            raise ValueError(f"parameter 'k' must be a scalar, vector or matrix, got shape {arr.shape}")
        self.k = arr
        if arr.ndim == 0:
            self.inputs, self.outputs = {"u": None}, {"y": None}
        elif arr.ndim == 1:
            self.inputs, self.outputs = {"u": arr.size}, {"y": arr.size}
        else:
            self.inputs, self.outputs = {"u": arr.shape[1]}, {"y": arr.shape[0]}
        self.feedthrough = True

    def context_numbers(self):
        """[mode, rows, cols, k]: mode 1 a matrix (rows x cols, library.c's ``matvec``, which
        sums each row in column order), 0 elementwise (k's size, the input width)."""
        if self.k.ndim == 2:
            return ((1.0, *self.k.shape), self.k)
        return ((0.0, self.k.size, self.inputs["u"]), self.k)

    def tunables(self):
        return _kernels.tunables("k", HEADER + 3, self.k.shape, "gain")


class Sum(KernelBlock):
    """Signed sum of the inputs ``u0, u1, ...``, one sign character per input.

    The first '+' input, the other '+' ones added in port order, then the '-' ones
    subtracted (with no '+' input: minus the first, then the others subtracted); '--' is
    -(u0 + u1).

    Parameters
    ----------
    signs : str
        one '+' or '-' per input, in port order u0, u1, ... (e.g. '+-' gives u0 - u1)
    """

    kernel_name = "sum"

    def __init__(self, signs: str = "++"):
        if not isinstance(signs, str) or not signs or set(signs) - {"+", "-"}:
            raise ValueError(f"parameter 'signs' must be a non-empty string of '+' and '-', got {signs!r}")
        self.signs = signs
        self.inputs = {f"u{j}": None for j in range(len(signs))}
        self.outputs = {"y": None}
        self.feedthrough = True

    def context_numbers(self):
        signs = [1.0 if s == "+" else -1.0 for s in self.signs]
        return ((len(signs), float(self.signs == "--")), signs)


class Saturation(KernelBlock):
    """Clips the input to ``[lower, upper]`` elementwise (NaN passes through).

    Parameters
    ----------
    lower : scalar or vector
        lower limit, a scalar applying to any width; -inf for no lower limit
    upper : scalar or vector
        upper limit, a scalar applying to any width; inf for no upper limit
    """

    kernel_name = "saturation"

    def __init__(self, lower: Any = -1.0, upper: Any = 1.0):
        lo = float_array(lower, "lower", allow_inf=True, allow_empty=False)
        hi = float_array(upper, "upper", allow_inf=True, allow_empty=False)
        for name, arr in (("lower", lo), ("upper", hi)):
            if arr.ndim > 1:
                raise ValueError(f"parameter '{name}' must be a scalar or a vector, got shape {arr.shape}")
        if lo.ndim == 1 and hi.ndim == 1 and lo.size != hi.size and 1 not in (lo.size, hi.size):
            raise ValueError(
                f"parameters 'lower' and 'upper' must have one width, got {lo.size} and {hi.size}"
            )
        if np.any(lo > hi):
            raise ValueError(f"parameter 'lower' must be <= 'upper', got lower={lower!r}, upper={upper!r}")
        if lo.ndim == 0 and hi.ndim == 0:
            width = None
        else:
            width = max(lo.size, hi.size)
            lo, hi = np.broadcast_to(lo, (width,)).copy(), np.broadcast_to(hi, (width,)).copy()
        self.lower, self.upper = lo, hi
        self.inputs, self.outputs = {"u": width}, {"y": width}
        self.feedthrough = True

    def context_numbers(self):
        width = self.outputs["y"]
        return (np.broadcast_to(self.lower, (width,)), np.broadcast_to(self.upper, (width,)))
