"""Behaviour of Gain, Sum and Saturation: values, widths, signs, limits, parameter checks.

Their methods run their C kernels, which need the port widths: a block whose width is open
gets it from its input first (``sized``), as a diagram's wiring gives it."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from blocks.library import Gain, Saturation, Sum


def sized(block, width):
    """The block with its open width resolved."""
    if None in block.outputs.values():
        block.set_width(width)
    return block


class TestGain:
    def test_scalar_gain_is_polymorphic(self):
        block = Gain(2.5)
        assert block.inputs == {"u": None} and block.outputs == {"y": None}
        block.set_width(3)
        assert block.inputs == {"u": 3} and block.outputs == {"y": 3}
        y = block.output(0.0, None, {"u": np.array([1.0, -2.0, 4.0])})["y"]
        np.testing.assert_array_equal(y, [2.5, -5.0, 10.0])
        assert y.dtype == np.float64

    def test_vector_gain_is_elementwise(self):
        block = Gain([1.0, -1.0, 0.5])
        assert block.inputs == {"u": 3} and block.outputs == {"y": 3}
        y = block.output(0.0, None, {"u": np.array([2.0, 2.0, 2.0])})["y"]
        np.testing.assert_array_equal(y, [2.0, -2.0, 1.0])

    def test_matrix_gain_multiplies(self):
        K = np.array([[1.0, 2.0, 3.0], [0.0, -1.0, 0.5]])
        block = Gain(K)
        assert block.inputs == {"u": 3} and block.outputs == {"y": 2}
        u = np.array([1.0, -1.0, 2.0])
        np.testing.assert_allclose(block.output(0.0, None, {"u": u})["y"], K @ u)

    def test_feedthrough_and_stateless(self):
        block = Gain(3.0)
        assert block.has_feedthrough()
        assert block.initial_state() is None

    def test_output_does_not_alias_input(self):
        u = np.array([1.0, 2.0])
        y = sized(Gain(1.0), 2).output(0.0, None, {"u": u})["y"]
        assert not np.shares_memory(y, u)

    @pytest.mark.parametrize("bad", [np.nan, [1.0, np.inf], np.ones((2, 2, 2)), [], "x"])
    def test_bad_gain_raises(self, bad):
        with pytest.raises(ValueError, match="'k'"):
            Gain(bad)


def reference_sum(signs, inputs):
    total = np.zeros_like(inputs["u0"])
    for j, s in enumerate(signs):
        total = total + inputs[f"u{j}"] if s == "+" else total - inputs[f"u{j}"]
    return total


class TestSum:
    def test_ports_follow_signs(self):
        block = Sum("+-+")
        assert block.inputs == {"u0": None, "u1": None, "u2": None}
        assert block.outputs == {"y": None}
        block.set_width(2)
        assert block.inputs == {"u0": 2, "u1": 2, "u2": 2} and block.outputs == {"y": 2}

    def test_default_adds_two_inputs(self):
        block = sized(Sum(), 1)
        y = block.output(0.0, None, {"u0": np.array([1.0]), "u1": np.array([2.5])})["y"]
        np.testing.assert_array_equal(y, [3.5])

    def test_difference(self):
        block = sized(Sum("+-"), 2)
        y = block.output(0.0, None, {"u0": np.array([5.0, 1.0]), "u1": np.array([2.0, 3.0])})["y"]
        np.testing.assert_array_equal(y, [3.0, -2.0])

    @pytest.mark.parametrize(
        "signs", ["+", "-", "++", "+-", "-+", "--", "+++", "++-", "+--", "-+-", "---", "+-+-+", "-----+"]
    )
    def test_every_sign_pattern_matches_reference(self, signs):
        rng = np.random.default_rng(len(signs))
        inputs = {f"u{j}": rng.normal(size=3) for j in range(len(signs))}
        kept = {p: v.copy() for p, v in inputs.items()}
        y = sized(Sum(signs), 3).output(0.0, None, inputs)["y"]
        np.testing.assert_allclose(y, reference_sum(signs, inputs), rtol=1e-14, atol=1e-14)
        for p, v in inputs.items():
            np.testing.assert_array_equal(v, kept[p])
            assert not np.shares_memory(y, v)

    @given(st.text(alphabet="+-", min_size=1, max_size=8),
           st.lists(st.floats(-1e6, 1e6), min_size=8, max_size=8))
    @settings(max_examples=60)
    def test_signed_sum_property(self, signs, values):
        inputs = {f"u{j}": np.array([values[j]]) for j in range(len(signs))}
        y = sized(Sum(signs), 1).output(0.0, None, inputs)["y"]
        np.testing.assert_allclose(y, reference_sum(signs, inputs), rtol=1e-12, atol=1e-6)

    @pytest.mark.parametrize("bad", ["", "+*", "+ -", 2, None, ["+", "-"]])
    def test_bad_signs_raise(self, bad):
        with pytest.raises(ValueError, match="signs"):
            Sum(bad)


class TestSaturation:
    def test_clips_to_default_unit_band(self):
        block = Saturation()
        assert block.inputs == {"u": None} and block.outputs == {"y": None}
        y = sized(block, 5).output(0.0, None, {"u": np.array([-3.0, -0.5, 0.0, 0.99, 2.0])})["y"]
        np.testing.assert_array_equal(y, [-1.0, -0.5, 0.0, 0.99, 1.0])

    def test_limits_are_reached_exactly(self):
        block = sized(Saturation(lower=-2.0, upper=0.5), 4)
        y = block.output(0.0, None, {"u": np.array([-2.0, 0.5, -2.0001, 0.5001])})["y"]
        np.testing.assert_array_equal(y, [-2.0, 0.5, -2.0, 0.5])

    def test_vector_bounds_fix_the_width(self):
        block = Saturation(lower=[-1.0, 0.0], upper=[1.0, 10.0])
        assert block.inputs == {"u": 2} and block.outputs == {"y": 2}
        y = block.output(0.0, None, {"u": np.array([5.0, -5.0])})["y"]
        np.testing.assert_array_equal(y, [1.0, 0.0])

    def test_scalar_bound_broadcasts_to_vector_bound(self):
        block = Saturation(lower=0.0, upper=[1.0, 2.0, 3.0])
        assert block.inputs == {"u": 3}
        y = block.output(0.0, None, {"u": np.array([9.0, -9.0, 2.5])})["y"]
        np.testing.assert_array_equal(y, [1.0, 0.0, 2.5])

    def test_one_sided_limit_with_infinity(self):
        block = sized(Saturation(lower=0.0, upper=np.inf), 2)
        y = block.output(0.0, None, {"u": np.array([-1.0, 1e300])})["y"]
        np.testing.assert_array_equal(y, [0.0, 1e300])

    def test_output_does_not_alias_input(self):
        u = np.array([0.1])
        assert not np.shares_memory(sized(Saturation(), 1).output(0.0, None, {"u": u})["y"], u)

    def test_lower_above_upper_raises(self):
        with pytest.raises(ValueError, match="lower"):
            Saturation(lower=1.0, upper=0.0)
        with pytest.raises(ValueError, match="lower"):
            Saturation(lower=[0.0, 2.0], upper=[1.0, 1.0])

    def test_bad_bounds_raise(self):
        with pytest.raises(ValueError, match="upper"):
            Saturation(upper=np.nan)
        with pytest.raises(ValueError, match="lower"):
            Saturation(lower=[[0.0]])
        with pytest.raises(ValueError, match="width"):
            Saturation(lower=[0.0, 0.0], upper=[1.0, 1.0, 1.0])
