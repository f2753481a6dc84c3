"""PID: Simulink's Discrete PID Controller (parallel and ideal forms, filtered derivative,
forward/backward/trapezoidal rules, output limits with anti-windup, tracking, reset).

Parallel form: C(z) = P + I a(z) + D N / (1 + N b(z)); ideal form: P [1 + I a(z) +
D N / (1 + N b(z))], where a(z) and b(z) are the integrator's and the derivative filter's
rule (T/(z-1), T z/(z-1) or (T/2)(z+1)/(z-1)). Unfiltered, the derivative is
D (z-1)/(T z). The kernel is lib_dynamic.c's pid, which says the equations at a hit.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any

import numpy as np

from blocks.block import Signal
from blocks.library import _params
from blocks.library.integrator import METHODS, output_share
from blocks.library.kernel_block import RESETS, Advancing

FORMS = ("parallel", "ideal")
ANTI_WINDUP = ("none", "clamping", "back_calculation")


class PID(Advancing):
    """A discrete PID controller of its input ``u`` (the error), as Simulink's Discrete PID
    Controller, with output limits, anti-windup, tracking and reset.

    C(z) = P + I a(z) + D N / (1 + N b(z)) in parallel form, P times
    [1 + I a(z) + D N / (1 + N b(z))] in ideal form, a and b the integrator's and the
    filter's rule: forward Euler T/(z-1), backward Euler T z/(z-1), trapezoidal
    (T/2)(z+1)/(z-1). The output may be limited to [lower, upper]; then anti-windup keeps
    the integral from running away: 'clamping' stops integrating while the output is
    limited and the error drives it further, 'back_calculation' feeds Kb (y - unlimited y)
    back into the integrator. With ``tracking`` an input ``track`` pulls the integral so
    that the output follows it (Kt (track - y) into the integrator, for bumpless
    transfer); with ``reset`` an input ``reset`` restarts the integrator and filter from
    their initial values. Anti-windup and tracking act on the integrator's next state
    (they use this hit's output). Gains may be vectors: one controller per element.
    Needs a period.

    Parameters
    ----------
    P : scalar or vector
        proportional gain
    I : scalar or vector
        integral gain (ideal form: multiplied by P)
    D : scalar or vector
        derivative gain (ideal form: multiplied by P)
    N : scalar or vector
        derivative filter coefficient (rad/s): the filter's pole; with forward Euler
        N T must be below 2 (a stable filter)
    form : {'parallel', 'ideal'}
        parallel P + I a + D N/(1 + N b), or ideal P (1 + I a + D N/(1 + N b))
    integrator : {'forward', 'backward', 'trapezoidal'}
        the integrator's rule a(z)
    filter : {'forward', 'backward', 'trapezoidal'}
        the derivative filter's rule b(z)
    filtered : bool
        false: an unfiltered derivative D (z - 1)/(T z), N unused
    initial_integrator : scalar or vector
        the integral term's initial value (in output units), also after a reset
    initial_filter : scalar or vector
        the derivative filter's initial state (unfiltered: the error before the first hit)
    lower : scalar or vector
        lower output limit; -inf for none
    upper : scalar or vector
        upper output limit; inf for none
    anti_windup : {'none', 'clamping', 'back_calculation'}
        how the integral is kept in check while the output is limited
    Kb : scalar or vector
        back-calculation gain
    tracking : bool
        adds the input ``track`` (the signal the output should follow), of the width of u
    Kt : scalar or vector
        tracking gain
    reset : {'none', 'rising', 'falling', 'either', 'level'}
        adds a scalar input ``reset`` that restarts the integrator and filter on its edge
        or while it is non-zero
    """

    kernel_name = "pid"
    period_reason = "its integral and derivative are over time"

    def __init__(self, P: Any = 1.0, I: Any = 0.0, D: Any = 0.0, N: Any = 100.0,  # noqa: E741 - Simulink's names
                 form: str = "parallel", integrator: str = "forward", filter: str = "forward",
                 filtered: bool = True, initial_integrator: Any = 0.0, initial_filter: Any = 0.0,
                 lower: Any = -np.inf, upper: Any = np.inf, anti_windup: str = "none", Kb: Any = 1.0,
                 tracking: bool = False, Kt: Any = 1.0, reset: str = "none"):
        self.P, self.I, self.D = (_params.elementwise(n, v) for n, v in (("P", P), ("I", I), ("D", D)))
        self.N = _params.elementwise("N", N, positive=True)
        self.form = _params.choice("form", form, FORMS)
        self.integrator = _params.choice("integrator", integrator, METHODS)
        self.filter = _params.choice("filter", filter, METHODS)
        self.filtered = _params.flag("filtered", filtered)
        self.initial_integrator = _params.elementwise("initial_integrator", initial_integrator)
        self.initial_filter = _params.elementwise("initial_filter", initial_filter)
        self.lower = _params.elementwise("lower", lower, allow_inf=True)
        self.upper = _params.elementwise("upper", upper, allow_inf=True)
        self.anti_windup = _params.choice("anti_windup", anti_windup, ANTI_WINDUP)
        self.Kb = _params.elementwise("Kb", Kb)
        self.tracking = _params.flag("tracking", tracking)
        self.Kt = _params.elementwise("Kt", Kt)
        self.reset = _params.choice("reset", reset, RESETS)
        width = _params.common_width(**{n: getattr(self, n) for n in self._VECTORS})
        _params.check_limits(self.lower, self.upper)
        self.inputs = {"u": width, **({"track": width} if self.tracking else {}),
                       **({"reset": 1} if self.reset != "none" else {})}
        self.outputs = {"y": width}
        Kp, Ki, Kd = self.parallel_gains()
        reads = set()
        if np.any(Kp != 0) or np.any(Kd != 0) or (self.integrator != "forward" and np.any(Ki != 0)):
            reads.add("u")
        if self.reset != "none":
            reads.add("reset")
        self.feedthrough = {"y": reads} if reads else False

    _VECTORS = ("P", "I", "D", "N", "initial_integrator", "initial_filter", "lower", "upper", "Kb", "Kt")

    def parallel_gains(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(Kp, Ki, Kd) of the parallel form this controller is."""
        if self.form == "ideal":
            return self.P, self.P * self.I, self.P * self.D
        return self.P, self.I, self.D

    def bind(self, period: Fraction | None) -> None:
        super().bind(period)
        T = float(period)
        if self.filtered and self.filter == "forward" and np.any((self.N * T >= 2) & (self.parallel_gains()[2] != 0)):
            raise ValueError(f"the derivative filter is unstable: N T = {float(np.max(self.N)) * T:g} >= 2 with "
                             "forward Euler; lower N, shorten the period or use filter: backward")

    def initial_state(self) -> Signal:
        width = self.outputs["y"] or 1
        return np.concatenate((_params.spread(self.initial_integrator, width),
                               _params.spread(self.initial_filter, width), (0.0,)))

    def context_numbers(self):
        w, T = self.outputs["y"], float(self.period)
        Kp, Ki, Kd = self.parallel_gains()
        N = _params.spread(self.N, w)
        Nf = N / (1.0 + N * output_share(self.filter, T))
        return (output_share(self.integrator, T), float(self.filtered), ANTI_WINDUP.index(self.anti_windup),
                float(self.tracking), RESETS.index(self.reset),
                *(_params.spread(v, w) for v in (Kp, Ki, Kd)), Nf,
                *(_params.spread(v, w) for v in (self.lower, self.upper, self.Kb, self.Kt,
                                                 self.initial_integrator, self.initial_filter)))
