"""Axis ticks: round values inside the range, not too many, labels that read back as the
values (with the power of ten or offset beside the axis), and autoscaled ranges."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from blocks.plot.ticks import MINUS, data_range, ticks


def read_back(label: str, beside: str) -> float:
    """A tick label's value, read with the text beside its axis (``1e-3``, ``+1000``)."""
    value = float(label.replace(MINUS, "-"))
    for part in beside.replace(MINUS, "-").split():
        value = value * 10.0 ** int(part[2:]) if part.startswith("1e") else value + float(part)
    return value


ranges = st.tuples(st.floats(-1e9, 1e9), st.floats(1e-9, 1e9)).filter(lambda r: r[1] > 1e-12 * max(1, abs(r[0])) * 1e4)


@settings(max_examples=300, deadline=None)
@given(ranges, st.integers(2, 12))
def test_ticks_are_round_inside_the_range_and_read_back(lo_span, most):
    lo, span = lo_span
    hi = lo + span
    t = ticks(lo, hi, most)
    assert 1 <= len(t.values) <= most + 1 or span < 1e-6 * abs(lo)
    step = np.diff(t.values)
    if len(step):
        assert np.allclose(step, step[0], rtol=1e-6)
        mantissa = step[0] / 10 ** math.floor(math.log10(step[0]))
        assert min(abs(mantissa - m) for m in (1, 2, 2.5, 5, 10)) < 1e-6
    for v in t.values:
        assert lo - 1e-9 * abs(span) <= v <= hi + 1e-9 * abs(span)
    assert len(set(t.labels)) == len(t.labels)  # no two ticks read the same
    for v, label in zip(t.values, t.labels):
        assert read_back(label, t.offset) == pytest.approx(v, rel=1e-9, abs=1e-6 * span)
        assert len(label) <= 8  # never a dozen digits: the power of ten or offset goes beside the axis


@pytest.mark.parametrize("lo, hi, labels, beside", [
    (0.0, 1.0, ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"], ""),
    (-0.055, 0.055, [f"{MINUS}0.050", f"{MINUS}0.025", "0.000", "0.025", "0.050"], ""),  # 2.5: a digit more
    (0.0, 2e6, ["0.0", "0.5", "1.0", "1.5", "2.0"], "1e6"),
    (-3e-5, 2e-5, [f"{MINUS}3", f"{MINUS}2", f"{MINUS}1", "0", "1", "2"], f"1e{MINUS}5"),
    (1000.0001, 1000.0003, ["1.0", "1.5", "2.0", "2.5", "3.0"], f"1e{MINUS}4 +1000"),
])
def test_labels_as_one_would_write_them(lo, hi, labels, beside):
    t = ticks(lo, hi, 5)
    assert list(t.labels) == labels and t.offset == beside


def test_an_autoscaled_range_has_margins_and_survives_flat_and_missing_data():
    assert data_range(np.array([0.0, 1.0])) == pytest.approx((-0.05, 1.05))
    lo, hi = data_range(np.array([2.0, 2.0]))
    assert lo < 2.0 < hi
    lo, hi = data_range(np.array([0.0]))
    assert lo < 0.0 < hi
    assert data_range(np.array([np.nan, np.inf, 1.0, 3.0])) == pytest.approx((0.9, 3.1))  # finite values only
    assert data_range(np.array([np.nan])) == (0.0, 1.0)
    assert ticks(1.0, 1.0, 5).values == () and ticks(0.0, math.inf, 5).values == ()
