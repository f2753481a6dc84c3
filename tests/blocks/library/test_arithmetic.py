"""Product, Divide, Abs, Sign, Bias, MinMax and Math against numpy (and MATLAB's definitions
of mod and rem), elementwise and matrix products, and the singular-matrix failure."""

from __future__ import annotations

import numpy as np
import pytest

import blocks
from blocks.block import BlockError
from blocks.library import Abs, Bias, Divide, Math, MinMax, Product, Sign
from blocks.library.arithmetic import BINARY, UNARY

from .stepping import step

RNG = np.random.default_rng(11)
A = RNG.normal(size=(40, 3))
B = RNG.normal(size=(40, 3))
C = RNG.normal(size=(40, 3))
SPECIAL = np.array([[0.0, -0.0, np.nan], [np.inf, -np.inf, 1e-300], [-2.5, 3.0, 7.0]])


def test_elementwise_products_and_quotients_in_order():
    y = step(Product("*/*"), {"u0": A, "u1": B, "u2": C})["y"]
    np.testing.assert_array_equal(y, A / B * C)
    np.testing.assert_array_equal(step(Divide(), {"u0": A, "u1": B})["y"], A / B)
    np.testing.assert_array_equal(step(Product("/*"), {"u0": A, "u1": B})["y"], 1.0 / A * B)
    np.testing.assert_array_equal(step(Product(3), {"u0": A, "u1": B, "u2": C})["y"], A * B * C)


def test_one_input_collapses_its_elements():
    np.testing.assert_array_equal(step(Product("*"), {"u": A})["y"][:, 0], A[:, 0] * A[:, 1] * A[:, 2])
    np.testing.assert_array_equal(step(Product("/"), {"u": A})["y"][:, 0], 1.0 / A[:, 0] / A[:, 1] / A[:, 2])


def test_matrix_products_and_inverses_match_numpy():
    M = RNG.normal(size=(10, 2, 3))
    S = RNG.normal(size=(10, 3, 3)) + 3 * np.eye(3)
    V = RNG.normal(size=(10, 3, 1))
    block = Product("*/*", multiplication="matrix", shapes=[[2, 3], [3, 3], [3, 1]])
    assert block.inputs == {"u0": 6, "u1": 9, "u2": 3} and block.outputs == {"y": 2}
    y = step(block, {"u0": M.reshape(10, -1), "u1": S.reshape(10, -1), "u2": V.reshape(10, -1)})["y"]
    expected = np.stack([M[k] @ np.linalg.inv(S[k]) @ V[k] for k in range(10)]).reshape(10, -1)
    np.testing.assert_allclose(y, expected, rtol=1e-12, atol=1e-12)
    inv = step(Divide("/", multiplication="matrix", shapes=[[3, 3]]), {"u": S.reshape(10, -1)})["y"]
    np.testing.assert_allclose(inv, np.linalg.inv(S).reshape(10, -1), rtol=1e-12, atol=1e-13)


def test_a_singular_matrix_stops_the_run_naming_the_input():
    diagram = blocks.loads_diagram("""
blocks:
  a: {type: Constant, params: {value: [1.0, 2.0, 3.0, 4.0]}}
  b: {type: Step, period: 1 ms, params: {time: 0.002, before: [1.0, 0.0, 0.0, 1.0], after: [1.0, 2.0, 2.0, 4.0]}}
  p: {type: Divide, params: {multiplication: matrix, shapes: [[2, 2], [2, 2]]}}
connections: [a.y -> p.u0, b.y -> p.u1]
log: [p.y]
""")
    results = blocks.simulate(diagram, t_end="5 ms")
    assert results.status.startswith("failed at t=0.002 s")
    assert "input 'u1' is a singular matrix" in results.status
    np.testing.assert_allclose(results["p.y"][1], [[1.0, 2.0, 3.0, 4.0]] * 2)


@pytest.mark.parametrize("shapes, word", [
    ([[2, 3], [2, 2]], "input 1 has 2 rows"), ([[2, 3]], "each of the 2 inputs"), ([[2, 2], [2, 3]], "square"),
    ([[2, 0], [0, 2]], "at least 1"), ("2x2", "shapes"),
])
def test_bad_matrix_shapes_are_named(shapes, word):
    with pytest.raises(ValueError, match=word):
        Divide("*/", multiplication="matrix", shapes=shapes)


def test_abs_sign_bias():
    np.testing.assert_array_equal(step(Abs(), {"u": SPECIAL})["y"], np.abs(SPECIAL))
    np.testing.assert_array_equal(step(Sign(), {"u": SPECIAL})["y"], np.sign(SPECIAL))
    np.testing.assert_array_equal(step(Bias([1.0, -2.0, 0.5]), {"u": A})["y"], A + [1.0, -2.0, 0.5])
    assert Bias(2.0).inputs == {"u": None} and Bias([1.0, 2.0]).inputs == {"u": 2}


def test_minmax_over_elements_and_across_inputs():
    np.testing.assert_array_equal(step(MinMax("max"), {"u": A})["y"][:, 0], A.max(axis=1))
    np.testing.assert_array_equal(step(MinMax("min", 3), {"u0": A, "u1": B, "u2": C})["y"],
                                  np.minimum(np.minimum(A, B), C))
    assert np.isnan(step(MinMax("min"), {"u": SPECIAL[:1]})["y"][0, 0])  # a NaN wins, as in numpy
    np.testing.assert_array_equal(step(MinMax("max", 2), {"u0": SPECIAL, "u1": SPECIAL[::-1]})["y"],
                                  np.maximum(SPECIAL, SPECIAL[::-1]))


NUMPY = {"exp": np.exp, "log": np.log, "log10": np.log10, "sqrt": np.sqrt, "square": np.square,
         "reciprocal": np.reciprocal, "sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin,
         "acos": np.arccos, "atan": np.arctan, "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh,
         "atan2": np.arctan2, "pow": np.power, "hypot": np.hypot}


def matlab_mod(a, b):
    return np.where(b == 0, a, a - np.floor(a / b) * b)


def matlab_rem(a, b):
    return np.fmod(a, b)


@pytest.mark.parametrize("function", UNARY)
def test_math_one_argument_functions_match_numpy(function):
    u = np.concatenate((A, 0.9 * np.tanh(A), SPECIAL))
    with np.errstate(all="ignore"):
        expected = NUMPY[function](u)
    y = step(Math(function), {"u": u})["y"]
    np.testing.assert_allclose(y, expected, rtol=4e-16, atol=0, equal_nan=True)


@pytest.mark.parametrize("function", BINARY)
def test_math_two_argument_functions_match_numpy_and_matlab(function):
    a = np.concatenate((A * 3, [[5.0, -5.0, 5.0], [0.0, 1.0, -1.0]]))
    b = np.concatenate((B, [[3.0, 3.0, -3.0], [2.0, 0.0, 0.0]]))
    if function == "pow":
        a = np.abs(a)
    reference = {"mod": matlab_mod, "rem": matlab_rem}.get(function, NUMPY.get(function))
    with np.errstate(all="ignore"):
        expected = reference(a, b)
    y = step(Math(function), {"u0": a, "u1": b})["y"]
    np.testing.assert_allclose(y, expected, rtol=4e-16, atol=1e-15, equal_nan=True)
    if function == "mod":
        np.testing.assert_array_equal(y[-2:], [[2.0, 1.0, -1.0], [0.0, 1.0, -1.0]])  # the divisor's sign


@pytest.mark.parametrize("cls, params, word", [
    (Product, dict(ops="*+"), "'ops'"), (Product, dict(ops=""), "'ops'"), (Product, dict(ops=0), "'ops'"),
    (Product, dict(multiplication="dot"), "'multiplication'"), (Product, dict(shapes=[[1, 1]] * 2), "'shapes'"),
    (Math, dict(function="gamma"), "'function'"), (MinMax, dict(function="mean"), "'function'"),
    (MinMax, dict(inputs=0), "'inputs'"), (Bias, dict(bias=[[1.0]]), "'bias'"),
])
def test_bad_parameters_are_named(cls, params, word):
    with pytest.raises(ValueError, match=word):
        cls(**params)


def test_an_input_of_the_wrong_width_is_refused_before_the_kernel_reads_it():
    block = Abs()
    block.set_width(3)
    with pytest.raises(BlockError, match="input 'u' has shape"):
        block.output(0.0, None, {"u": np.zeros(2)})
