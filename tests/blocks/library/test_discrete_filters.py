"""DiscreteDerivative, MovingAverage and Memory against scipy.signal.lfilter of their FIR
filters (K (1 - z^-1)/T, ones(N)/N, z^-1), and Memory's one-hit delay in a diagram."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter

import blocks
from blocks.library import DiscreteDerivative, Memory, MovingAverage

from .stepping import PERIOD, series, step

T = float(PERIOD)


def test_derivative_is_k_times_one_minus_z_inverse_over_t():
    u = series(300, seed=1)
    y = step(DiscreteDerivative(gain=0.5), {"u": u})["y"][:, 0]
    np.testing.assert_allclose(y, lfilter([0.5 / T, -0.5 / T], [1.0], u), rtol=1e-13, atol=1e-10)


def test_derivative_starts_from_the_initial_previous_input():
    y = step(DiscreteDerivative(initial=[1.0, 2.0]), {"u": [[1.0, 1.0], [1.0, 1.0]]})["y"]
    np.testing.assert_allclose(y, [[0.0, -1.0 / T], [0.0, 0.0]])


@pytest.mark.parametrize("window", [1, 2, 7, 50])
def test_moving_average_is_the_fir_filter_from_rest(window):
    u = np.column_stack([series(400, seed=2), series(400, seed=3)])
    y = step(MovingAverage(window=window), {"u": u})["y"]
    for i in range(2):
        np.testing.assert_allclose(y[:, i], lfilter(np.ones(window) / window, [1.0], u[:, i]), rtol=0, atol=1e-13)


def test_moving_average_assumes_the_initial_inputs_before_the_first_hit():
    y = step(MovingAverage(window=4, initial=2.0), {"u": np.zeros(5)})["y"][:, 0]
    np.testing.assert_allclose(y, [1.5, 1.0, 0.5, 0.0, 0.0])


def test_memory_delays_by_one_hit_of_the_rate_it_inherits():
    diagram = blocks.loads_diagram("""
blocks:
  src: {type: Ramp, period: 2 ms, params: {slope: 1000.0}}
  mem: {type: Memory, params: {initial: -1.0}}
connections: [src.y -> mem.u]
log: [mem.y, src.y]
""")
    results = blocks.simulate(diagram, t_end="10 ms")
    t, y = results["mem.y"]
    np.testing.assert_allclose(t, np.arange(0, 11, 2) * 1e-3)
    np.testing.assert_allclose(y[:, 0], [-1.0, 0.0, 2.0, 4.0, 6.0, 8.0])


@pytest.mark.parametrize("cls, params, word", [
    (MovingAverage, dict(window=0), "'window'"), (MovingAverage, dict(window=2.5), "'window'"),
    (DiscreteDerivative, dict(gain="k"), "'gain'"), (Memory, dict(initial=[]), "'initial'"),
])
def test_bad_parameters_are_named(cls, params, word):
    with pytest.raises(ValueError, match=word):
        cls(**params)


def test_the_derivative_needs_a_period():
    with pytest.raises(ValueError, match="needs a period"):
        DiscreteDerivative().bind(None)
