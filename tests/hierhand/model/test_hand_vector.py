"""The hand vector and its inverse: hand dict -> numbers by FMI-style name -> hand dict."""

from __future__ import annotations

import numpy as np
import pytest

from hierhand.model import load_hand
from hierhand.model.hand_vector import flatten, hand_dict, hand_vector, parameter_names, unflatten


def without_names(hand: dict) -> dict:
    for finger in hand["fingers"]:
        finger.pop("name")
    return hand


@pytest.fixture
def hand():
    """A hand unlike the default in every section."""
    return load_hand({"gravity": [0.5, -9.7], "object": {"mass": 0.36, "pos": [0.001, 0.061]},
                      "contact": {"mu_s": 1.1, "mu_d": 1.0}})


def test_hand_dict_inverts_hand_vector(hand):
    data = hand_dict(hand.vector)
    assert data == without_names(hand.params.to_dict())
    assert data["fingers"][1]["links"][2]["com"] == [0.006, 0.0]
    np.testing.assert_array_equal(hand_vector(data), hand.vector)


def test_unflatten_inverts_flatten(hand):
    flat = flatten(hand.params.to_dict())
    assert set(flat) == set(parameter_names())
    assert unflatten(flat) == without_names(hand.params.to_dict())
    assert flatten(unflatten(flat)) == flat


def test_names_are_one_based():
    data = unflatten({"fingers[1].q0[1]": 1.0, "fingers[1].q0[2]": 2.0, "gravity[2]": -9.81, "gravity[1]": 0.0})
    assert data == {"fingers": [{"q0": [1.0, 2.0]}], "gravity": [0.0, -9.81]}


@pytest.mark.parametrize("values, message", [
    ({"fingers[2].q0[1]": 1.0}, r"indices of 'fingers' must run from 1 to 1"),
    ({"gravity[1]": 1.0, "gravity[3]": 2.0}, r"indices of 'gravity' must run from 1 to 2"),
    ({"object..mass": 1.0}, r"'object..mass' is not a hand-vector name"),
    ({"gravity": 1.0, "gravity[1]": 2.0}, r"'gravity\[1\]': a number is also given for a part of its path"),
    ({"gravity[1]": 2.0, "gravity": 1.0}, r"'gravity': numbers are also given for parts of it"),
])
def test_unflatten_rejects_names_that_do_not_make_a_hand(values, message):
    with pytest.raises(ValueError, match=message):
        unflatten(values)


def test_hand_dict_needs_the_whole_vector():
    with pytest.raises(ValueError, match=f"a hand vector has {len(parameter_names())} numbers, got shape \\(3,\\)"):
        hand_dict([1.0, 2.0, 3.0])
