"""RandomNumber and BandLimitedWhiteNoise: the generator is the counter-based hash
lib_sources.c documents (checked against a Python oracle of it, and against numbers
recorded once, which any IEEE 754 machine must reproduce), the numbers have the
distribution asked for, and a sweep point's seed is set like any parameter."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats
from scipy.signal import welch

import blocks
from blocks.library import BandLimitedWhiteNoise, RandomNumber
from blocks.sweep import grid_points, read_sweep, run_sweep

from .stepping import PERIOD, advanced, step

MASK = 2**64 - 1


def mix64(z: int) -> int:
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return z ^ (z >> 31)


def draw(seed: int, stream: int, counter: int, attempt: int) -> int:
    golden = 0x9E3779B97F4A7C15
    z = mix64(seed ^ 0x243F6A8885A308D3)
    for word in (stream, counter, attempt):
        z = mix64((z + (word + 1) * golden) & MASK)
    return z


def unit(bits: int) -> float:
    return (bits >> 11) / 2.0**53


def normal(seed: int, stream: int, counter: int) -> float:
    """Marsaglia's polar method on the draws, with the math library's log."""
    for j in range(64):
        a = 2.0 * unit(draw(seed, stream, counter, 2 * j)) - 1.0
        b = 2.0 * unit(draw(seed, stream, counter, 2 * j + 1)) - 1.0
        s = a * a + b * b
        if 0.0 < s < 1.0:
            return a * math.sqrt(-2.0 * math.log(s) / s)
    return 0.0


def test_uniform_numbers_are_the_documented_hash():
    y = step(RandomNumber("uniform", minimum=0.0, maximum=1.0, seed=12345), n=50)["y"][:, 0]
    np.testing.assert_array_equal(y, [unit(draw(12345, 0, k, 0)) for k in range(50)])


def test_normal_numbers_are_the_polar_method_on_the_hash():
    y = step(RandomNumber(seed=99, mean=[0.0, 0.0]), n=200)["y"]
    expected = np.array([[normal(99, i, k) for i in range(2)] for k in range(200)])
    np.testing.assert_allclose(y, expected, rtol=4e-16, atol=0)  # libm's log against the portable one


def test_the_same_seed_gives_the_recorded_numbers():
    """Recorded once; a change of these bits breaks every diagram's reproducibility."""
    y = step(RandomNumber(seed=0), n=4)["y"][:, 0]
    assert y.tolist() == [-1.4950416896683998, 0.022896691269358106, -1.3156844945902169, 2.488870077729441]
    y = step(RandomNumber("uniform", minimum=0.0, maximum=1.0, seed=12345), n=2)["y"][:, 0]
    assert y.tolist() == [0.2980398917718522, 0.8593486658297291]
    y = step(RandomNumber(seed=2**64 - 1), n=1)["y"][:, 0]
    assert y.tolist() == [0.11562607981102449]


def test_normal_numbers_have_the_mean_variance_and_shape_asked_for():
    n = 40000
    y = advanced(RandomNumber(mean=[1.0, -2.0], variance=[4.0, 0.25], seed=7), n)
    for i, (mean, var) in enumerate(((1.0, 4.0), (-2.0, 0.25))):
        z = (y[:, i] - mean) / math.sqrt(var)
        assert abs(z.mean()) < 4 / math.sqrt(n) and abs(z.var() - 1.0) < 4 * math.sqrt(2 / n)
        assert stats.kstest(z, "norm").pvalue > 1e-3
        assert abs(np.corrcoef(z[:-1], z[1:])[0, 1]) < 4 / math.sqrt(n)  # no memory from hit to hit
    assert abs(np.corrcoef(y[:, 0], y[:, 1])[0, 1]) < 4 / math.sqrt(n)  # elements are independent


def test_uniform_numbers_fill_their_interval():
    y = advanced(RandomNumber("uniform", minimum=-3.0, maximum=5.0, seed=1), 20000)[:, 0]
    assert y.min() >= -3.0 and y.max() < 5.0
    assert stats.kstest(y, "uniform", args=(-3.0, 8.0)).pvalue > 1e-3


def test_advance_gives_the_numbers_of_hit_after_hit():
    np.testing.assert_array_equal(advanced(RandomNumber(seed=5, mean=[0.0, 1.0]), 30),
                                  step(RandomNumber(seed=5, mean=[0.0, 1.0]), n=30)["y"])


def test_seeds_give_different_sequences():
    a, b = (step(RandomNumber(seed=s), n=100)["y"][:, 0] for s in (1, 2))
    assert abs(np.corrcoef(a, b)[0, 1]) < 0.4 and not np.array_equal(a, b)


def test_band_limited_white_noise_has_variance_power_over_period():
    n = 40000
    y = advanced(BandLimitedWhiteNoise(power=0.02, seed=3), n)[:, 0]
    assert abs(y.var() / (0.02 / float(PERIOD)) - 1.0) < 4 * math.sqrt(2 / n)
    _, psd = welch(y, fs=1 / float(PERIOD), nperseg=1024)
    # a one-sided density of 2 * power, flat up to the Nyquist frequency
    assert abs(np.median(psd[1:-1]) / (2 * 0.02) - 1.0) < 0.1


NOISY = """
name: noisy
time: {t_end: 0.2 s}
blocks:
  noise: {type: RandomNumber, period: 1 ms, params: {seed: 1}}
  avg:   {type: MovingAverage, params: {window: 10}}
connections: [noise.y -> avg.u]
log: [avg.y]
"""


def test_a_sweep_sets_each_points_seed_and_a_run_of_that_seed_agrees(tmp_path):
    diagram = tmp_path / "noisy.yaml"
    diagram.write_text(NOISY)
    run_sweep(diagram, grid_points({"noise.seed": [1, 2, 3]}), ["end=final(avg.y)"], tmp_path / "sweep",
              serial=True, progress=False)
    rows = {int(r["noise.seed"]): float(r["end"]) for r in read_sweep(tmp_path / "sweep")[1]}
    assert len(set(rows.values())) == 3
    alone = blocks.simulate(blocks.load_diagram(diagram, overrides={"noise.seed": 2}))
    assert alone["avg.y"][1][-1, 0] == rows[2]


def test_compiled_and_python_runs_give_the_same_bits(monkeypatch):
    diagram = blocks.loads_diagram(NOISY)
    compiled = blocks.simulate(diagram)
    monkeypatch.setattr(blocks.engine.compiled, "usable_kernel", lambda *args: None)
    np.testing.assert_array_equal(blocks.simulate(diagram)["avg.y"][1], compiled["avg.y"][1])


@pytest.mark.parametrize("cls, params, word", [
    (RandomNumber, dict(seed=-1), "'seed'"), (RandomNumber, dict(seed=2**64), "'seed'"),
    (RandomNumber, dict(seed=1.5), "'seed'"), (RandomNumber, dict(seed=True), "'seed'"),
    (RandomNumber, dict(distribution="gamma"), "'distribution'"), (RandomNumber, dict(variance=-1.0), "'variance'"),
    (RandomNumber, dict(minimum=0.0), "'minimum' is for distribution: uniform"),
    (RandomNumber, dict(distribution="uniform", mean=1.0), "'mean' is for distribution: normal"),
    (RandomNumber, dict(distribution="uniform", minimum=1.0, maximum=1.0), "'minimum' must be below"),
    (BandLimitedWhiteNoise, dict(power=-0.1), "'power'"),
])
def test_bad_parameters_are_named(cls, params, word):
    with pytest.raises(ValueError, match=word):
        cls(**params)


def test_random_sources_need_a_period():
    with pytest.raises(ValueError, match="needs a period"):
        RandomNumber().bind(None)
