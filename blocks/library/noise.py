"""Seeded random sources: RandomNumber (normal or uniform) and BandLimitedWhiteNoise.

The number a block outputs at its k-th hit, element i, is a hash of (seed, i, k), computed
by lib_sources.c with integer mixing and IEEE 754's exactly rounded arithmetic (a
logarithm of its own, not libm's): the same seed gives the same signal on any machine,
in C or Python, whatever else the diagram holds. Two blocks with the same seed give the
same sequence; a sweep varies the seed like any parameter (``--grid noise.seed=1,2,3``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from blocks.block import Signal
from blocks.library import _params
from blocks.library.kernel_block import Advancing
from blocks.library.sources import broadcast_vectors

MAX_SEED = 2**64 - 1


def seed_words(seed: Any) -> tuple[int, int]:
    """The seed (a whole number from 0 to 2^64 - 1) as its high and low 32 bits."""
    value = _params.integer("seed", seed, minimum=0, maximum=MAX_SEED)
    return value >> 32, value & 0xFFFFFFFF


class _Random(Advancing):
    """A seeded source: state [hits so far], output p + q z for z of (seed, element, hit)."""

    kernel_name = "random_number"
    period_reason = "it draws a new number at each of its hits"
    uniform = False

    def _ports(self, width: int) -> None:
        self.inputs, self.outputs = {}, {"y": width}
        self.feedthrough = False

    def initial_state(self) -> Signal:
        return np.zeros(1)

    def scale(self) -> tuple[np.ndarray, np.ndarray]:
        """(p, q) of every element."""
        raise NotImplementedError

    def context_numbers(self):
        return (float(self.uniform), *self.seed_words, *self.scale())


class RandomNumber(_Random):
    """A new seeded random number at every hit, normal or uniform.

    Normally distributed with ``mean`` and ``variance`` (Simulink's Random Number), or
    uniform in [minimum, maximum). The same seed gives the same numbers. Needs a period.

    Parameters
    ----------
    distribution : {'normal', 'uniform'}
        the numbers' distribution
    mean : scalar or vector
        'normal' only: the mean (default 0)
    variance : scalar or vector
        'normal' only: the variance (>= 0, default 1)
    minimum : scalar or vector
        'uniform' only: the smallest value (default -1)
    maximum : scalar or vector
        'uniform' only: the bound the values stay below (default 1)
    seed : int
        0 to 2^64 - 1; each element of a vector output has a stream of its own
    """

    def __init__(self, distribution: str = "normal", mean: Any = None, variance: Any = None, minimum: Any = None,
                 maximum: Any = None, seed: int = 0):
        self.distribution = _params.choice("distribution", distribution, ("normal", "uniform"))
        self.uniform = self.distribution == "uniform"
        own, other = (("minimum", "maximum"), ("mean", "variance")) if self.uniform else \
            (("mean", "variance"), ("minimum", "maximum"))
        given = {"mean": mean, "variance": variance, "minimum": minimum, "maximum": maximum}
        for name in other:
            if given[name] is not None:
                raise ValueError(f"parameter '{name}' is for distribution: "
                                 f"{'normal' if self.uniform else 'uniform'}; this one is {self.distribution}")
        defaults = {"mean": 0.0, "variance": 1.0, "minimum": -1.0, "maximum": 1.0}
        v = broadcast_vectors(**{n: defaults[n] if given[n] is None else given[n] for n in own})
        if self.uniform:
            self.minimum, self.maximum = v["minimum"], v["maximum"]
            if np.any(~(self.minimum < self.maximum)):
                raise ValueError(f"parameter 'minimum' must be below 'maximum', got {minimum!r} and {maximum!r}")
        else:
            self.mean, self.variance = v["mean"], v["variance"]
            if np.any(self.variance < 0):
                raise ValueError(f"parameter 'variance' must not be negative, got {variance!r}")
        self.seed = _params.integer("seed", seed, minimum=0, maximum=MAX_SEED)
        self.seed_words = seed_words(self.seed)
        self._ports(next(iter(v.values())).size)

    def scale(self):
        if self.uniform:
            return self.minimum, self.maximum - self.minimum
        return self.mean, np.sqrt(self.variance)


class BandLimitedWhiteNoise(_Random):
    """Seeded white noise of a power spectral density, for a continuous model.

    Normally distributed numbers of variance power / T at each hit (T the period), so that the noise has the power spectral density
    ``power`` up to the Nyquist frequency (Simulink's Band-Limited White Noise; choose T
    well below the system's smallest time constant). Seeded. Needs a period.

    Parameters
    ----------
    power : scalar or vector
        the height of the power spectral density (>= 0), units^2 per Hz
    seed : int
        0 to 2^64 - 1; each element of a vector output has a stream of its own
    """

    def __init__(self, power: Any = 0.1, seed: int = 0):
        self.power = _params.elementwise("power", power, nonnegative=True)
        self.seed = _params.integer("seed", seed, minimum=0, maximum=MAX_SEED)
        self.seed_words = seed_words(self.seed)
        self._ports(self.power.size)

    def scale(self):
        power = _params.spread(self.power, self.outputs["y"])
        return np.zeros_like(power), np.sqrt(power / float(self.period))
