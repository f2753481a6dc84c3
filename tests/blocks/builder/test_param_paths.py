"""``--set`` paths into parameters: mapping keys, 0-based list indices, and their errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from blocks import DiagramError, load_diagram, loads_diagram
from blocks.builder.param_paths import PathError, set_path

ROOT = Path(__file__).resolve().parents[3]
DEFS = "python:tests.blocks.blockdefs"
WEIGHTS = f"""\
blocks:
  w: {{type: {DEFS}:Weights}}
"""


def no_start(name):
    return None


def test_a_path_sets_a_key_and_creates_missing_mappings():
    params = {"contact": {"mu_s": 1.0}}
    set_path(params, "plant", ["contact", "mu_d"], 0.8, no_start)
    set_path(params, "plant", ["object", "mass"], 0.36, no_start)
    assert params == {"contact": {"mu_s": 1.0, "mu_d": 0.8}, "object": {"mass": 0.36}}


def test_a_path_indexes_lists_from_zero():
    params = {"fingers": [{"links": [{"length": 1.0}, {"length": 2.0}]}, {"links": []}]}
    set_path(params, "plant", ["fingers", "0", "links", "1", "length"], 0.041, no_start)
    set_path(params, "plant", ["fingers", "1"], "whole", no_start)
    assert params == {"fingers": [{"links": [{"length": 1.0}, {"length": 0.041}]}, "whole"]}


def test_a_parameter_not_given_starts_from_the_blocks_default():
    params: dict = {}
    set_path(params, "b", ["gains", "1"], 5.0, lambda name: [1.0, 2.0, 3.0])
    assert params == {"gains": [1.0, 5.0, 3.0]}


@pytest.mark.parametrize("parts, message, hint", [
    (["xs", "3"], "index 3 is out of range: 'b.xs' has 2 element(s)", "valid indices: 0 to 1"),
    (["xs", "-1"], "'b.xs' is a list; '-1' is not an index of it", "0-based index (0 to 1)"),
    (["xs", "first"], "'b.xs' is a list; 'first' is not an index of it", "0-based index"),
    (["empty", "0"], "index 0 is out of range: 'b.empty' has 0 element(s)", "the list is empty"),
    (["k", "x", "y"], "'b.k.x' is a float (2.0), not a mapping or a list", "--set b.k.x=..."),
    (["xs", "0", "deeper"], "'b.xs.0' is a float (1.0), not a mapping or a list", ""),
])
def test_a_path_that_does_not_fit_says_why(parts, message, hint):
    params = {"xs": [1.0, 2.0], "empty": [], "k": {"x": 2.0}}
    with pytest.raises(PathError) as info:
        set_path(params, "b", parts, 0.0, no_start)
    assert str(info.value) == message
    assert hint in info.value.hint


def test_set_indexes_a_matrix_parameter_of_a_diagram():
    d = load_diagram(ROOT / "diagrams" / "toy.yaml", overrides={"plant.A.0.0": 0.5, "prop.k": 2.0})
    assert d.parameters()["plant"]["A"] == [[0.5]]
    np.testing.assert_array_equal(d.blocks["plant"].block.A, [[0.5]])


def test_set_into_a_parameter_the_diagram_does_not_give():
    d = loads_diagram(WEIGHTS, trust=True, overrides={"w.weights.1": 5.0, "w.extra.2": 7.0})
    assert d.parameters()["w"] == {"weights": [1.0, 5.0], "extra": [1.0, 2.0, 7.0]}
    np.testing.assert_array_equal(d.blocks["w"].block.weights, [1.0, 5.0])


@pytest.mark.parametrize("key, text", [
    ("w.weights.2", "--set w.weights.2=1.0: index 2 is out of range: 'w.weights' has 2 element(s) "
                    "(hint: valid indices: 0 to 1)"),
    ("w.weights.x", "--set w.weights.x=1.0: 'w.weights' is a list; 'x' is not an index of it "
                    "(hint: address an element by its 0-based index (0 to 1))"),
])
def test_a_bad_index_in_set_is_one_line_naming_the_set(key, text):
    with pytest.raises(DiagramError) as info:
        loads_diagram(WEIGHTS, trust=True, overrides={key: 1.0})
    assert [str(i) for i in info.value.issues] == [text]


def test_override_issues_name_how_the_user_gave_them():
    with pytest.raises(DiagramError) as info:
        loads_diagram(WEIGHTS, overrides={"w.weights.x": 1, "w.nope": 2, "v.k": 3}, trust=True,
                      origins={"w.weights.x": "--grid w.weights.x=1,2", "v.k": "--points p.csv:1: column 'v.k'"})
    found = {i.override: str(i) for i in info.value.issues}
    assert found["w.weights.x"].startswith("--grid w.weights.x=1,2: 'w.weights' is a list")
    assert found["w.nope"].startswith("--set w.nope=2: block 'w' ")
    assert found["v.k"].startswith("--points p.csv:1: column 'v.k': no block named 'v'")


def test_issues_of_the_file_are_no_override():
    with pytest.raises(DiagramError) as info:
        loads_diagram(WEIGHTS + "  x: {type: Nope}\n", trust=True)
    assert [i.override for i in info.value.issues] == [None]
