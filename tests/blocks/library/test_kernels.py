"""The library blocks' compiled kernels equal their Python methods bit for bit.

Each kernel is called alone through ``blocks._native.call`` and compared (``np.array_equal``,
and the same bits for NaN and signed zeros) with ``output`` / ``update`` / ``advance`` of
the same block, over several parameter sets (scalars, width-3 vectors, random 2x2 and 3x3 models).
"""

from fractions import Fraction

import numpy as np
import pytest

from blocks.kernel import Kernel
from blocks.library import (
    Constant,
    DiscreteStateSpace,
    DiscreteTransferFunction,
    Gain,
    Ramp,
    Saturation,
    Step,
    Sum,
    UnitDelay,
    ZeroOrderHold,
)
from blocks.library.lti import CHUNK

_native = pytest.importorskip("blocks._native")

TIMES = (-1.0, 0.0, 0.25, 0.5, 0.5000000000000001, 1.0, 3.7, 1e6)


def prepared(block, width=None, period=Fraction(1, 1000)):
    """The block with its period bound and its open widths resolved."""
    block.bind(period)
    if width is not None:
        block.set_width(width)
    return block


def kernel_of(block) -> Kernel:
    kernel = block.kernel()
    assert isinstance(kernel, Kernel)
    return kernel


def same(a, b) -> bool:
    """Equal arrays, bit for bit (so NaN equals NaN of the same payload, and 0.0 is not -0.0)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=True) and np.array_equal(
        np.ascontiguousarray(a).view(np.int64), np.ascontiguousarray(b).view(np.int64))


def port_list(block, inputs):
    return [np.ascontiguousarray(inputs[p], dtype=float) for p in block.inputs]


def out_width(block):
    return sum(block.outputs.values())


def c_output(block, t, state, inputs):
    kernel = kernel_of(block)
    out = np.full(out_width(block), np.nan)
    code, _ = _native.call("output", kernel.output, kernel.context, t, state, port_list(block, inputs),
                           out)
    assert code == 0
    return out


def c_update(block, t, state, inputs):
    kernel = kernel_of(block)
    state = state.copy()
    code, _ = _native.call("update", kernel.update, kernel.context, t, state, port_list(block, inputs), None)
    assert code == 0
    return state


def c_advance(block, t, state, inputs, n):
    kernel = kernel_of(block)
    state = None if state is None else state.copy()
    rows = np.full((max(n, 0), out_width(block)), np.nan)
    ports = port_list(block, inputs)
    code, done, _ = _native.call("advance", kernel.advance, kernel.context, t, state, ports, rows, n)
    assert code == 0 and done == max(n, 0)
    return state, rows


def py_output(block, t, state, inputs):
    out = block.output(t, None if state is None else state.copy(), inputs)
    return np.concatenate([np.atleast_1d(out[p]) for p in block.outputs])


def assert_outputs_equal(block, state, inputs, times=(0.0,)):
    for t in times:
        expected = py_output(block, t, state, inputs)
        got = c_output(block, t, state, inputs)
        assert same(got, expected), (t, got, expected)


# -- sources -------------------------------------------------------------------------


@pytest.mark.parametrize("value", [2.5, [1.0, -2.0, 3.5], [0.1]])
def test_constant(value):
    block = prepared(Constant(value))
    assert_outputs_equal(block, None, {}, TIMES)


@pytest.mark.parametrize("params", [
    dict(time=0.5),
    dict(time=0.5, before=[1.0, 2.0, 3.0], after=-1.5),
    dict(time=-0.3, before=0.1, after=[4.0, 5.0, 6.0]),
])
def test_step(params):
    block = prepared(Step(**params))
    assert_outputs_equal(block, None, {}, TIMES)


@pytest.mark.parametrize("params", [
    dict(),
    dict(slope=0.3, start=0.5, initial=1.0),
    dict(slope=[0.1, -0.7, 1e3], start=0.25, initial=[1.0, 2.0, 3.0]),
    dict(slope=[1.0 / 3.0, 2.0, 3.0], start=-1.0, initial=0.7),
])
def test_ramp(params):
    block = prepared(Ramp(**params))
    assert_outputs_equal(block, None, {}, TIMES)


# -- arithmetic ----------------------------------------------------------------------

RNG_SEEDS = (0, 1, 2)


@pytest.mark.parametrize("seed", RNG_SEEDS)
@pytest.mark.parametrize("k, width", [(2.5, 1), (-0.3, 3), ([1.0, -2.0, 1.0 / 3.0], 3), ([0.7], 1),
                                      ("m2", 2), ("m3", 3), ("m23", 3), ("m32", 2), ("m14", 4)])
def test_gain(k, width, seed):
    rng = np.random.default_rng(seed)
    if isinstance(k, str):
        shape = {"m2": (2, 2), "m3": (3, 3), "m23": (2, 3), "m32": (3, 2), "m14": (1, 4)}[k]
        k = rng.normal(size=shape)
    block = prepared(Gain(k), width)
    for _ in range(20):
        u = rng.normal(size=block.inputs["u"]) * 10.0 ** rng.integers(-3, 4)
        assert_outputs_equal(block, None, {"u": u})


@pytest.mark.parametrize("signs", ["+", "-", "++", "+-", "-+", "--", "+++", "++-", "+--", "-+-", "---",
                                   "-++-+"])
@pytest.mark.parametrize("width", [1, 3])
def test_sum(signs, width):
    rng = np.random.default_rng(len(signs) * 10 + width)
    block = prepared(Sum(signs), width)
    for _ in range(20):
        inputs = {f"u{j}": rng.normal(size=width) * 10.0 ** rng.integers(-8, 8) for j in range(len(signs))}
        assert_outputs_equal(block, None, inputs)


@pytest.mark.parametrize("lower, upper, width", [
    (-1.0, 1.0, 1),
    (-1.0, 1.0, 3),
    ([-1.0, 0.0, -np.inf], [1.0, 0.5, 2.0], 3),
    (-0.5, [0.0, np.inf, 3.0], 3),
])
def test_saturation(lower, upper, width):
    rng = np.random.default_rng(width)
    block = prepared(Saturation(lower, upper), width)
    for _ in range(20):
        assert_outputs_equal(block, None, {"u": rng.normal(size=width) * 3.0})
    assert_outputs_equal(block, None, {"u": np.full(width, np.nan)})
    assert_outputs_equal(block, None, {"u": np.full(width, np.inf)})


# -- discrete ------------------------------------------------------------------------


@pytest.mark.parametrize("initial, width", [(0.0, 1), (2.0, 3), ([1.0, -2.0, 3.0], 3)])
def test_unit_delay(initial, width):
    rng = np.random.default_rng(width)
    block = prepared(UnitDelay(initial=initial), width)
    state = block.initial_state()
    for _ in range(5):
        u = rng.normal(size=width)
        assert_outputs_equal(block, state, {"u": u})
        expected = block.update(0.0, state.copy(), {"u": u})
        assert same(c_update(block, 0.0, state, {"u": u}), expected)
        state = expected
    for n in (0, 1, 7, 100):
        u = rng.normal(size=width)
        x, rows = block.advance(0.0, state.copy(), {"u": u}, n)
        cx, crows = c_advance(block, 0.0, state, {"u": u}, n)
        if n:
            assert same(cx, x)
        assert same(crows, rows["y"])


@pytest.mark.parametrize("width", [1, 3])
def test_zero_order_hold(width):
    rng = np.random.default_rng(width)
    block = prepared(ZeroOrderHold(), width)
    for _ in range(5):
        assert_outputs_equal(block, None, {"u": rng.normal(size=width)})


# -- linear time-invariant -----------------------------------------------------------


def random_model(rng, n, m, p, with_d):
    A = rng.normal(size=(n, n))
    A *= 0.95 / max(abs(np.linalg.eigvals(A)))
    B = rng.normal(size=(n, m))
    C = rng.normal(size=(p, n))
    D = rng.normal(size=(p, m)) if with_d else None
    return A, B, C, D


LTI_SHAPES = [(1, 1, 1), (2, 1, 1), (2, 2, 2), (3, 1, 1), (3, 3, 3), (3, 2, 4), (2, 3, 1), (4, 3, 2)]


def lti_blocks():
    rng = np.random.default_rng(7)
    blocks = [
        DiscreteStateSpace([[0.999]], [[1.0e-4]], [[1.0]], [[0.0]]),  # the toy diagram's plant
        DiscreteStateSpace([[1.0]], [[0.02]], [[1.0]], [[0.0]]),  # and its integrator
        DiscreteStateSpace([[0.5]], [[0.3]], [[2.0]], [[0.7]], x0=[1.5]),
        DiscreteTransferFunction([1.0, 0.5], [1.0, -1.2, 0.36]),
        DiscreteTransferFunction([0.2, 0.1, 0.3], [1.0, -0.5, 0.06], x0=[0.3, -0.2]),
        DiscreteTransferFunction([2.0], [4.0]),  # a pure gain, no state
    ]
    for n, m, p in LTI_SHAPES:
        for with_d in (False, True):
            A, B, C, D = random_model(rng, n, m, p, with_d)
            blocks.append(DiscreteStateSpace(A, B, C, D, x0=rng.normal(size=n)))
    return blocks


LTI_BLOCKS = lti_blocks()


@pytest.mark.parametrize("index", range(len(LTI_BLOCKS)))
def test_lti_output_and_update(index):
    block = prepared(LTI_BLOCKS[index])
    rng = np.random.default_rng(index)
    state = block.initial_state()
    for _ in range(30):
        u = rng.normal(size=block.inputs["u"])
        assert_outputs_equal(block, state, {"u": u})
        if state is not None:
            expected = block.update(0.0, state.copy(), {"u": u})
            assert same(c_update(block, 0.0, state, {"u": u}), expected)
            state = expected


@pytest.mark.parametrize("n", [0, 1, 2, 7, CHUNK, CHUNK + 1, 100, 3 * CHUNK + 5])
@pytest.mark.parametrize("index", range(len(LTI_BLOCKS)))
def test_lti_advance(index, n):
    block = prepared(LTI_BLOCKS[index])
    rng = np.random.default_rng(1000 + index)
    state = block.initial_state()
    if state is not None:
        state = state + rng.normal(size=state.size)
    u = rng.normal(size=block.inputs["u"])
    x, rows = block.advance(0.0, None if state is None else state.copy(), {"u": u}, n)
    cx, crows = c_advance(block, 0.0, state, {"u": u}, n)
    assert same(crows, rows["y"])
    if state is not None:
        assert same(cx, x)
    # and again from where that left off: the kernel keeps no memory between calls
    if state is not None and n:
        x2, rows2 = block.advance(0.0, x.copy(), {"u": u}, 7)
        cx2, crows2 = c_advance(block, 0.0, cx, {"u": u}, 7)
        assert same(crows2, rows2["y"]) and same(cx2, x2)


@pytest.mark.parametrize("index", range(len(LTI_BLOCKS)))
def test_lti_all_chunks_are_the_chunk_maps(index):
    block = prepared(LTI_BLOCKS[index])
    if block.initial_state() is None:
        return
    ymap, xmaps = block._all_chunks()
    for c in range(1, CHUNK + 1):
        y, x = block._chunk(c)
        assert same(ymap[:c * block.outputs["y"]], y) and same(xmaps[c - 1], x)


def test_lti_kernel_refused_for_long_rows():
    rng = np.random.default_rng(3)
    A, B, C, D = random_model(rng, 6, 2, 1, True)
    assert prepared(DiscreteStateSpace(A, B, C, D)).kernel() is None


def test_lti_continuous_model_has_kernel_only_once_bound():
    block = DiscreteStateSpace([[-1.0]], [[1.0]], [[1.0]], method="zoh")
    assert block.kernel() is None
    prepared(block, period=Fraction(1, 100))
    state = block.initial_state()
    u = np.array([0.3])
    x, rows = block.advance(0.0, state.copy(), {"u": u}, 9)
    cx, crows = c_advance(block, 0.0, state, {"u": u}, 9)
    assert same(crows, rows["y"]) and same(cx, x)


def test_gain_kernel_refused_for_long_matrix_rows():
    rng = np.random.default_rng(4)
    assert prepared(Gain(rng.normal(size=(3, 8)))).kernel() is None


def test_polymorphic_blocks_need_a_width():
    assert Sum("+-").kernel() is None
    assert Gain(2.0).kernel() is None
    assert ZeroOrderHold().kernel() is None


def test_kernel_is_built_once():
    block = prepared(DiscreteStateSpace([[0.9]], [[1.0]], [[1.0]]))
    assert block.kernel() is block.kernel()
