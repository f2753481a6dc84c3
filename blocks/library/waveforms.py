"""Periodic and swept sources: Sine, Pulse and Chirp, functions of time only (frequencies
in Hz). Vectors of parameters give vector outputs. Kernels in lib_sources.c."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from blocks.library import _params
from blocks.library.kernel_block import KernelBlock
from blocks.library.sources import broadcast_vectors


class _Waveform(KernelBlock):
    """A source of time: no inputs, output ``y`` of its parameters' width."""

    time_varying = True

    def _ports(self, width: int) -> None:
        self.inputs, self.outputs = {}, {"y": width}
        self.feedthrough = False


class Sine(_Waveform):
    """y = amplitude sin(2 pi frequency t + phase) + bias (Simulink's time-based Sine Wave,
    with the frequency in Hz).

    Parameters
    ----------
    amplitude : scalar or vector
        peak value
    frequency : scalar or vector
        in Hz (cycles per second)
    phase : scalar or vector
        in rad, at t = 0
    bias : scalar or vector
        added to the output
    """

    kernel_name = "sine"

    def __init__(self, amplitude: Any = 1.0, frequency: Any = 1.0, phase: Any = 0.0, bias: Any = 0.0):
        v = broadcast_vectors(amplitude=amplitude, frequency=frequency, phase=phase, bias=bias)
        self.amplitude, self.frequency, self.phase, self.bias = v["amplitude"], v["frequency"], v["phase"], v["bias"]
        self._ports(self.amplitude.size)

    def context_numbers(self):
        return (self.amplitude, 2.0 * math.pi * self.frequency, self.phase, self.bias)


class Pulse(_Waveform):
    """Rectangular pulses of ``amplitude``, ``duty`` of each ``period``, from ``delay`` on.

    The output is ``amplitude`` from delay + j period for duty * period, 0 between the
    pulses and before ``delay`` (Simulink's time-based Pulse Generator, with the width as a
    fraction). Tick times are floats, so a time within 1e-9 of a period of an edge counts
    as on it: 0.3 s is the start of the fourth pulse of period 0.1 s.

    Parameters
    ----------
    amplitude : scalar or vector
        the pulses' height
    period : scalar or vector
        seconds from one pulse's start to the next (> 0)
    duty : scalar or vector
        the pulse's width as a fraction of the period, in (0, 1]
    delay : scalar or vector
        time of the first pulse's start, seconds (>= 0)
    """

    kernel_name = "pulse"

    def __init__(self, amplitude: Any = 1.0, period: Any = 1.0, duty: Any = 0.5, delay: Any = 0.0):
        v = broadcast_vectors(amplitude=amplitude, period=period, duty=duty, delay=delay)
        self.amplitude, self.pulse_period, self.duty, self.delay = v["amplitude"], v["period"], v["duty"], v["delay"]
        if np.any(~(self.pulse_period > 0)):
            raise ValueError(f"parameter 'period' must be positive, got {period!r}")
        if np.any(~((self.duty > 0) & (self.duty <= 1))):
            raise ValueError(f"parameter 'duty' must be in (0, 1], got {duty!r}")
        if np.any(self.delay < 0):
            raise ValueError(f"parameter 'delay' must not be negative, got {delay!r}")
        self._ports(self.amplitude.size)

    def context_numbers(self):
        return (self.amplitude, self.pulse_period, self.duty, self.delay)


SWEEPS = ("linear", "logarithmic")


class Chirp(_Waveform):
    """A swept sine from f0 at t = 0 to f1 at ``target_time`` (Hz), linear or logarithmic.

    y = amplitude sin(phase(t) + phase0), the frequency going from f0 to f1 and on at the
    same rate: linearly (2 pi (f0 t + (f1 -
    f0) t^2 / (2 T1)), Simulink's Chirp Signal) or logarithmically (exponential in
    frequency), as scipy.signal.chirp's 'linear' and 'logarithmic' (whose cosine is this
    sine with phase -90 degrees).

    Parameters
    ----------
    amplitude : scalar or vector
        peak value
    f0 : scalar or vector
        frequency at t = 0, Hz (> 0 for 'logarithmic')
    f1 : scalar or vector
        frequency at the target time, Hz (> 0 for 'logarithmic', and not f0)
    target_time : scalar or vector
        when the frequency reaches f1, seconds (> 0)
    method : {'linear', 'logarithmic'}
        how the frequency changes
    phase : scalar or vector
        in rad, added to the sweep's phase
    """

    kernel_name = "chirp"

    def __init__(self, amplitude: Any = 1.0, f0: Any = 0.1, f1: Any = 1.0, target_time: Any = 100.0,
                 method: str = "linear", phase: Any = 0.0):
        v = broadcast_vectors(amplitude=amplitude, f0=f0, f1=f1, target_time=target_time, phase=phase)
        self.amplitude, self.f0, self.f1 = v["amplitude"], v["f0"], v["f1"]
        self.target_time, self.phase = v["target_time"], v["phase"]
        self.method = _params.choice("method", method, SWEEPS)
        if np.any(~(self.target_time > 0)):
            raise ValueError(f"parameter 'target_time' must be positive, got {target_time!r}")
        if self.method == "logarithmic":
            if np.any(~((self.f0 > 0) & (self.f1 > 0))):
                raise ValueError("parameters 'f0' and 'f1' must be positive for method: logarithmic")
            if np.any(self.f0 == self.f1):
                raise ValueError("parameters 'f0' and 'f1' must differ for method: logarithmic")
        self._ports(self.amplitude.size)

    def context_numbers(self):
        if self.method == "linear":
            a = 2.0 * math.pi * self.f0
            b = math.pi * (self.f1 - self.f0) / self.target_time
        else:
            ratio = np.log(self.f1 / self.f0)
            a = 2.0 * math.pi * self.f0 * self.target_time / ratio
            b = ratio / self.target_time
        return (float(self.method == "logarithmic"), self.amplitude, a, b, self.phase)
