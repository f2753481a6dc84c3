"""Basic discrete-time blocks: one-sample delays (UnitDelay, Memory), the zero-order hold,
the discrete derivative and the moving average."""

from __future__ import annotations

import operator
from typing import Any

import numpy as np

from blocks.arrays import float_array
from blocks.block import Signal
from blocks.library import _params
from blocks.library.kernel_block import Advancing, KernelBlock
from blocks.limits import check_block_size


class UnitDelay(Advancing):
    """Delays its input by one sample: outputs the input of the previous hit (z^-1).

    Parameters
    ----------
    initial : scalar or vector
        output at the first hit; a scalar is repeated to the width
    width : int
        signal width; omit to take it from a vector 'initial' or from the connections
    """

    kernel_name = "unit_delay"

    def __init__(self, initial: Any = 0.0, width: int | None = None):
        self.initial = float_array(initial, "initial", ndim=1, allow_empty=False)
        if width is not None:
            try:
                width = operator.index(width)
            except TypeError:
                raise ValueError(f"parameter 'width' must be a positive integer, got {width!r}") from None
            if width < 1:
                raise ValueError(f"parameter 'width' must be a positive integer, got {width!r}")
            if self.initial.size not in (1, width):
                raise ValueError(
                    f"parameter 'initial' has width {self.initial.size} but parameter 'width' is {width}"
                )
        elif self.initial.size > 1 or np.ndim(initial) == 1:
            width = self.initial.size
        self.width = width
        self.inputs = {"u": width}
        self.outputs = {"y": width}
        self.feedthrough = False

    def initial_state(self) -> Signal:
        """``initial`` repeated to the port width (width 1 while it is still unresolved)."""
        width = self.outputs["y"] or self.initial.size
        return np.resize(self.initial, width).astype(float)


class ZeroOrderHold(KernelBlock):
    """Samples its input at its own period and holds it in between (y = u at each hit)."""

    kernel_name = "zero_order_hold"

    def __init__(self):
        self.inputs = {"u": None}
        self.outputs = {"y": None}
        self.feedthrough = True


class Memory(UnitDelay):
    """Outputs its input of the previous hit, at whatever rate it inherits.

    Simulink's Memory block: the same one-hit delay as UnitDelay, under the name Simulink gives it
    for blocks without a sample time of their own."""


class DiscreteDerivative(KernelBlock):
    """The discrete derivative y = K (u(n) - u(n-1)) / T, as Simulink's Discrete Derivative
    (the transfer function K (z - 1)/(T z)). Needs a period.

    Parameters
    ----------
    gain : scalar or vector
        K
    initial : scalar or vector
        the input before the first hit, u(-1)
    """

    kernel_name = "derivative"
    period_reason = "it divides by it"

    def __init__(self, gain: Any = 1.0, initial: Any = 0.0):
        self.gain = _params.elementwise("gain", gain)
        self.initial = _params.elementwise("initial", initial)
        width = _params.common_width(gain=self.gain, initial=self.initial)
        self.inputs, self.outputs = {"u": width}, {"y": width}
        self.feedthrough = True


    def initial_state(self) -> Signal:
        return np.array(_params.spread(self.initial, self.outputs["y"] or self.initial.size), dtype=float)

    def context_numbers(self):
        return (_params.spread(self.gain, self.outputs["y"]),)


class MovingAverage(KernelBlock):
    """The mean of the last ``window`` inputs (this hit's included), elementwise.

    Before the window has filled, the missing inputs count as ``initial`` (zeros: the FIR filter
    ones(window)/window from rest).

    Parameters
    ----------
    window : int
        how many hits are averaged
    initial : scalar or vector
        the inputs assumed before the first hit
    """

    kernel_name = "moving_average"

    def __init__(self, window: int = 2, initial: Any = 0.0):
        self.window = _params.integer("window", window, minimum=1, maximum=1_000_000)
        self.initial = _params.elementwise("initial", initial)
        width = _params.common_width(initial=self.initial)
        self.inputs, self.outputs = {"u": width}, {"y": width}
        self.feedthrough = True
        self._check_size(width or 1)

    def set_width(self, width: int) -> None:
        self._check_size(width)
        super().set_width(width)

    def _check_size(self, width: int) -> None:
        check_block_size(("window", self.window), ("width", width))

    def initial_state(self) -> Signal:
        width = self.outputs["y"] or self.initial.size
        return np.concatenate(((0.0,), np.tile(_params.spread(self.initial, width), self.window - 1)))

    def context_numbers(self):
        return (self.window,)
