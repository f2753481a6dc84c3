"""Relational, Compare, Logic, Switch and MultiportSwitch against numpy's comparisons and
logic and the switching rules Simulink documents (the multiport control truncated toward
zero, zero- or one-based, out of range an error or the last port)."""

from __future__ import annotations

import operator

import numpy as np
import pytest

import blocks
from blocks.library import Compare, Logic, MultiportSwitch, Relational, Switch

from .stepping import step

VALUES = np.array([-2.0, -1.0, -0.0, 0.0, 0.5, 1.0, np.nan, np.inf])
A = np.array(np.meshgrid(VALUES, VALUES)).reshape(2, -1).T  # every pair
OPS = {"<": operator.lt, "<=": operator.le, "==": operator.eq, "!=": operator.ne, ">=": operator.ge,
       ">": operator.gt}


@pytest.mark.parametrize("op", list(OPS))
def test_relational_and_compare_are_ieee_comparisons(op):
    u0, u1 = A[:, :1], A[:, 1:]
    np.testing.assert_array_equal(step(Relational(op), {"u0": u0, "u1": u1})["y"], OPS[op](u0, u1).astype(float))
    np.testing.assert_array_equal(step(Compare(op, 0.5), {"u": u0})["y"], OPS[op](u0, 0.5).astype(float))
    np.testing.assert_array_equal(step(Compare(op, [0.0, 1.0]), {"u": A})["y"], OPS[op](A, [0.0, 1.0]).astype(float))


TRUTH = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0], [0, 1, 1], [1, 0, 0], [1, 0, 1], [1, 1, 0], [1, 1, 1]],
                 dtype=float) * np.array([1.0, -3.0, np.nan])  # non-zero, NaN included, is true


def expected_logic(op, truth):
    t = truth != 0
    count = t.sum(axis=-1)
    n = t.shape[-1]
    return {"and": count == n, "or": count > 0, "nand": count != n, "nor": count == 0, "xor": count % 2 == 1,
            "nxor": count % 2 == 0}[op].astype(float)


@pytest.mark.parametrize("op", ["and", "or", "nand", "nor", "xor", "nxor"])
def test_logic_elementwise_and_across_one_inputs_elements(op):
    inputs = {f"u{j}": TRUTH[:, j:j + 1] for j in range(3)}
    np.testing.assert_array_equal(step(Logic(op, 3), inputs)["y"][:, 0], expected_logic(op, TRUTH))
    np.testing.assert_array_equal(step(Logic(op, 1), {"u": TRUTH})["y"][:, 0], expected_logic(op, TRUTH))


def test_not_negates_each_element():
    np.testing.assert_array_equal(step(Logic("not", 1), {"u": TRUTH})["y"], (TRUTH == 0).astype(float))


@pytest.mark.parametrize("criterion, threshold, passes", [
    (">=", 0.5, lambda c: c >= 0.5), (">", 0.5, lambda c: c > 0.5), ("nonzero", 0.0, lambda c: c != 0),
])
def test_switch_passes_u0_where_the_control_passes(criterion, threshold, passes):
    control = VALUES[:, None]
    a, b = np.full((8, 2), 1.0), np.full((8, 2), 2.0)
    y = step(Switch(criterion, threshold), {"u0": a, "control": control, "u1": b})["y"]
    np.testing.assert_array_equal(y, np.where(passes(control), a, b))
    each = np.column_stack([VALUES, VALUES[::-1]])
    y = step(Switch(criterion, threshold, elementwise=True), {"u0": a, "control": each, "u1": b})["y"]
    np.testing.assert_array_equal(y, np.where(passes(each), a, b))


@pytest.mark.parametrize("base", [0, 1])
def test_multiport_switch_truncates_the_control_toward_zero(base):
    data = {f"u{j}": np.full((7, 2), 10.0 * j) for j in range(3)}
    control = np.array([0.0, 0.9, 1.0, 1.7, 2.0, 2.99, -0.5])[:, None] + base
    y = step(MultiportSwitch(3, base=base, default="last"), {"control": control, **data})["y"][:, 0]
    np.testing.assert_array_equal(y, [0.0, 0.0, 10.0, 10.0, 20.0, 20.0, 0.0 if base == 0 else 20.0])


def test_multiport_switch_out_of_range_stops_the_run_or_takes_the_last_input():
    y = step(MultiportSwitch(2, default="last"), {"control": [[5.0], [np.nan]], "u0": [[1.0]] * 2,
                                                 "u1": [[2.0]] * 2})["y"]
    np.testing.assert_array_equal(y, [[2.0], [2.0]])
    diagram = blocks.loads_diagram("""
blocks:
  k: {type: Ramp, period: 1 ms, params: {slope: 1000.0}}
  a: {type: Constant, params: {value: 1.0}}
  b: {type: Constant, params: {value: 2.0}}
  m: {type: MultiportSwitch, params: {inputs: 2}}
connections: [k.y -> m.control, a.y -> m.u0, b.y -> m.u1]
log: [m.y]
""")
    results = blocks.simulate(diagram, t_end="5 ms")
    assert results.status.startswith("failed at t=0.002 s") and "control selects no data input" in results.status
    np.testing.assert_array_equal(results["m.y"][1][:, 0], [1.0, 2.0])


@pytest.mark.parametrize("cls, params, word", [
    (Relational, dict(op="=<"), "'op'"), (Compare, dict(constant=np.nan), "'constant'"),
    (Logic, dict(op="not", inputs=2), "'inputs'"), (Logic, dict(op="andnot"), "'op'"),
    (Switch, dict(criterion="<"), "'criterion'"), (Switch, dict(elementwise=1), "'elementwise'"),
    (MultiportSwitch, dict(base=2), "'base'"), (MultiportSwitch, dict(default="first"), "'default'"),
    (MultiportSwitch, dict(inputs=0), "'inputs'"),
])
def test_bad_parameters_are_named(cls, params, word):
    with pytest.raises(ValueError, match=word):
        cls(**params)
