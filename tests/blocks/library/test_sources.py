"""Behaviour of the source blocks: values over time, broadcasting, parameter checks."""

import numpy as np
import pytest

from blocks.library import Constant, Ramp, Step


class TestConstant:
    def test_outputs_value_at_any_time(self):
        block = Constant([1.0, -2.5])
        assert block.outputs == {"y": 2}
        assert block.inputs == {}
        for t in (0.0, 3.7, 1e6):
            np.testing.assert_array_equal(block.output(t, None, {})["y"], [1.0, -2.5])

    def test_scalar_becomes_width_one(self):
        block = Constant(4)
        assert block.outputs == {"y": 1}
        y = block.output(0.0, None, {})["y"]
        assert y.dtype == np.float64 and y.shape == (1,)
        assert y[0] == 4.0

    def test_stateless_and_not_time_varying(self):
        block = Constant(1.0)
        assert block.initial_state() is None
        assert not block.time_varying
        assert not block.has_feedthrough()

    def test_output_is_a_fresh_array(self):
        block = Constant([1.0, 2.0])
        first = block.output(0.0, None, {})["y"]
        first[:] = 99.0
        np.testing.assert_array_equal(block.output(1.0, None, {})["y"], [1.0, 2.0])

    @pytest.mark.parametrize("bad", [np.nan, [1.0, np.inf], [[1.0, 2.0]], []])
    def test_bad_value_raises(self, bad):
        with pytest.raises(ValueError, match="value"):
            Constant(bad)


class TestStep:
    def test_switches_at_time_inclusive(self):
        block = Step(time=0.5, before=-1.0, after=3.0)
        assert block.time_varying
        assert block.output(0.0, None, {})["y"][0] == -1.0
        assert block.output(0.4999, None, {})["y"][0] == -1.0
        assert block.output(0.5, None, {})["y"][0] == 3.0
        assert block.output(7.0, None, {})["y"][0] == 3.0

    def test_defaults_are_zero_then_one(self):
        block = Step(time=1.0)
        assert block.output(0.9, None, {})["y"][0] == 0.0
        assert block.output(1.0, None, {})["y"][0] == 1.0

    def test_scalar_broadcasts_to_vector_width(self):
        block = Step(time=1.0, before=0.0, after=[1.0, 2.0, 3.0])
        assert block.outputs == {"y": 3}
        np.testing.assert_array_equal(block.output(0.0, None, {})["y"], [0.0, 0.0, 0.0])
        np.testing.assert_array_equal(block.output(2.0, None, {})["y"], [1.0, 2.0, 3.0])

        block = Step(time=1.0, before=[5.0, 6.0], after=-1.0)
        np.testing.assert_array_equal(block.output(2.0, None, {})["y"], [-1.0, -1.0])

    def test_output_is_a_fresh_array(self):
        block = Step(time=1.0, after=[1.0, 2.0])
        block.output(2.0, None, {})["y"][:] = 0.0
        np.testing.assert_array_equal(block.output(2.0, None, {})["y"], [1.0, 2.0])

    def test_mismatched_widths_raise(self):
        with pytest.raises(ValueError, match="before.*after|after.*before"):
            Step(time=1.0, before=[0.0, 0.0], after=[1.0, 1.0, 1.0])

    @pytest.mark.parametrize("bad", [np.nan, np.inf, "soon", None])
    def test_bad_time_raises(self, bad):
        with pytest.raises(ValueError, match="time"):
            Step(time=bad)

    def test_non_finite_level_raises(self):
        with pytest.raises(ValueError, match="after"):
            Step(time=1.0, after=np.nan)


class TestRamp:
    def test_values(self):
        block = Ramp(slope=2.0, start=1.0, initial=0.5)
        assert block.time_varying
        assert block.output(0.0, None, {})["y"][0] == 0.5
        assert block.output(1.0, None, {})["y"][0] == 0.5
        assert block.output(1.25, None, {})["y"][0] == pytest.approx(1.0)
        assert block.output(4.0, None, {})["y"][0] == pytest.approx(6.5)

    def test_defaults_give_y_equals_t(self):
        block = Ramp()
        for t in (0.0, 0.3, 12.0):
            assert block.output(t, None, {})["y"][0] == pytest.approx(t)

    def test_negative_slope(self):
        block = Ramp(slope=-1.0)
        assert block.output(3.0, None, {})["y"][0] == pytest.approx(-3.0)

    def test_vector_slope_with_scalar_initial(self):
        block = Ramp(slope=[1.0, -2.0], start=0.5, initial=1.0)
        assert block.outputs == {"y": 2}
        np.testing.assert_allclose(block.output(0.0, None, {})["y"], [1.0, 1.0])
        np.testing.assert_allclose(block.output(1.5, None, {})["y"], [2.0, -1.0])

    def test_vector_initial_with_scalar_slope(self):
        block = Ramp(slope=1.0, initial=[0.0, 10.0, 20.0])
        np.testing.assert_allclose(block.output(2.0, None, {})["y"], [2.0, 12.0, 22.0])

    def test_output_is_a_fresh_array(self):
        block = Ramp(initial=[1.0, 2.0])
        block.output(-1.0, None, {})["y"][:] = 0.0
        np.testing.assert_array_equal(block.output(-1.0, None, {})["y"], [1.0, 2.0])

    def test_bad_parameters_raise(self):
        with pytest.raises(ValueError, match="slope|initial"):
            Ramp(slope=[1.0, 2.0], initial=[0.0, 0.0, 0.0])
        with pytest.raises(ValueError, match="start"):
            Ramp(start=np.inf)
        with pytest.raises(ValueError, match="slope"):
            Ramp(slope=[[1.0]])
