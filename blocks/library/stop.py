"""Stop: ends the run when its input is non-zero, as Simulink's Stop Simulation block."""

from __future__ import annotations

import numpy as np

from blocks.block import Signal
from blocks.library.kernel_block import KernelBlock


class Stop(KernelBlock):
    """Ends the run when its input is non-zero (Simulink's Stop Simulation).

    At a hit where any element of its input is non-zero (NaN included), its update raises EndRun, so the run finishes that tick, goes on to the block's next
    hit (or t_end, if that comes first) and ends there as at t_end; run.json's
    ``ended_by`` names the block and the element. Connect a Compare or Relational block to
    stop on a condition. It has no outputs; its state says whether it has stopped."""

    kernel_name = "stop"

    def __init__(self):
        self.inputs, self.outputs = {"u": None}, {}
        self.feedthrough = False

    def initial_state(self) -> Signal:
        return np.zeros(1)

    def end_reason(self, which: int) -> str:
        element = "input" if self.inputs["u"] == 1 else f"input element {which}"
        return f"{element} is non-zero"

    def context_numbers(self):
        return (self.inputs["u"],)
