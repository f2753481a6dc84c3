"""The library's C kernels compute what independent numpy statements of their blocks do.

The blocks are defined once, by their kernels; ``oracles`` holds numpy code of the
simplest of them (their former Python methods). Each block's methods (which call its
kernel through ``blocks._native.call``) are compared with its oracle over several parameter
sets (scalars, width-3 vectors, random models up to 6 states and one of 130). Elementwise
arithmetic and the single-term products of 1x1 models match bit for bit
(``np.array_equal``, and the same bits for NaN and signed zeros); matrix products of
several terms match numpy's to round-off (library.c sums each row in order, BLAS in its
own): ``assert_allclose`` with rtol 1e-12 and atol 1e-14 times the size of the terms.
"""

import weakref
from fractions import Fraction

import numpy as np
import pytest

from blocks.engine.kernel import Kernel
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

from . import oracles

pytest.importorskip("blocks._native")

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


def output(block, t, state, inputs):
    """The block's output (its kernel's), all ports side by side."""
    out = block.output(t, None if state is None else state.copy(), inputs)
    return np.concatenate([np.atleast_1d(out[p]) for p in block.outputs])


def update(block, t, state, inputs):
    return block.update(t, state.copy(), inputs)


def advance(block, t, state, inputs, n):
    state, rows = block.advance(t, None if state is None else state.copy(), inputs, n)
    return state, rows["y"]


def magnitude(M, v):
    """The size of the terms of M . v: the largest row of |M| . |v|."""
    return float((np.abs(np.atleast_2d(M)) @ np.abs(v)).max())


def assert_close(got, expected, scale):
    """Equal to round-off: a product of several terms summed in another order."""
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-14 * scale)


def assert_outputs_equal(block, oracle, inputs, times=(0.0,)):
    for t in times:
        got, expected = output(block, t, None, inputs), oracle(t)
        assert same(got, expected), (t, got, expected)


# -- sources -------------------------------------------------------------------------


@pytest.mark.parametrize("value", [2.5, [1.0, -2.0, 3.5], [0.1]])
def test_constant(value):
    block = prepared(Constant(value))
    assert_outputs_equal(block, lambda t: oracles.constant(block, t), {}, TIMES)


@pytest.mark.parametrize("params", [
    dict(time=0.5),
    dict(time=0.5, before=[1.0, 2.0, 3.0], after=-1.5),
    dict(time=-0.3, before=0.1, after=[4.0, 5.0, 6.0]),
])
def test_step(params):
    block = prepared(Step(**params))
    assert_outputs_equal(block, lambda t: oracles.step(block, t), {}, TIMES)


@pytest.mark.parametrize("params", [
    dict(),
    dict(slope=0.3, start=0.5, initial=1.0),
    dict(slope=[0.1, -0.7, 1e3], start=0.25, initial=[1.0, 2.0, 3.0]),
    dict(slope=[1.0 / 3.0, 2.0, 3.0], start=-1.0, initial=0.7),
])
def test_ramp(params):
    block = prepared(Ramp(**params))
    assert_outputs_equal(block, lambda t: oracles.ramp(block, t), {}, TIMES)


@pytest.mark.parametrize("block, parameters", [
    (Constant([1.5, -2.0]), {"value[1]": 1.5, "value[2]": -2.0}),
    (Step(0.25, before=[1.0, 2.0], after=[3.0, 4.0]),
     {"time": 0.25, "before[1]": 1.0, "before[2]": 2.0, "after[1]": 3.0, "after[2]": 4.0}),
    (Gain([[1.0, 2.0], [3.0, 4.0]]), {"k[1,1]": 1.0, "k[1,2]": 2.0, "k[2,1]": 3.0, "k[2,2]": 4.0}),
])
def test_tunables_name_the_slots_of_their_parameters(block, parameters):
    """An exported FMU's parameters are slots of the kernels' records: each names the
    number its parameter holds."""
    record = kernel_of(prepared(block)).record
    assert {tunable.name: record.values[tunable.slot] for tunable in record.tunables} == parameters


# -- arithmetic ----------------------------------------------------------------------

RNG_SEEDS = (0, 1, 2)


@pytest.mark.parametrize("seed", RNG_SEEDS)
@pytest.mark.parametrize("k, width", [(2.5, 1), (-0.3, 3), ([1.0, -2.0, 1.0 / 3.0], 3), ([0.7], 1)])
def test_gain_elementwise(k, width, seed):
    rng = np.random.default_rng(seed)
    block = prepared(Gain(k), width)
    for _ in range(20):
        u = rng.normal(size=block.inputs["u"]) * 10.0 ** rng.integers(-3, 4)
        assert_outputs_equal(block, lambda t: oracles.gain(block, u), {"u": u})


@pytest.mark.parametrize("seed", RNG_SEEDS)
@pytest.mark.parametrize("shape", [(2, 2), (3, 3), (2, 3), (3, 2), (1, 4), (3, 8), (2, 40)])
def test_gain_matrix(shape, seed):
    rng = np.random.default_rng(seed)
    k = rng.normal(size=shape)
    block = prepared(Gain(k))
    for _ in range(20):
        u = rng.normal(size=shape[1]) * 10.0 ** rng.integers(-3, 4)
        assert_close(output(block, 0.0, None, {"u": u}), oracles.gain(block, u), magnitude(k, u))


def test_gain_matrix_of_one_column_is_exact():
    block = prepared(Gain([[2.0]]))
    for u in (1.0 / 3.0, -0.0, 7e-300):
        u = np.array([u])
        assert_outputs_equal(block, lambda t: oracles.gain(block, u), {"u": u})


@pytest.mark.parametrize("signs", ["+", "-", "++", "+-", "-+", "--", "+++", "++-", "+--", "-+-", "---",
                                   "-++-+"])
@pytest.mark.parametrize("width", [1, 3])
def test_sum(signs, width):
    rng = np.random.default_rng(len(signs) * 10 + width)
    block = prepared(Sum(signs), width)
    for _ in range(20):
        inputs = {f"u{j}": rng.normal(size=width) * 10.0 ** rng.integers(-8, 8) for j in range(len(signs))}
        assert_outputs_equal(block, lambda t: oracles.signed_sum(block, inputs), inputs)
    zeros = {f"u{j}": np.array([0.0, -0.0, 0.0][:width]) * (-1) ** j for j in range(len(signs))}
    assert_outputs_equal(block, lambda t: oracles.signed_sum(block, zeros), zeros)  # the signs of zero


@pytest.mark.parametrize("lower, upper, width", [
    (-1.0, 1.0, 1),
    (-1.0, 1.0, 3),
    ([-1.0, 0.0, -np.inf], [1.0, 0.5, 2.0], 3),
    (-0.5, [0.0, np.inf, 3.0], 3),
])
def test_saturation(lower, upper, width):
    rng = np.random.default_rng(width)
    block = prepared(Saturation(lower, upper), width)
    for u in [rng.normal(size=width) * 3.0 for _ in range(20)] + [np.full(width, np.nan), np.full(width, np.inf)]:
        assert_outputs_equal(block, lambda t: oracles.saturation(block, u), {"u": u})


# -- discrete ------------------------------------------------------------------------


@pytest.mark.parametrize("initial, width", [(0.0, 1), (2.0, 3), ([1.0, -2.0, 3.0], 3)])
def test_unit_delay(initial, width):
    rng = np.random.default_rng(width)
    block = prepared(UnitDelay(initial=initial), width)
    state = block.initial_state()
    for _ in range(5):
        u = rng.normal(size=width)
        assert same(output(block, 0.0, state, {"u": u}), state)
        expected = oracles.unit_delay_update(block, state, u)
        assert same(update(block, 0.0, state, {"u": u}), expected)
        state = expected
    for n in (0, 1, 7, 100):
        u = rng.normal(size=width)
        x, rows = oracles.unit_delay_advance(block, state.copy(), u, n)
        cx, crows = advance(block, 0.0, state, {"u": u}, n)
        assert same(cx, x) and same(crows, rows)


@pytest.mark.parametrize("width", [1, 3])
def test_zero_order_hold(width):
    rng = np.random.default_rng(width)
    block = prepared(ZeroOrderHold(), width)
    for _ in range(5):
        u = rng.normal(size=width)
        assert same(output(block, 0.0, None, {"u": u}), u)


# -- linear time-invariant -----------------------------------------------------------
def random_model(rng, n, m, p, with_d):
    A = rng.normal(size=(n, n))
    A *= 0.95 / max(abs(np.linalg.eigvals(A)))
    B = rng.normal(size=(n, m))
    C = rng.normal(size=(p, n))
    D = rng.normal(size=(p, m)) if with_d else None
    return A, B, C, D


LTI_SHAPES = [(1, 1, 1), (2, 1, 1), (2, 2, 2), (3, 1, 1), (3, 3, 3), (3, 2, 4), (2, 3, 1), (4, 3, 2), (6, 2, 1)]


def lti_blocks():
    rng = np.random.default_rng(7)
    blocks = [
        DiscreteStateSpace([[0.999]], [[1.0e-4]], [[1.0]], [[0.0]]),  # the toy diagram's plant
        DiscreteStateSpace([[1.0]], [[0.02]], [[1.0]], [[0.0]]),  # and its integrator
        DiscreteStateSpace([[0.5]], [[0.3]], [[2.0]], [[0.7]], x0=[1.5]),
        DiscreteStateSpace([[-0.9]], [[1.0 / 3.0]], [[-1.7]], x0=[0.0]),
        DiscreteTransferFunction([1.0, 0.5], [1.0, -1.2, 0.36]),
        DiscreteTransferFunction([0.2, 0.1, 0.3], [1.0, -0.5, 0.06], x0=[0.3, -0.2]),
        DiscreteTransferFunction([2.0], [4.0]),  # a pure gain, no state
        DiscreteTransferFunction([3.0], [1.0, -0.25]),  # one state
        DiscreteStateSpace([[0.5]], [[1.0, 2.0]], [[1.0]], [[0.0, 0.5]]),  # one state, two inputs
    ]
    for n, m, p in LTI_SHAPES:
        for with_d in (False, True):
            A, B, C, D = random_model(rng, n, m, p, with_d)
            blocks.append(DiscreteStateSpace(A, B, C, D, x0=rng.normal(size=n)))
    return blocks


LTI_BLOCKS = lti_blocks()


def exact(block) -> bool:
    """Whether the block's products all have a single term: a 1x1x1 model (whose
    two-term sums the oracle writes out as the kernel does) or a 1x1 pure gain."""
    return (block.A.shape[0], block.B.shape[1], block.C.shape[0]) in ((1, 1, 1), (0, 1, 1))


_CHUNK_MAPS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
"""Each block's maps of CHUNK hits, made once: a large model's take a fifth of a second."""


def lti_scale(block, state, u):
    """The size of the terms of the block's products on z = [state; u]."""
    if state is None:
        return magnitude(block.D, u)
    z = np.concatenate((state, u))
    if block not in _CHUNK_MAPS:
        _CHUNK_MAPS[block] = oracles.lti_chunk(block, CHUNK)
    ymap, xmap = _CHUNK_MAPS[block]
    return max(magnitude(np.hstack((block.C, block.D)), z), magnitude(np.hstack((block.A, block.B)), z),
               magnitude(ymap, z), magnitude(xmap, z))


def assert_lti_equal(block, got, expected, state, u):
    if exact(block):
        assert same(got, expected), (got, expected)
    else:
        assert_close(got, expected, lti_scale(block, state, u))


def test_exact_cases():
    assert [exact(prepared(b)) for b in LTI_BLOCKS[:8]] == [True, True, True, True, False, False, True, True]


@pytest.mark.parametrize("index", range(len(LTI_BLOCKS)))
def test_lti_output_and_update(index):
    block = prepared(LTI_BLOCKS[index])
    rng = np.random.default_rng(index)
    state = block.initial_state()
    for _ in range(30):
        u = rng.normal(size=block.inputs["u"])
        assert_lti_equal(block, output(block, 0.0, state, {"u": u}), oracles.lti_output(block, state, u),
                         state, u)
        if state is not None:
            expected = oracles.lti_update(block, state, u)
            assert_lti_equal(block, update(block, 0.0, state, {"u": u}), expected, state, u)
            state = expected


def check_advance(block, state, u, n):
    """The oracle and the kernel advance by n from state, then by 7 more from where each
    left off."""
    x, rows = oracles.lti_advance(block, None if state is None else state.copy(), u, n)
    cx, crows = advance(block, 0.0, state, {"u": u}, n)
    assert_lti_equal(block, crows, rows, state, u)
    if state is not None:
        assert_lti_equal(block, cx, x, state, u)
    # and again from where that left off: the kernel keeps no memory between calls
    if state is not None and n:
        x2, rows2 = oracles.lti_advance(block, x.copy(), u, 7)
        cx2, crows2 = advance(block, 0.0, cx, {"u": u}, 7)
        assert_lti_equal(block, crows2, rows2, x, u)
        assert_lti_equal(block, cx2, x2, x, u)


@pytest.mark.parametrize("n", [0, 1, 7, CHUNK, CHUNK + 1, 3 * CHUNK + 5])
@pytest.mark.parametrize("index", range(len(LTI_BLOCKS)))
def test_lti_advance(index, n):
    block = prepared(LTI_BLOCKS[index])
    rng = np.random.default_rng(1000 + index)
    state = block.initial_state()
    if state is not None:
        state = state + rng.normal(size=state.size)
    check_advance(block, state, rng.normal(size=block.inputs["u"]), n)


def test_lti_advance_of_the_toy_plant_is_exact_from_many_states():
    block = prepared(DiscreteStateSpace([[0.999]], [[1.0e-4]], [[1.0]], [[0.0]]), period=Fraction(1, 10000))
    rng = np.random.default_rng(11)
    for _ in range(50):
        check_advance(block, rng.normal(size=1) * 10.0 ** rng.integers(-3, 4), rng.normal(size=1),
                      int(rng.integers(0, 200)))
    check_advance(block, np.array([-0.0]), np.array([-0.0]), 3)  # and the sign of zero


@pytest.mark.parametrize("index", range(len(LTI_BLOCKS)))
def test_lti_all_chunks_are_the_chunk_maps(index):
    """The maps the kernel's context holds are the oracle's, to the bit."""
    block = prepared(LTI_BLOCKS[index])
    if block.initial_state() is None:
        return
    ymap, xmaps = block._all_chunks()
    for c in range(1, CHUNK + 1):
        y, x = oracles.lti_chunk(block, c)
        assert same(ymap[:c * block.outputs["y"]], y) and same(xmaps[c - 1], x)


def test_lti_kernel_for_a_large_model():
    """130 states: the kernels' vectors outgrow their stack buffers (library.c's LTI_STACK)."""
    rng = np.random.default_rng(3)
    A, B, C, D = random_model(rng, 130, 2, 3, True)
    block = prepared(DiscreteStateSpace(A, B, C, D, x0=rng.normal(size=130)))
    state, u = block.initial_state(), rng.normal(size=2)
    assert_lti_equal(block, output(block, 0.0, state, {"u": u}), oracles.lti_output(block, state, u), state, u)
    assert_lti_equal(block, update(block, 0.0, state, {"u": u}), oracles.lti_update(block, state, u), state, u)
    check_advance(block, state, u, CHUNK + 3)


def test_lti_continuous_model_has_kernel_only_once_bound():
    block = DiscreteStateSpace([[-1.0]], [[1.0]], [[1.0]], method="zoh")
    assert block.kernel() is None
    prepared(block, period=Fraction(1, 100))
    state = block.initial_state()
    u = np.array([0.3])
    x, rows = oracles.lti_advance(block, state.copy(), u, 9)
    cx, crows = advance(block, 0.0, state, {"u": u}, 9)
    assert same(crows, rows) and same(cx, x)


def test_polymorphic_blocks_need_a_width():
    assert Sum("+-").kernel() is None
    assert Gain(2.0).kernel() is None
    assert ZeroOrderHold().kernel() is None


def test_kernel_is_built_once():
    block = prepared(DiscreteStateSpace([[0.9]], [[1.0]], [[1.0]]))
    assert block.kernel() is block.kernel()


def test_a_parameter_changed_between_runs_reaches_the_kernel():
    """Kernels are cached on their block by the values they copy: a gain changed on the
    block between runs is used by the next run."""
    import blocks

    text = """
time: {t_end: 2 ms}
blocks:
  c: {type: Constant, period: 1 ms, params: {value: 2.0}}
  g: {type: Gain, params: {k: 3.0}}
connections: [c.y -> g.u]
log: [g.y]
"""
    d = blocks.loads_diagram(text, filename="k.yaml")
    assert blocks.simulate(d)["g.y"][1][-1, 0] == 6.0
    d.blocks["g"].block.k[...] = 5.0
    d.blocks["c"].block.value[...] = 1.5
    assert blocks.simulate(d)["g.y"][1][-1, 0] == 7.5
