"""Discontinuities: DeadZone, Quantizer (memoryless), RateLimiter and Backlash (with the
previous output as state), with Simulink's semantics, elementwise. Kernels in lib_math.c
and lib_dynamic.c."""

from __future__ import annotations

from typing import Any

import numpy as np

from blocks.block import Signal
from blocks.library import _params
from blocks.library.arithmetic import Elementwise


class DeadZone(Elementwise):
    """Zero inside [start, end]; outside, the distance past the nearer edge (u - end above
    it, u - start below it), as Simulink's Dead Zone.

    Parameters
    ----------
    start : scalar or vector
        lower edge of the dead zone
    end : scalar or vector
        upper edge of the dead zone (>= start)
    """

    kernel_name = "dead_zone"

    def __init__(self, start: Any = -0.5, end: Any = 0.5):
        self.start = _params.elementwise("start", start)
        self.end = _params.elementwise("end", end)
        width = _params.common_width(start=self.start, end=self.end)
        if np.any(self.start > self.end):
            raise ValueError(f"parameter 'start' must be <= 'end', got start={start!r}, end={end!r}")
        self._ports(width)

    def context_numbers(self):
        w = self.outputs["y"]
        return (_params.spread(self.start, w), _params.spread(self.end, w))


class Quantizer(Elementwise):
    """Rounds to a multiple of the interval: y = q round(u / q), halves away from zero (as
    Simulink's Quantizer).

    Parameters
    ----------
    interval : scalar or vector
        the quantization interval q (> 0)
    """

    kernel_name = "quantizer"

    def __init__(self, interval: Any = 0.5):
        self.interval = _params.elementwise("interval", interval, positive=True)
        self._ports(_params.common_width(interval=self.interval))

    def context_numbers(self):
        return (_params.spread(self.interval, self.outputs["y"]),)


class _WithPreviousOutput(Elementwise):
    """An elementwise block whose state is its previous output, starting at ``initial``."""

    initial: np.ndarray

    def initial_state(self) -> Signal:
        return np.array(_params.spread(self.initial, self.outputs["y"] or self.initial.size), dtype=float)


class RateLimiter(_WithPreviousOutput):
    """Limits the output's rate of change to [falling, rising] units per second.

    With rate = (u - y_prev) / T, the output is y_prev + T *
    rising above the rising rate, y_prev + T * falling below the falling rate, else u
    (Simulink's Rate Limiter in discrete mode; y_prev starts at ``initial``). Needs a period.

    Parameters
    ----------
    rising : scalar or vector
        largest rate of increase, units per second (>= 0; inf for none)
    falling : scalar or vector
        largest rate of decrease, units per second (<= 0; -inf for none)
    initial : scalar or vector
        the output before the first hit
    """

    kernel_name = "rate_limiter"
    period_reason = "its rates are per second"

    def __init__(self, rising: Any = 1.0, falling: Any = -1.0, initial: Any = 0.0):
        self.rising = _params.elementwise("rising", rising, nonnegative=True, allow_inf=True)
        self.falling = _params.elementwise("falling", falling, allow_inf=True)
        if np.any(self.falling > 0):
            raise ValueError(f"parameter 'falling' must not be positive, got {falling!r}")
        self.initial = _params.elementwise("initial", initial)
        self._ports(_params.common_width(rising=self.rising, falling=self.falling, initial=self.initial))


    def context_numbers(self):
        w = self.outputs["y"]
        return (_params.spread(self.rising, w), _params.spread(self.falling, w))


class Backlash(_WithPreviousOutput):
    """Play in a mechanism: the output holds until the input has moved half the deadband
    away from it, then follows the input at that distance (Simulink's Backlash).

    Parameters
    ----------
    width : scalar or vector
        the deadband's width (>= 0)
    initial : scalar or vector
        the output before the first hit
    """

    kernel_name = "backlash"

    def __init__(self, width: Any = 1.0, initial: Any = 0.0):
        self.width = _params.elementwise("width", width, nonnegative=True)
        self.initial = _params.elementwise("initial", initial)
        self._ports(_params.common_width(width=self.width, initial=self.initial))

    def context_numbers(self):
        return (_params.spread(self.width, self.outputs["y"]) / 2.0,)
