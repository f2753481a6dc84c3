"""Exact time: durations parse to exact Fractions, ticks map to correctly rounded floats."""

from __future__ import annotations

import math
from fractions import Fraction

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from blocks import parse_duration
from blocks.timebase import DurationError, fraction_gcd, tick_time


@pytest.mark.parametrize("text, expected", [
    ("0.1 ms", Fraction(1, 10_000)),
    ("1ms", Fraction(1, 1000)),
    ("10 ms", Fraction(1, 100)),
    ("100 us", Fraction(1, 10_000)),
    ("0.5 s", Fraction(1, 2)),
    (0.0001, Fraction(1, 10_000)),
    (2, Fraction(2)),
    ("1e-4", Fraction(1, 10_000)),
    ("2", Fraction(2)),
    ("0.1", Fraction(1, 10)),
    (0.1, Fraction(1, 10)),
    ("250 ns", Fraction(1, 4_000_000)),
    ("  3 s  ", Fraction(3)),
    ("1.5e-3 s", Fraction(3, 2000)),
    (".5 ms", Fraction(1, 2000)),
    ("0 s", Fraction(0)),
])
def test_parse_duration_is_exact(text, expected):
    value = parse_duration(text)
    assert isinstance(value, Fraction)
    assert value == expected


@pytest.mark.parametrize("text, seconds", [
    ("1 min", 60), ("1.5 min", 90), ("2 h", 7200), ("0.25h", 900), ("1 hour", 3600), ("3 minutes", 180),
    ("1 day", 86400), ("2 ks", 2000), ("1 millisecond", Fraction(1, 1000)), ("-1 min", -60),
])
def test_durations_read_any_unit_of_time_exactly(text, seconds):
    assert parse_duration(text) == Fraction(seconds)


@pytest.mark.parametrize("text", ["40 year", "20000 day", "1e-15 min"])
def test_durations_in_other_units_keep_the_range(text):
    with pytest.raises(DurationError, match="out of range"):
        parse_duration(text)


def test_parse_duration_does_not_go_through_binary_floats():
    # 0.1 ms written three ways is one exact number, and ten of them make exactly 1 ms.
    assert parse_duration("0.1 ms") == parse_duration("100 us") == parse_duration(0.0001)
    assert 10 * parse_duration("0.1 ms") == parse_duration("1 ms")
    assert parse_duration(0.3) == Fraction(3, 10) != Fraction(0.3)


def test_parse_duration_keeps_a_fraction():
    assert parse_duration(Fraction(1, 3)) == Fraction(1, 3)


@given(st.integers(min_value=0, max_value=10**9), st.integers(min_value=0, max_value=9),
       st.sampled_from([("s", 1), ("ms", 1000), ("us", 10**6), ("ns", 10**9)]))
def test_parse_duration_of_decimal_text_is_exact(mantissa, decimals, unit):
    name, per_second = unit
    value = Fraction(mantissa, 10**decimals * per_second)
    assume(value == 0 or Fraction(1, 10**12) <= value <= 10**9)
    digits = str(mantissa).rjust(decimals + 1, "0")
    text = f"{digits[:len(digits) - decimals]}.{digits[len(digits) - decimals:]}" if decimals else digits
    assert parse_duration(f"{text} {name}") == Fraction(mantissa, 10**decimals * per_second)
    assert parse_duration(f"{text}{name}") == Fraction(mantissa, 10**decimals * per_second)


@pytest.mark.parametrize("text", ["1e5000 s", "1e-5000", "0.0001 ns", 1e10, "2e9 s", Fraction(1, 10**13)])
def test_parse_duration_rejects_absurd_magnitudes(text):
    with pytest.raises(DurationError, match="out of range"):
        parse_duration(text)


@pytest.mark.parametrize("bad", [
    "fast", "", "   ", "ms", "1 m", "1 Hz", "1 s2", "1 kg", "1 nothing", "1 ms ms", "1,5 ms", "1.2.3", "nan", "inf", "-inf",
    "1 ms2", "0x10", "one ms", "1e", "e3", "--1",
    float("nan"), float("inf"), -float("inf"), True, False, None, [1], {"s": 1}, b"1 ms",
])
def test_parse_duration_rejects_bad_values(bad):
    with pytest.raises(DurationError) as info:
        parse_duration(bad)
    assert str(info.value)
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize("values, expected", [
    ([Fraction(1, 10_000), Fraction(1, 1000), Fraction(1, 100)], Fraction(1, 10_000)),
    ([Fraction(1, 3), Fraction(1, 2)], Fraction(1, 6)),
    ([Fraction(2, 3), Fraction(4, 5)], Fraction(2, 15)),
    ([Fraction(3, 7)], Fraction(3, 7)),
    ([Fraction(6), Fraction(4)], Fraction(2)),
    ([Fraction(3, 10_000), Fraction(1, 500)], Fraction(1, 10_000)),
])
def test_fraction_gcd(values, expected):
    assert fraction_gcd(values) == expected


positive_fractions = st.fractions(min_value=Fraction(1, 10**6), max_value=100, max_denominator=10**6)


@given(st.lists(positive_fractions, min_size=1, max_size=6))
def test_fraction_gcd_is_the_greatest_common_divisor(values):
    g = fraction_gcd(values)
    assert g > 0
    multiples = [v / g for v in values]
    assert all(m.denominator == 1 for m in multiples)          # g divides every value
    assert math.gcd(*(int(m) for m in multiples)) == 1         # and nothing larger does


def test_tick_time_is_the_nearest_float_for_many_ticks():
    tick = Fraction(1, 10_000)
    for k in list(range(0, 200_001)) + [10**9 + 7, 2**53 - 1, 2**53 + 1, 10**15 + 3]:
        assert tick_time(k, tick) == float(Fraction(k, 10_000)), k


def test_tick_time_does_not_accumulate():
    tick = Fraction(1, 10)
    assert tick_time(3, tick) == 0.3
    assert 0.1 * 3 != 0.3          # what accumulated float time would give instead
    assert tick_time(10, tick) == 1.0


@settings(max_examples=300)
@given(st.integers(min_value=0, max_value=10**12),
       st.fractions(min_value=Fraction(1, 10**9), max_value=10, max_denominator=10**9))
def test_tick_time_is_correctly_rounded_for_any_tick(k, tick):
    assert tick_time(k, tick) == float(k * tick)
