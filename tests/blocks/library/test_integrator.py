"""DiscreteIntegrator against the output equations Simulink documents for its Discrete-Time
Integrator, and (initial state given) against scipy.signal.lfilter of its transfer function.

Simulink, with y(0) = IC: y(n) = y(n-1) + K T u(n-1) (forward Euler), y(n-1) + K T u(n)
(backward), y(n-1) + K T (u(n) + u(n-1))/2 (trapezoidal); limits clip; a reset restarts
from IC at that hit.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter

from blocks.library import DiscreteIntegrator

from .stepping import PERIOD, series, step

T = float(PERIOD)


def simulink(method: str, u: np.ndarray, K: float, ic: float) -> np.ndarray:
    """The documented recursions, from y(0) = IC."""
    y = np.empty(len(u))
    y[0] = ic
    for n in range(1, len(u)):
        term = {"forward": u[n - 1], "backward": u[n], "trapezoidal": (u[n] + u[n - 1]) / 2}[method]
        y[n] = y[n - 1] + K * T * term
    return y


@pytest.mark.parametrize("method", ["forward", "backward", "trapezoidal"])
def test_initial_output_follows_simulinks_equations(method):
    u = series(500, seed=1)
    y = step(DiscreteIntegrator(gain=2.5, method=method, initial=0.3), {"u": u})["y"][:, 0]
    np.testing.assert_allclose(y, simulink(method, u, 2.5, 0.3), rtol=0, atol=1e-12)


TRANSFER = {"forward": ([0.0, T], [1.0, -1.0]), "backward": ([T, 0.0], [1.0, -1.0]),
            "trapezoidal": ([T / 2, T / 2], [1.0, -1.0])}


@pytest.mark.parametrize("method", ["forward", "backward", "trapezoidal"])
def test_initial_state_is_the_transfer_function(method):
    u = series(500, seed=2)
    y = step(DiscreteIntegrator(gain=1.5, method=method, initial_is="state"), {"u": u})["y"][:, 0]
    b, a = TRANSFER[method]
    np.testing.assert_allclose(y, lfilter(1.5 * np.array(b), a, u), rtol=0, atol=1e-12)


@pytest.mark.parametrize("method", ["forward", "backward", "trapezoidal"])
def test_limits_clip_output_and_state(method):
    u = np.concatenate((np.full(100, 50.0), np.full(100, -50.0)))
    y = step(DiscreteIntegrator(method=method, lower=-1.0, upper=0.5), {"u": u})["y"][:, 0]
    assert y.max() == 0.5 and y.min() == -1.0
    # the state does not wind up: the first hit after the reversal already comes down
    assert y[101] < 0.5


def test_vector_parameters_integrate_each_element():
    u = np.column_stack([series(100, seed=3), series(100, seed=4)])
    y = step(DiscreteIntegrator(gain=[1.0, -2.0], initial=[0.0, 1.0]), {"u": u})["y"]
    np.testing.assert_allclose(y[:, 0], simulink("forward", u[:, 0], 1.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(y[:, 1], simulink("forward", u[:, 1], -2.0, 1.0), atol=1e-12)


@pytest.mark.parametrize("kind, reset, restarts", [
    ("rising", [0, 0, 1, 1, 0, 1, -1, 0], [2, 5, 7]),
    ("falling", [1, 1, 0, 0, 1, 0, 0, -1], [2, 5, 7]),
    ("either", [0, 1, 1, 0, 0, 0], [1, 3]),
    ("level", [0, 1, 1, 0, 0, 0], [1, 2]),
])
def test_reset_restarts_from_the_initial_output(kind, reset, restarts):
    n = len(reset)
    y = step(DiscreteIntegrator(initial=0.25, reset=kind), {"u": np.full(n, 100.0), "reset": reset})["y"][:, 0]
    expected, value = [], 0.25
    for k in range(n):
        if k in restarts:
            value = 0.25
        expected.append(value)
        value += T * 100.0
    np.testing.assert_allclose(y, expected, atol=1e-12)


def test_feedthrough_and_ports():
    assert not DiscreteIntegrator().has_feedthrough()
    assert DiscreteIntegrator(method="backward").reads("y") == {"u"}
    assert DiscreteIntegrator(reset="rising").reads("y") == {"reset"}
    assert DiscreteIntegrator(reset="level").inputs == {"u": None, "reset": 1}


def test_advance_gives_the_hits_one_by_one():
    block = DiscreteIntegrator(gain=3.0, initial=0.5)
    block.bind(PERIOD)
    block.set_width(2)
    u = np.array([1.0, -2.0])
    state = block.initial_state()
    rows = []
    one = state.copy()
    for k in range(7):
        one = block.update(k * T, one, {"u": u})
        rows.append(block.output((k + 1) * T, one, {"u": u})["y"])
    state, out = block.advance(0.0, state, {"u": u}, 7)
    np.testing.assert_array_equal(out["y"], np.array(rows))
    np.testing.assert_array_equal(state, one)


@pytest.mark.parametrize("params, word", [
    (dict(method="euler"), "'method'"), (dict(initial_is="both"), "'initial_is'"),
    (dict(lower=1.0, upper=0.0), "'lower'"), (dict(gain=[1.0, 2.0], initial=[1.0, 2.0, 3.0]), "one width"),
    (dict(reset="sometimes"), "'reset'"), (dict(gain=float("nan")), "'gain'"),
])
def test_bad_parameters_are_named(params, word):
    with pytest.raises(ValueError, match=word):
        DiscreteIntegrator(**params)


def test_needs_a_period():
    with pytest.raises(ValueError, match="needs a period"):
        DiscreteIntegrator().bind(None)
