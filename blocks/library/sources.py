"""Source blocks: signals that depend only on time (or on nothing at all)."""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from blocks.arrays import float_array
from blocks.block import Block, Signal
from blocks.library import _kernels


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


class Constant(Block):
    """Outputs a fixed value at every hit.

    Parameters
    ----------
    value : scalar or vector
        the output value
    """

    def __init__(self, value: Any):
        self.value = float_array(value, "value", ndim=1, allow_empty=False)
        self.inputs = {}
        self.outputs = {"y": self.value.size}
        self.feedthrough = False

    def output(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        return {"y": self.value.copy()}

    def kernel(self):
        return _kernels.cached(self, (self.value.tobytes(),), lambda: _kernels.make_kernel(
            np.concatenate(((self.value.size,), self.value)), "constant_output",
            tunables=_kernels.tunables("value", 1, self._shape(), "the output value")))

    def _shape(self) -> tuple[int, ...]:
        return () if self.value.size == 1 else self.value.shape


class Step(Block):
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

    def __init__(self, time: float, before: Any = 0.0, after: Any = 1.0):
        self.time = float(float_array(time, "time", ndim=0))
        vectors = broadcast_vectors(before=before, after=after)
        self.before, self.after = vectors["before"], vectors["after"]
        self.inputs = {}
        self.outputs = {"y": self.before.size}
        self.feedthrough = False

    def output(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        return {"y": (self.before if t < self.time else self.after).copy()}

    def kernel(self):
        w = self.before.size
        key = (self.time, self.before.tobytes(), self.after.tobytes())
        shape = () if w == 1 else (w,)
        return _kernels.cached(self, key, lambda: _kernels.make_kernel(
            np.concatenate(((w, self.time), self.before, self.after)), "step_output",
            tunables=(*_kernels.tunables("time", 1, (), "switching time, s"),
                      *_kernels.tunables("before", 2, shape, "output before the switching time"),
                      *_kernels.tunables("after", 2 + w, shape, "output from the switching time on"))))


class Ramp(Block):
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

    def __init__(self, slope: Any = 1.0, start: float = 0.0, initial: Any = 0.0):
        self.start = float(float_array(start, "start", ndim=0))
        vectors = broadcast_vectors(slope=slope, initial=initial)
        self.slope, self.initial = vectors["slope"], vectors["initial"]
        self.inputs = {}
        self.outputs = {"y": self.slope.size}
        self.feedthrough = False

    def output(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        elapsed = t - self.start
        if elapsed <= 0.0:
            return {"y": self.initial.copy()}
        return {"y": self.initial + self.slope * elapsed}

    def kernel(self):
        w = self.slope.size
        key = (self.start, self.slope.tobytes(), self.initial.tobytes())
        return _kernels.cached(self, key, lambda: _kernels.make_kernel(
            np.concatenate(((w, self.start), self.slope, self.initial)), "ramp_output"))
