"""Behaviour of UnitDelay and ZeroOrderHold."""

from fractions import Fraction

import numpy as np
import pytest

from blocks.block import Block
from blocks.library import UnitDelay, ZeroOrderHold


class TestUnitDelay:
    def test_delays_by_one_sample(self):
        block = UnitDelay(initial=7.0)
        block.set_width(1)
        state = block.initial_state()
        seen = []
        for u in (1.0, 2.0, 3.0):
            seen.append(block.output(0.0, state, {"u": np.array([u])})["y"][0])
            state = block.update(0.0, state, {"u": np.array([u])})
        assert seen == [7.0, 1.0, 2.0]

    def test_no_feedthrough(self):
        block = UnitDelay()
        assert block.feedthrough is False
        assert not block.has_feedthrough()
        assert block.is_stateful()

    def test_scalar_initial_is_polymorphic_and_broadcast(self):
        block = UnitDelay(initial=2.0)
        assert block.inputs == {"u": None} and block.outputs == {"y": None}
        block.set_width(3)
        np.testing.assert_array_equal(block.initial_state(), [2.0, 2.0, 2.0])

    def test_vector_initial_fixes_width(self):
        block = UnitDelay(initial=[1.0, 2.0])
        assert block.inputs == {"u": 2} and block.outputs == {"y": 2}
        np.testing.assert_array_equal(block.initial_state(), [1.0, 2.0])

    def test_width_parameter(self):
        block = UnitDelay(initial=0.5, width=4)
        assert block.inputs == {"u": 4} and block.outputs == {"y": 4}
        np.testing.assert_array_equal(block.initial_state(), [0.5] * 4)

    def test_output_and_state_are_not_aliases(self):
        """The output is a copy of the state, the state (updated in place, as every
        library block's) a copy of the input."""
        block = UnitDelay(initial=[1.0, 2.0])
        state = block.initial_state()
        y = block.output(0.0, state, {"u": np.zeros(2)})["y"]
        assert not np.shares_memory(y, state)
        u = np.array([3.0, 4.0])
        new_state = block.update(0.0, state, {"u": u})
        assert not np.shares_memory(new_state, u) and not np.shares_memory(new_state, y)
        np.testing.assert_array_equal(new_state, [3.0, 4.0])
        np.testing.assert_array_equal(y, [1.0, 2.0])

    def test_advance_by_zero_keeps_state(self):
        block = UnitDelay(initial=[1.0, -1.0])
        state, out = block.advance(0.0, block.initial_state(), {"u": np.array([5.0, 5.0])}, 0)
        np.testing.assert_array_equal(state, [1.0, -1.0])
        assert out["y"].shape == (0, 2)

    @pytest.mark.parametrize("n", [1, 5, 100])
    def test_advance_matches_reference_loop(self, n):
        block = UnitDelay(initial=[1.0, -1.0])
        block.bind(Fraction(1, 10))
        inputs = {"u": np.array([0.25, 4.0])}
        state, out = block.advance(0.0, block.initial_state(), inputs, n)
        ref_state, ref_out = Block.advance(block, 0.0, block.initial_state(), inputs, n)
        np.testing.assert_array_equal(state, ref_state)
        assert out["y"].shape == (n, 2)
        np.testing.assert_array_equal(out["y"], ref_out["y"])

    @pytest.mark.parametrize(
        "kwargs", [{"width": 0}, {"width": 2.5}, {"width": "3"}, {"initial": [1.0, 2.0], "width": 3},
                   {"initial": np.nan}, {"initial": [[1.0]]}]
    )
    def test_bad_parameters_raise(self, kwargs):
        with pytest.raises(ValueError, match="width|initial"):
            UnitDelay(**kwargs)


class TestZeroOrderHold:
    def test_passes_input_through_as_copy(self):
        block = ZeroOrderHold()
        assert block.inputs == {"u": None} and block.outputs == {"y": None}
        assert block.has_feedthrough()
        assert block.initial_state() is None
        block.set_width(2)
        u = np.array([1.5, -2.0])
        y = block.output(0.0, None, {"u": u})["y"]
        np.testing.assert_array_equal(y, u)
        assert not np.shares_memory(y, u)

    def test_takes_no_parameters(self):
        assert ZeroOrderHold.parameters() == {}
