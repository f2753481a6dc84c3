"""ObjectSupport: the object's weight carried until the hand-over, from the plant's hand."""

from __future__ import annotations

import numpy as np
import pytest

from blocks import loads_diagram, simulate
from blocks.library import Step
from blocks.registry import resolve_type
from hierhand.model import Hand, HandPlant, ObjectSupport, load_hand


def test_it_carries_the_weight_until_the_hand_over_then_nothing():
    support = ObjectSupport(hand=Hand.default(), until=0.1)
    before = support.output(0.0, None, {})["y"]
    np.testing.assert_array_equal(before, [0.0, 2.943, 0.0])  # 0.3 kg * 9.81 m/s^2, as the diagrams had it
    assert not np.signbit(before).any()
    np.testing.assert_array_equal(support.output(0.09, None, {})["y"], before)
    np.testing.assert_array_equal(support.output(0.1, None, {})["y"], np.zeros(3))  # from 'until' on, like Step
    np.testing.assert_array_equal(support.output(0.5, None, {})["y"], np.zeros(3))
    assert support.output(0.0, None, {})["y"] is not support.output(0.0, None, {})["y"]


def test_the_force_is_minus_m_g_of_the_plants_hand():
    plant = HandPlant(gravity=[1.0, -9.7], object={"mass": 0.36})
    support = ObjectSupport(hand=plant)
    np.testing.assert_allclose(support.output(0.0, None, {})["y"], [-0.36, 0.36 * 9.7, 0.0], rtol=1e-15)
    assert support.until == 0.1


def test_it_is_a_registered_time_varying_source_without_inputs():
    assert resolve_type("ObjectSupport") is ObjectSupport
    support = ObjectSupport(hand=load_hand({}))
    assert ObjectSupport.time_varying and ObjectSupport.block_params == ("hand",)
    assert support.inputs == {} and support.outputs == {"y": 3} and not support.has_feedthrough()


def test_in_a_diagram_it_switches_at_until_on_its_period():
    d = loads_diagram("""
time: {t_end: 50 ms}
blocks:
  plant: {type: HandPlant, period: 0.1 ms, params: {object: {mass: 0.5}}}
  tau: {type: Constant, params: {value: [0, 0, 0, 0, 0, 0, 0, 0, 0]}}
  support: {type: ObjectSupport, period: 10 ms, params: {hand: plant, until: 0.02}}
connections:
  - tau.y -> plant.tau
  - support.y -> plant.f_ext
log: [support.y]
""")
    t, y = simulate(d)["support.y"]
    np.testing.assert_allclose(t, [0.0, 0.01, 0.02, 0.03, 0.04, 0.05])
    np.testing.assert_allclose(y[:, 1], [0.5 * 9.81] * 2 + [0.0] * 4)


@pytest.mark.parametrize("until", ["soon", float("nan"), True, None])
def test_until_must_be_a_finite_time(until):
    with pytest.raises(ValueError, match=r"^parameter 'until' must be a finite time in seconds"):
        ObjectSupport(hand=Hand.default(), until=until)


def test_its_hand_must_be_a_plant():
    with pytest.raises(ValueError, match=r"^parameter 'hand': the block is a Step; expected a HandPlant"):
        ObjectSupport(hand=Step(time=0.1))
