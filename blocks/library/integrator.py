"""DiscreteIntegrator: Simulink's Discrete-Time Integrator (forward Euler, backward Euler,
trapezoidal; gain; limits; reset), and the integration rule it shares with the PID.

With the block's input u, gain K and period T, at each hit
    y(n) = clip(x(n) + c K u(n)),   x(n+1) = clip(y(n) + (T - c) K u(n)),
where c = 0 (forward Euler: T/(z-1)), T (backward Euler: T z/(z-1)) or T/2 (trapezoidal:
(T/2)(z+1)/(z-1)). The kernel is lib_dynamic.c's integrator.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from blocks.block import Signal
from blocks.library import _params
from blocks.library.kernel_block import RESETS, Advancing

METHODS = ("forward", "backward", "trapezoidal")
"""Integration rules: forward Euler, backward Euler, trapezoidal."""


def output_share(method: str, period: float) -> float:
    """c of the rule: how much of this hit's input the output already integrates (the rest,
    T - c, goes into the next state)."""
    return {"forward": 0.0, "backward": period, "trapezoidal": period / 2.0}[method]


class DiscreteIntegrator(Advancing):
    """Integrates its input: Simulink's Discrete-Time Integrator (forward Euler, backward
    Euler or trapezoidal; gain, limits, reset).

    With ``initial_is: output`` (Simulink's default) the first hit outputs ``initial``
    (clipped), and so does a hit that resets: y(0) = IC, then y(n) = y(n-1) + K T u(n-1)
    (forward), y(n-1) + K T u(n) (backward) or y(n-1) + K T (u(n) + u(n-1))/2
    (trapezoidal). With ``initial_is: state`` the state starts at (and resets to)
    ``initial``, and the block is the transfer function K T/(z-1), K T z/(z-1) or
    K (T/2)(z+1)/(z-1) from that state. The limits clip the output and the state. Needs a
    period.

    Parameters
    ----------
    gain : scalar or vector
        K, multiplying the input
    method : {'forward', 'backward', 'trapezoidal'}
        the integration rule (backward and trapezoidal have feedthrough)
    initial : scalar or vector
        the initial output (or state, see initial_is), also the value a reset restores
    initial_is : {'output', 'state'}
        whether 'initial' is the first output or the first state
    lower : scalar or vector
        lower limit of the output and state; -inf for none
    upper : scalar or vector
        upper limit of the output and state; inf for none
    reset : {'none', 'rising', 'falling', 'either', 'level'}
        adds a scalar input ``reset`` that restarts the integral on its rising edge (from
        negative to zero or positive, or from zero to positive, as Simulink's triggers),
        its falling edge, either, or at every hit while it is non-zero
    """

    kernel_name = "integrator"
    period_reason = "it integrates over time"

    def __init__(self, gain: Any = 1.0, method: str = "forward", initial: Any = 0.0, initial_is: str = "output",
                 lower: Any = -np.inf, upper: Any = np.inf, reset: str = "none"):
        self.gain = _params.elementwise("gain", gain)
        self.method = _params.choice("method", method, METHODS)
        self.initial = _params.elementwise("initial", initial)
        self.initial_is = _params.choice("initial_is", initial_is, ("output", "state"))
        self.lower = _params.elementwise("lower", lower, allow_inf=True)
        self.upper = _params.elementwise("upper", upper, allow_inf=True)
        self.reset = _params.choice("reset", reset, RESETS)
        width = _params.common_width(gain=self.gain, initial=self.initial, lower=self.lower, upper=self.upper)
        _params.check_limits(self.lower, self.upper)
        self.inputs = {"u": width, **({"reset": 1} if self.reset != "none" else {})}
        self.outputs = {"y": width}
        reads = ({"u"} if self.method != "forward" else set()) | ({"reset"} if self.reset != "none" else set())
        self.feedthrough = {"y": reads} if reads else False


    def initial_state(self) -> Signal:
        width = self.outputs["y"] or 1
        return np.concatenate((_params.spread(self.initial, width), (0.0, 0.0)))

    def context_numbers(self):
        w, T = self.outputs["y"], float(self.period)
        c = output_share(self.method, T)
        return (c, T - c, float(self.initial_is == "state"), RESETS.index(self.reset),
                *(_params.spread(p, w) for p in (self.gain, self.lower, self.upper, self.initial)))
