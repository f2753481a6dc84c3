"""Basic discrete-time blocks: one-sample delay and zero-order hold."""

from __future__ import annotations

import operator
from typing import Any, Mapping

import numpy as np

from blocks.arrays import float_array
from blocks.block import Block, Signal
from blocks.library import _kernels


class UnitDelay(Block):
    """Delays its input by one sample: outputs the input of the previous hit (z^-1).

    Parameters
    ----------
    initial : scalar or vector
        output at the first hit; a scalar is repeated to the width
    width : int
        signal width; omit to take it from a vector 'initial' or from the connections
    """

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

    def output(self, t: float, state: Signal, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        return {"y": state.copy()}

    def update(self, t: float, state: Signal, inputs: Mapping[str, Signal]) -> Signal:
        return inputs["u"].copy()

    def advance(self, t: float, state: Signal, inputs: Mapping[str, Signal], n: int):
        """Held input: every one of the ``n`` following outputs is that input."""
        u = inputs["u"]
        if n <= 0:
            return state, {"y": np.empty((0, state.size))}
        return u.copy(), {"y": np.tile(u, (n, 1))}

    def kernel(self):
        width = self.outputs["y"]
        if width is None:
            return None
        return _kernels.cached(self, (width,), lambda: _kernels.make_kernel(
            np.array([width], dtype=float), "unit_delay_output", "unit_delay_update", "unit_delay_advance"))


class ZeroOrderHold(Block):
    """Samples its input at its own period and holds it in between (y = u at each hit)."""

    def __init__(self):
        self.inputs = {"u": None}
        self.outputs = {"y": None}
        self.feedthrough = True

    def output(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        return {"y": inputs["u"].copy()}

    def kernel(self):
        width = self.outputs["y"]
        if width is None:
            return None
        return _kernels.cached(self, (width,), lambda: _kernels.make_kernel(
            np.array([width], dtype=float), "zero_order_hold_output"))
