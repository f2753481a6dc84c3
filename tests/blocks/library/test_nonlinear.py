"""DeadZone, Quantizer, RateLimiter and Backlash against the definitions Simulink documents
(Rate Limiter in discrete mode: rate = (u(i) - y(i-1)) / T, y(-1) the initial condition)."""

from __future__ import annotations

import numpy as np
import pytest

from blocks.library import Backlash, DeadZone, Quantizer, RateLimiter

from .stepping import PERIOD, series, step

T = float(PERIOD)
U = np.concatenate((np.linspace(-2, 2, 41), [np.nan, 0.5, -0.5, 0.25]))[:, None]


def test_dead_zone():
    y = step(DeadZone(-0.5, 1.0), {"u": U})["y"][:, 0]
    u = U[:, 0]
    expected = np.where(u > 1.0, u - 1.0, np.where(u < -0.5, u + 0.5, np.where(np.isnan(u), np.nan, 0.0)))
    np.testing.assert_array_equal(y, expected)


def test_quantizer_rounds_halves_away_from_zero():
    u = np.array([0.25, -0.25, 0.74, 0.75, -0.75, 1.2, 0.49999999999999994, np.nan])[:, None]
    y = step(Quantizer(0.5), {"u": u})["y"][:, 0]
    np.testing.assert_array_equal(y, [0.5, -0.5, 0.5, 1.0, -1.0, 1.0, 0.5, np.nan])
    big = series(200, seed=3)[:, None]
    expected = 0.1 * np.where(np.abs(big / 0.1 - np.trunc(big / 0.1)) >= 0.5,
                              np.trunc(big / 0.1) + np.sign(big), np.trunc(big / 0.1))
    np.testing.assert_array_equal(step(Quantizer(0.1), {"u": big})["y"], expected)


def rate_limited(u, rising, falling, initial):
    y, prev = [], initial
    for uk in u:
        rate = (uk - prev) / T
        prev = T * rising + prev if rate > rising else T * falling + prev if rate < falling else uk
        y.append(prev)
    return np.array(y)


def test_rate_limiter_follows_simulinks_discrete_equations():
    u = 3 * series(400, seed=2)
    y = step(RateLimiter(rising=200.0, falling=-50.0, initial=1.0), {"u": u})["y"][:, 0]
    np.testing.assert_array_equal(y, rate_limited(u, 200.0, -50.0, 1.0))
    assert np.all(np.diff(np.concatenate(([1.0], y))) <= 200.0 * T * (1 + 1e-12))
    assert np.all(np.diff(np.concatenate(([1.0], y))) >= -50.0 * T * (1 + 1e-12))


def test_an_unlimited_rate_limiter_passes_its_input():
    u = series(100, seed=4)
    np.testing.assert_array_equal(step(RateLimiter(np.inf, -np.inf), {"u": u})["y"][:, 0], u)


def backlash(u, width, initial):
    y, prev = [], initial
    for uk in u:
        if uk - prev > width / 2:
            prev = uk - width / 2
        elif uk - prev < -width / 2:
            prev = uk + width / 2
        y.append(prev)
    return np.array(y)


def test_backlash_holds_inside_the_deadband_and_follows_outside():
    u = np.sin(np.linspace(0, 6 * np.pi, 300)) * np.linspace(0.2, 2.0, 300)
    y = step(Backlash(width=0.6, initial=0.1), {"u": u})["y"][:, 0]
    np.testing.assert_array_equal(y, backlash(u, 0.6, 0.1))
    assert np.all(np.abs(u - y) <= 0.3 + 1e-15)


@pytest.mark.parametrize("cls, params, word", [
    (DeadZone, dict(start=1.0, end=0.0), "'start'"), (Quantizer, dict(interval=0.0), "'interval'"),
    (RateLimiter, dict(rising=-1.0), "'rising'"), (RateLimiter, dict(falling=1.0), "'falling'"),
    (Backlash, dict(width=-1.0), "'width'"), (Backlash, dict(width=[1.0, 2.0], initial=[0, 0, 0]), "one width"),
])
def test_bad_parameters_are_named(cls, params, word):
    with pytest.raises(ValueError, match=word):
        cls(**params)


def test_the_rate_limiter_needs_a_period():
    with pytest.raises(ValueError, match="needs a period"):
        RateLimiter().bind(None)
