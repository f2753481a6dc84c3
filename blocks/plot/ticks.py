"""An axis's range and ticks: the data's span with a margin, and round tick values (1, 2,
2.5 or 5 times a power of ten) labelled with as many decimals as their step needs.

Values too large or too small for plain decimals are labelled in units of a power of ten
(``1e-3`` beside the axis), and a small range far from zero relative to an offset
(``+1000``), as matplotlib's default formatter does, so that a label never runs to a
dozen digits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MARGIN = 0.05
"""Of the data's span, added each side of an autoscaled axis."""

STEPS = (1.0, 2.0, 2.5, 5.0, 10.0)
SCIENTIFIC = (1e-3, 1e5)
"""Ticks whose largest magnitude lies outside this range are labelled in a power of ten."""

MINUS = "\u2212"


@dataclass(frozen=True)
class Ticks:
    """Tick ``values`` (data units), their ``labels``, and the text beside the axis that
    they are read with (``1e-3``, ``+1000`` or nothing)."""

    values: tuple[float, ...]
    labels: tuple[str, ...]
    offset: str = ""


def data_range(values: np.ndarray, margin: float = MARGIN) -> tuple[float, float]:
    """The span of the finite ``values`` widened by ``margin`` each side; a single value
    gets a span around it, and no finite value (0, 1). The range is finite even for
    values near the largest double (the margin is then cut at it)."""
    finite = values[np.isfinite(values)]
    if finite.size == 0:
        return 0.0, 1.0
    lo, hi = float(finite.min()), float(finite.max())
    if hi - lo <= 1e-12 * max(1.0, abs(lo), abs(hi)):
        pad = 0.05 * abs(lo) if lo != 0 else 0.05
        lo, hi = lo - pad, hi + pad
    pad = 2 * margin * (hi / 2 - lo / 2)  # halves: no overflow for a span of +-1e308
    biggest = float(np.finfo(float).max)
    return max(lo - pad, -biggest), min(hi + pad, biggest)


def ticks(lo: float, hi: float, most: int) -> Ticks:
    """At most ``most`` + 1 round ticks within [lo, hi], labelled; none for a range whose
    ticks a double cannot step through (a step under 1e-300 or over 1e307)."""
    raw = (hi / 2 - lo / 2) / max(1, most) * 2
    if not (math.isfinite(lo) and math.isfinite(hi) and 1e-300 < raw < 1e307):
        return Ticks((), ())
    power = 10.0 ** math.floor(math.log10(raw))
    step = next(m * power for m in STEPS if m * power >= raw * (1 - 1e-9))
    first = math.ceil(lo / step - 1e-9)
    last = math.floor(hi / step + 1e-9)
    values = tuple(k * step for k in range(first, last + 1))
    return Ticks(values, *_labels(values, step, lo, hi))


def _labels(values: tuple[float, ...], step: float, lo: float, hi: float) -> tuple[tuple[str, ...], str]:
    offset = 0.0
    if hi - lo < 1e-4 * max(abs(lo), abs(hi)):
        power = 10.0 ** math.ceil(math.log10(hi - lo))
        offset = math.floor(lo / power) * power
    shown = [v - offset for v in values]
    largest = max((abs(v) for v in shown), default=0.0)
    exponent = 0
    if largest > 0 and not SCIENTIFIC[0] <= largest < SCIENTIFIC[1]:
        exponent = math.floor(math.log10(largest))
    scale = 10.0 ** -exponent
    decimals = max(0, -math.floor(math.log10(step * scale) + 1e-9))
    if _needs_more(step * scale, decimals):
        decimals += 1
    labels = tuple(_number(v * scale, decimals) for v in shown)
    beside = []
    if exponent:
        beside.append(f"1e{exponent}".replace("-", MINUS))
    if offset:
        beside.append(("+" if offset > 0 else MINUS) + _number(abs(offset), 0 if offset == round(offset) else 6))
    return labels, " ".join(beside)


def _needs_more(step: float, decimals: int) -> bool:
    """Whether ``step`` shown with ``decimals`` decimals loses a digit (2.5 with none)."""
    return abs(round(step, decimals) - step) > 1e-9 * step


def _number(value: float, decimals: int) -> str:
    text = f"{value:.{decimals}f}"
    if float(text) == 0.0:
        text = text.lstrip("-")
    return text.replace("-", MINUS)
