"""Sine against its closed form, Pulse against edges computed in exact rationals (the tick
times of a diagram), Chirp against scipy.signal.chirp."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from scipy.signal import chirp

import blocks
from blocks.library import Chirp, Pulse, Sine

from .stepping import step

TICK = Fraction(1, 10000)


def test_sine_is_its_closed_form():
    t = np.arange(5000) * 1e-4
    y = step(Sine(amplitude=[2.0, 1.0], frequency=[3.0, 50.0], phase=[0.5, -1.0], bias=[1.0, 0.0]),
             n=len(t), period=TICK)["y"]
    expected = np.column_stack([2.0 * np.sin(2 * np.pi * 3.0 * t + 0.5) + 1.0, np.sin(2 * np.pi * 50.0 * t - 1.0)])
    np.testing.assert_allclose(y, expected, rtol=0, atol=1e-13)


def exact_pulse(n: int, amplitude: float, period: Fraction, duty: Fraction, delay: Fraction) -> np.ndarray:
    """The pulse at ticks 0 .. n-1, in integers: every time as a multiple of the common
    denominator of the tick, the period, the pulse's width and the delay."""
    width = duty * period
    unit = math.lcm(*(x.denominator for x in (TICK, period, width, delay)))
    tick, p, w, d = (int(x * unit) for x in (TICK, period, width, delay))
    t = np.arange(n, dtype=np.int64) * tick
    return np.where((t >= d) & ((t - d) % p < w), amplitude, 0.0)


@pytest.mark.parametrize("period, duty, delay", [
    ("0.1", "0.5", "0"), ("0.3", "0.2", "0.05"), ("0.7", "1", "0.3"), ("0.0003", "0.3333", "0.0001"),
])
def test_pulse_edges_fall_on_the_exact_tick_times(period, duty, delay):
    """In a diagram, t is k * tick rounded to a float; the pulse must switch on the tick
    that exact arithmetic says, not one late because 0.3 / 0.1 rounds below 3."""
    diagram = blocks.loads_diagram(f"""
blocks:
  p: {{type: Pulse, period: 0.1 ms, params: {{amplitude: 2.5, period: {period}, duty: {duty}, delay: {delay}}}}}
log: [p.y]
""")
    results = blocks.simulate(diagram, t_end="3 s")
    y = results["p.y"][1][:, 0]
    np.testing.assert_array_equal(y, exact_pulse(len(y), 2.5, Fraction(period), Fraction(duty), Fraction(delay)))


@pytest.mark.parametrize("method", ["linear", "logarithmic"])
def test_chirp_is_scipys_sine_sweep(method):
    t = np.arange(10000) * 1e-4
    y = step(Chirp(amplitude=1.5, f0=0.5, f1=20.0, target_time=0.7, method=method, phase=0.3),
             n=len(t), period=TICK)["y"][:, 0]
    expected = 1.5 * chirp(t, f0=0.5, t1=0.7, f1=20.0, method=method, phi=np.degrees(0.3) - 90.0)
    np.testing.assert_allclose(y, expected, rtol=0, atol=1e-10)


def test_sources_need_a_period():
    with pytest.raises(blocks.DiagramError, match="changes with time"):
        blocks.loads_diagram("blocks: {s: {type: Sine}}\nlog: [s.y]")


@pytest.mark.parametrize("cls, params, word", [
    (Pulse, dict(period=0.0), "'period'"), (Pulse, dict(duty=1.5), "'duty'"), (Pulse, dict(delay=-1.0), "'delay'"),
    (Chirp, dict(method="cubic"), "'method'"), (Chirp, dict(method="logarithmic", f0=0.0), "'f0'"),
    (Chirp, dict(target_time=0.0), "'target_time'"), (Sine, dict(frequency=[1.0, 2.0], phase=[0, 1, 2]), "one width"),
])
def test_bad_parameters_are_named(cls, params, word):
    with pytest.raises(ValueError, match=word):
        cls(**params)
