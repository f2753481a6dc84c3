"""Mux, Demux, Concatenate and Selector: values against numpy's concatenate, split and
indexing; ports, element labels, and selections the input's width cannot hold."""

from __future__ import annotations

import numpy as np
import pytest

import blocks
from blocks.library import Concatenate, Demux, Mux, Selector

from .stepping import step

RNG = np.random.default_rng(5)


def test_concatenate_and_mux_join_in_order():
    a, b, c = RNG.normal(size=(6, 2)), RNG.normal(size=(6, 1)), RNG.normal(size=(6, 3))
    block = Concatenate([2, 1, 3])
    assert block.inputs == {"u0": 2, "u1": 1, "u2": 3} and block.outputs == {"y": 6}
    np.testing.assert_array_equal(step(block, {"u0": a, "u1": b, "u2": c})["y"], np.hstack((a, b, c)))
    mux = Mux(3)
    assert mux.inputs == {"u0": 1, "u1": 1, "u2": 1}
    np.testing.assert_array_equal(step(mux, {"u0": b, "u1": b * 2, "u2": b * 3})["y"], np.hstack((b, 2 * b, 3 * b)))


def test_mux_labels_name_the_output_elements():
    mux = Mux([1, 2], labels=["speed", "pos"])
    assert mux.element_labels("y") == ["speed", "pos.0", "pos.1"]
    assert Mux(2).element_labels("y") is None


def test_demux_splits_in_order():
    u = RNG.normal(size=(5, 6))
    out = step(Demux([1, 3, 2]), {"u": u})
    parts = np.split(u, [1, 4], axis=1)
    for j in range(3):
        np.testing.assert_array_equal(out[f"y{j}"], parts[j])
    assert Demux(4).outputs == {"y0": 1, "y1": 1, "y2": 1, "y3": 1} and Demux(4).inputs == {"u": 4}


@pytest.mark.parametrize("indices, width, picked", [
    ([2, 0, 2], None, [2, 0, 2]), ("0:3", None, [0, 1, 2]), ("1:6:2", None, [1, 3, 5]),
    ([-1, 0], 6, [5, 0]), ("3:", 6, [3, 4, 5]), ("::-2", 6, [5, 3, 1]),
])
def test_selector_picks_like_numpy(indices, width, picked):
    u = RNG.normal(size=(4, 6))
    block = Selector(indices, width=width)
    assert block.outputs == {"y": len(picked)}
    np.testing.assert_array_equal(step(block, {"u": u})["y"], u[:, picked])


def test_an_index_past_a_connected_width_is_a_load_error_at_the_selector():
    with pytest.raises(blocks.DiagramError) as error:
        blocks.loads_diagram("""
blocks:
  c: {type: Constant, params: {value: [1.0, 2.0, 3.0]}}
  s: {type: Selector, params: {indices: [0, 3]}}
connections: [c.y -> s.u]
log: [s.y]
""")
    message = str(error.value)
    assert ":4: block 's' (Selector) cannot take the width 3" in message
    assert "index 3 is out of range for an input of width 3" in message


def test_indices_within_a_connected_width_load_and_pick():
    diagram = blocks.loads_diagram("""
blocks:
  c: {type: Constant, params: {value: [1.0, 2.0, 3.0]}}
  s: {type: Selector, params: {indices: [2, 0]}}
connections: [c.y -> s.u]
log: [s.y]
""")
    np.testing.assert_array_equal(blocks.simulate(diagram, t_end=0.1)["s.y"][1][0], [3.0, 1.0])


@pytest.mark.parametrize("cls, params, word", [
    (Selector, dict(indices=[5], width=3), "index 5 is out of range"),
    (Selector, dict(indices=[-1]), "give 'width'"), (Selector, dict(indices="2:"), "give 'width'"),
    (Selector, dict(indices=[]), "'indices'"), (Selector, dict(indices="a:b"), "'indices'"),
    (Selector, dict(indices="0:0"), "selects nothing"), (Selector, dict(indices=[0], width=0), "'width'"),
    (Mux, dict(widths=[1, 0]), "'widths'"), (Mux, dict(widths=2, labels=["a"]), "'labels'"),
    (Demux, dict(widths=[]), "'widths'"), (Concatenate, dict(widths=65), "at most 64"),
])
def test_bad_parameters_are_named(cls, params, word):
    with pytest.raises(ValueError, match=word):
        cls(**params)
