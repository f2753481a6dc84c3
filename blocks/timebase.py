"""Exact time: durations as rationals parsed from decimal text, ticks as integers.

Periods, offsets and end times are ``fractions.Fraction`` seconds, parsed from the
decimal text the user wrote (``"0.1 ms"``, ``"100us"``, ``0.5``, ``"1 min"``), never
through a binary float, so that 0.1 ms is exactly 1/10000 s and rate coincidences are
exact. Any unit of time pint knows is read (``min``, ``h``, ``day``, ``hour``): its
length in seconds as the shortest decimal of pint's factor, exact for every unit that is
a decimal number of seconds.
"""

from __future__ import annotations

import functools
import math
import re
from fractions import Fraction
from functools import reduce

_UNITS = {"s": Fraction(1), "ms": Fraction(1, 1000), "us": Fraction(1, 10**6),
          "µs": Fraction(1, 10**6), "ns": Fraction(1, 10**9)}
"""The units durations are written back in; read without pint, as are ``min`` and ``h``."""
_READ_UNITS = {**_UNITS, "min": Fraction(60), "h": Fraction(3600)}
_DURATION = re.compile(
    r"^\s*(?P<num>[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)\s*(?P<unit>[^\W\d][\w]*)?\s*$")
UNITS_SHOWN = "s, ms, us, ns, min, h or any unit of time pint knows"


MIN_DURATION = Fraction(1, 10**12)
MAX_DURATION = Fraction(10**9)
"""Nonzero durations outside [1 ps, 1e9 s] are rejected: they are typos, and exact ticks
of such spans would not fit the executor's integer and float arithmetic."""


MAX_DURATION_CHARS = 60
"""Longest duration text: 17 significant digits, a point, a sign, an exponent and a unit
fit many times over; a text of 100 000 digits is refused before it becomes a number."""


class DurationError(ValueError):
    """A duration text that is not a number with an optional unit."""


def _in_range(seconds: Fraction, text: object) -> Fraction:
    if seconds != 0 and not MIN_DURATION <= abs(seconds) <= MAX_DURATION:
        raise DurationError(f"duration {text!r} is out of range (1e-12 s to 1e9 s)")
    return seconds


def parse_duration(value: object) -> Fraction:
    """Seconds as an exact Fraction from ``"1 ms"``, ``"100us"``, ``0.5`` or ``2``.

    A float is read through its shortest decimal representation (``repr``), which
    is the text the user typed for every value a YAML or Python literal can hold.
    """
    if isinstance(value, bool):
        raise DurationError(f"expected a duration, got {value!r}")
    if isinstance(value, int):
        return _in_range(Fraction(value), value)
    if isinstance(value, Fraction):
        return _in_range(value, value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise DurationError(f"expected a finite duration, got {value!r}")
        return _in_range(Fraction(repr(value)), value)
    if isinstance(value, str):
        if len(value) > MAX_DURATION_CHARS:
            raise DurationError(f"duration {value[:20]!r}... has {len(value)} characters; a duration is a number "
                                f"of at most {MAX_DURATION_CHARS} characters and a unit")
        m = _DURATION.match(value)
        if m:
            mantissa, _, exponent = m["num"].lower().partition("e")
            if exponent and abs(int(exponent)) > 30:
                raise DurationError(f"duration {value!r} is out of range (1e-12 s to 1e9 s)")
            per = _seconds_per(m["unit"] or "s")
            if per is not None:
                return _in_range(Fraction(m["num"]) * per, value)
    raise DurationError(
        f"cannot read {value!r} as a duration; write a number of seconds or a number "
        f"with a unit of time: {UNITS_SHOWN} (e.g. '0.1 ms', '2 min')")


def _seconds_per(unit: str) -> Fraction | None:
    """The seconds in one ``unit``: exact for s, ms, us, ns, min and h, else pint's factor
    as its shortest decimal; None when pint does not know it as a unit of time."""
    found = _READ_UNITS.get(unit)
    if found is not None:
        return found
    from .units import seconds_in

    seconds = seconds_in(unit)
    return None if seconds is None else Fraction(repr(seconds))


def positive_duration(value: object, what: str) -> Fraction:
    """``value`` as a duration longer than zero: the rule of an end time, a period and a
    step, checked here only. DurationError otherwise, its message starting with ``what``
    (``"time.t_end"``, ``"--t-end"``, ``"block 'g': period"``)."""
    try:
        seconds = parse_duration(value)
    except DurationError as exc:
        raise DurationError(f"{what}: {exc}") from None
    if seconds <= 0:
        raise DurationError(f"{what} must be positive, got {value!r}")
    return seconds


@functools.lru_cache(maxsize=256)
def format_duration(seconds: Fraction) -> str:
    """Short human text for an exact duration, in the largest unit giving a clean number."""
    if seconds == 0:
        return "0 s"
    for unit in ("s", "ms", "us", "ns"):
        value = seconds / _UNITS[unit]
        if abs(value) >= 1 or unit == "ns":
            if value.denominator == 1:
                return f"{value.numerator} {unit}"
            return f"{float(value):g} {unit}"
    raise AssertionError("unreachable")


def exact_duration_text(seconds: Fraction) -> str:
    """``seconds`` as text that ``parse_duration`` reads back exactly (``"0.1 ms"``,
    ``"2.5 s"``), in the largest unit giving a number of at least 1; ValueError for a
    duration no decimal text gives (1/3 s)."""
    if seconds == 0:
        return "0 s"
    for unit in ("s", "ms", "us", "ns"):
        value = seconds / _UNITS[unit]
        if abs(value) >= 1 or unit == "ns":
            break
    digits = 0
    while (value * 10**digits).denominator != 1:
        digits += 1
        if digits > 30:
            raise ValueError(f"the duration {seconds} s is not a decimal number of seconds")
    scaled = abs(value * 10**digits).numerator
    whole, frac = divmod(scaled, 10**digits)
    text = str(whole) + (f".{frac:0{digits}d}".rstrip("0") if digits else "")
    return f"{'-' if value < 0 else ''}{text} {unit}"


def fraction_gcd(values: list[Fraction]) -> Fraction:
    """Greatest common divisor of positive rationals: gcd(numerators)/lcm(denominators)."""
    num = reduce(math.gcd, (v.numerator for v in values))
    den = reduce(math.lcm, (v.denominator for v in values))
    return Fraction(num, den)


def tick_time(k: int, tick: Fraction) -> float:
    """The float nearest to ``k * tick``: one integer product, one correctly rounded division."""
    return k * tick.numerator / tick.denominator
