"""Source blocks: signals that depend only on time (or on nothing at all)."""

from __future__ import annotations

from typing import Any

import numpy as np

from blocks.arrays import float_array
from blocks.block import Signal
from blocks.library import _kernels
from blocks.library.kernel_block import HEADER, KernelBlock


def broadcast_vectors(**params: Any) -> dict[str, Signal]:
    """Parameters as vectors of one common width; a width-1 value is repeated to fit.

    Raises ValueError naming the parameters when two of them have different widths > 1.
    """
    vectors = {name: float_array(value, name, ndim=1, allow_empty=False) for name, value in params.items()}
    widths = {name: v.size for name, v in vectors.items() if v.size != 1}
    if len(set(widths.values())) > 1:
        desc = ", ".join(f"'{n}' has width {w}" for n, w in widths.items())
        raise ValueError(f"parameters must be scalars or vectors of one width: {desc}")
    width = next(iter(widths.values()), 1)
    return {name: np.repeat(v, width) if v.size != width else v for name, v in vectors.items()}


def _shape(vector: np.ndarray) -> tuple[int, ...]:
    """A parameter's shape as its tunables name it: () for one number."""
    return () if vector.size == 1 else vector.shape


class Constant(KernelBlock):
    """Outputs a fixed value at every hit.

    Parameters
    ----------
    value : scalar or vector
        the output value
    """

    kernel_name = "constant"

    def __init__(self, value: Any):
        self.value = float_array(value, "value", ndim=1, allow_empty=False)
        self.inputs = {}
        self.outputs = {"y": self.value.size}
        self.feedthrough = False

    def context_numbers(self):
        return (self.value,)

    def tunables(self):
        return _kernels.tunables("value", HEADER, _shape(self.value), "the output value")


class Step(KernelBlock):
    """Outputs ``before`` until ``time``, then ``after`` from ``time`` on (t >= time).

    Parameters
    ----------
    time : float
        switching time in seconds; the output is 'after' from this time on
    before : scalar or vector
        output before the switching time
    after : scalar or vector
        output from the switching time on
    """
    time_varying = True
    kernel_name = "step"

    def __init__(self, time: float, before: Any = 0.0, after: Any = 1.0):
        self.time = float(float_array(time, "time", ndim=0))
        vectors = broadcast_vectors(before=before, after=after)
        self.before, self.after = vectors["before"], vectors["after"]
        self.inputs = {}
        self.outputs = {"y": self.before.size}
        self.feedthrough = False

    def context_numbers(self):
        return (self.time, self.before, self.after)

    def tunables(self):
        shape, first = _shape(self.before), HEADER + 1
        return (*_kernels.tunables("time", HEADER, (), "switching time, s"),
                *_kernels.tunables("before", first, shape, "output before the switching time"),
                *_kernels.tunables("after", first + self.before.size, shape, "output from the switching time on"))


class Ramp(KernelBlock):
    """Outputs ``initial + slope * max(0, t - start)``: flat until ``start``, then linear.

    Parameters
    ----------
    slope : scalar or vector
        rate of change after the start time (units per second)
    start : float
        time in seconds at which the ramp starts rising
    initial : scalar or vector
        output value up to the start time
    """
    time_varying = True
    kernel_name = "ramp"

    def __init__(self, slope: Any = 1.0, start: float = 0.0, initial: Any = 0.0):
        self.start = float(float_array(start, "start", ndim=0))
        vectors = broadcast_vectors(slope=slope, initial=initial)
        self.slope, self.initial = vectors["slope"], vectors["initial"]
        self.inputs = {}
        self.outputs = {"y": self.slope.size}
        self.feedthrough = False

    def context_numbers(self):
        return (self.start, self.slope, self.initial)
