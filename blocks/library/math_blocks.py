"""Memoryless arithmetic blocks: gain, signed sum, saturation."""

from __future__ import annotations

from functools import partial
from typing import Any, Callable, Mapping

import numpy as np

from blocks.arrays import float_array
from blocks.block import Block, Signal
from blocks.library import _kernels

# Python-float scalars cost an extra conversion inside every ufunc call; 0-d arrays
# multiply and compare against a small vector about a third faster, so scalar
# parameters are stored as 0-d float64 arrays.


class Gain(Block):
    """Multiplies the input by ``k``: scalar, elementwise vector, or matrix (y = K @ u).

    Parameters
    ----------
    k : scalar, vector or matrix
        gain: a scalar (any width), a vector (elementwise) or a matrix (y = K @ u)
    """

    def __init__(self, k: Any = 1.0):
        arr = float_array(k, "k", allow_empty=False)
        if arr.ndim > 2:
            raise ValueError(f"parameter 'k' must be a scalar, vector or matrix, got shape {arr.shape}")
        self.k = arr
        self._matrix = arr.ndim == 2
        if arr.ndim == 0:
            self.inputs, self.outputs = {"u": None}, {"y": None}
        elif arr.ndim == 1:
            self.inputs, self.outputs = {"u": arr.size}, {"y": arr.size}
        else:
            self.inputs, self.outputs = {"u": arr.shape[1]}, {"y": arr.shape[0]}
        self.feedthrough = True

    def output(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        if self._matrix:
            return {"y": self.k.dot(inputs["u"])}
        return {"y": inputs["u"] * self.k}

    def kernel(self):
        """C output: elementwise (the same bits), or the matrix product (library.c's
        ``matvec``: ``ndarray.dot`` to round-off where a row has several terms)."""
        width = self.inputs["u"]
        return _kernels.cached(self, (width, self.k.shape, self.k.tobytes()), lambda: self._build_kernel(width))

    def _build_kernel(self, width):
        if width is None:
            return None
        if self._matrix:
            rows, cols = self.k.shape
            header = (1.0, rows, cols)
        else:
            header = (0.0, self.k.size, width)
        return _kernels.make_kernel(np.concatenate((header, self.k.ravel())), "gain_output",
                                    tunables=_kernels.tunables("k", 3, self.k.shape, "gain"))


def _sum_p(i: Mapping[str, Signal]) -> Signal:
    return i["u0"].copy()


def _sum_m(i: Mapping[str, Signal]) -> Signal:
    return -i["u0"]


def _sum_pp(i: Mapping[str, Signal]) -> Signal:
    return i["u0"] + i["u1"]


def _sum_pm(i: Mapping[str, Signal]) -> Signal:
    return i["u0"] - i["u1"]


def _sum_mp(i: Mapping[str, Signal]) -> Signal:
    return i["u1"] - i["u0"]


def _sum_mm(i: Mapping[str, Signal]) -> Signal:
    r = i["u0"] + i["u1"]
    return np.negative(r, out=r)


def _sum_ppp(i: Mapping[str, Signal]) -> Signal:
    r = i["u0"] + i["u1"]
    r += i["u2"]
    return r


def _sum_ppm(i: Mapping[str, Signal]) -> Signal:
    r = i["u0"] + i["u1"]
    r -= i["u2"]
    return r


def _sum_pmm(i: Mapping[str, Signal]) -> Signal:
    r = i["u0"] - i["u1"]
    r -= i["u2"]
    return r


def _sum_general(plus: tuple[str, ...], minus: tuple[str, ...], i: Mapping[str, Signal]) -> Signal:
    """Any sign pattern: start from the first '+' input (or minus the first '-')."""
    if plus:
        r = i[plus[0]].copy()
        rest = minus
    else:
        r = -i[minus[0]]
        rest = minus[1:]
    for p in plus[1:]:
        r += i[p]
    for p in rest:
        r -= i[p]
    return r


_SUM_KERNELS: dict[str, Callable[[Mapping[str, Signal]], Signal]] = {
    "+": _sum_p,
    "-": _sum_m,
    "++": _sum_pp,
    "+-": _sum_pm,
    "-+": _sum_mp,
    "--": _sum_mm,
    "+++": _sum_ppp,
    "++-": _sum_ppm,
    "+--": _sum_pmm,
}


class Sum(Block):
    """Signed sum of the inputs ``u0, u1, ...``, one sign character per input.

    Parameters
    ----------
    signs : str
        one '+' or '-' per input, in port order u0, u1, ... (e.g. '+-' gives u0 - u1)
    """

    def __init__(self, signs: str = "++"):
        if not isinstance(signs, str) or not signs or set(signs) - {"+", "-"}:
            raise ValueError(f"parameter 'signs' must be a non-empty string of '+' and '-', got {signs!r}")
        self.signs = signs
        ports = tuple(f"u{j}" for j in range(len(signs)))
        self.inputs = {p: None for p in ports}
        self.outputs = {"y": None}
        self.feedthrough = True
        kernel = _SUM_KERNELS.get(signs)
        if kernel is None:
            plus = tuple(p for p, s in zip(ports, signs) if s == "+")
            minus = tuple(p for p, s in zip(ports, signs) if s == "-")
            kernel = partial(_sum_general, plus, minus)
        self._kernel = kernel

    def output(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        return {"y": self._kernel(inputs)}

    def kernel(self):
        width = self.outputs["y"]
        if width is None:
            return None
        signs = [1.0 if s == "+" else -1.0 for s in self.signs]
        return _kernels.cached(self, (width, self.signs), lambda: _kernels.make_kernel(
            np.concatenate(((width, len(signs), float(self.signs == "--")), signs)), "sum_output"))


class Saturation(Block):
    """Clips the input to ``[lower, upper]`` elementwise.

    Parameters
    ----------
    lower : scalar or vector
        lower limit, a scalar applying to any width; -inf for no lower limit
    upper : scalar or vector
        upper limit, a scalar applying to any width; inf for no upper limit
    """

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

    def output(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        return {"y": np.minimum(np.maximum(inputs["u"], self.lower), self.upper)}

    def kernel(self):
        width = self.outputs["y"]
        if width is None:
            return None

        def build():
            lo = np.broadcast_to(self.lower, (width,))
            hi = np.broadcast_to(self.upper, (width,))
            return _kernels.make_kernel(np.concatenate(((width,), lo, hi)), "saturation_output")

        return _kernels.cached(self, (width, np.asarray(self.lower).tobytes(), np.asarray(self.upper).tobytes()), build)
