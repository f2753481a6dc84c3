"""Behaviour of DiscreteStateSpace and DiscreteTransferFunction.

Checks the state equations, feedthrough detection, shape validation, zoh/tustin
discretisation against closed forms, and the ``advance`` closed form against the
reference loop of ``Block.advance``.
"""

import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from blocks.block import Block, BlockError
from blocks.library import DiscreteStateSpace, DiscreteTransferFunction
from blocks.library.lti import CHUNK


def random_stable(rng, n, m, p, with_d):
    """A random discrete system with spectral radius 0.9."""
    A = rng.normal(size=(n, n))
    A *= 0.9 / max(abs(np.linalg.eigvals(A)))
    B = rng.normal(size=(n, m))
    C = rng.normal(size=(p, n))
    D = rng.normal(size=(p, m)) if with_d else None
    return A, B, C, D


def simulate(block, inputs, state=None):
    """Run output then update at each hit; return the outputs as rows."""
    state = block.initial_state() if state is None else state
    rows = []
    for k, u in enumerate(inputs):
        u = np.atleast_1d(np.asarray(u, dtype=float))
        rows.append(block.output(float(k), state, {"u": u})["y"])
        if state is not None:
            state = block.update(float(k), state, {"u": u})
    return np.array(rows)


def assert_close_relative(actual, expected, rtol=1e-12):
    scale = max(1.0, float(np.max(np.abs(expected)))) if np.size(expected) else 1.0
    np.testing.assert_allclose(actual, expected, rtol=rtol, atol=rtol * scale)


class TestDiscreteStateSpace:
    def test_update_and_output_match_equations(self):
        rng = np.random.default_rng(1)
        A, B, C, D = random_stable(rng, 3, 2, 2, with_d=True)
        block = DiscreteStateSpace(A, B, C, D, x0=[1.0, -1.0, 0.5])
        assert block.inputs == {"u": 2} and block.outputs == {"y": 2}
        x = block.initial_state()
        np.testing.assert_array_equal(x, [1.0, -1.0, 0.5])
        for _ in range(5):
            u = rng.normal(size=2)
            y = block.output(0.0, x, {"u": u})["y"]
            np.testing.assert_allclose(y, C @ x + D @ u, rtol=1e-14, atol=1e-14)
            x_next = block.update(0.0, x.copy(), {"u": u})
            np.testing.assert_allclose(x_next, A @ x + B @ u, rtol=1e-14, atol=1e-14)
            x = x_next

    def test_scalar_system_matches_equations(self):
        block = DiscreteStateSpace(0.5, 2.0, 3.0, 0.25, x0=4.0)
        x = block.initial_state()
        u = np.array([1.0])
        assert block.output(0.0, x, {"u": u})["y"][0] == pytest.approx(3.0 * 4.0 + 0.25)
        assert block.update(0.0, x, {"u": u})[0] == pytest.approx(0.5 * 4.0 + 2.0)

    def test_feedthrough_follows_d(self):
        assert not DiscreteStateSpace(0.5, 1.0, 1.0).has_feedthrough()
        assert not DiscreteStateSpace(0.5, 1.0, 1.0, D=0.0).has_feedthrough()
        assert DiscreteStateSpace(0.5, 1.0, 1.0, D=0.1).has_feedthrough()
        assert DiscreteStateSpace(np.eye(2), np.eye(2), np.eye(2), [[0.0, 0.0], [0.0, 1e-9]]).feedthrough

    def test_outputs_and_states_are_fresh(self):
        """An output is an array of its own, which the update (of the state, in place, as
        every library block's) leaves alone; each initial state is a new array."""
        for block in (DiscreteStateSpace(0.5, 1.0, 1.0, x0=0.5),
                      DiscreteStateSpace(np.eye(2) * 0.5, np.ones((2, 1)), np.eye(2), x0=[1.0, 2.0]),
                      DiscreteStateSpace(np.eye(2) * 0.5, np.ones((2, 1)), np.eye(2), np.ones((2, 1)))):
            x = block.initial_state()
            u = np.array([1.0])
            y = block.output(0.0, x, {"u": u})["y"]
            y_before = y.copy()
            x_next = block.update(0.0, x, {"u": u})
            assert not np.shares_memory(y, x_next)
            np.testing.assert_array_equal(y, y_before)
            assert not np.shares_memory(block.initial_state(), block.initial_state())
            assert y.dtype == np.float64 and y.ndim == 1

    def test_column_b_may_be_given_as_list(self):
        block = DiscreteStateSpace([[0.5, 0.0], [0.0, 0.5]], [1.0, 2.0], [[1.0, 1.0]])
        assert block.inputs == {"u": 1}
        np.testing.assert_array_equal(block.B, [[1.0], [2.0]])

    @pytest.mark.parametrize(
        "kwargs, name",
        [
            (dict(A=[[1.0, 0.0]], B=1.0, C=1.0), "'A'"),
            (dict(A=np.eye(2), B=np.ones((3, 1)), C=np.ones((1, 2))), "'B'"),
            (dict(A=np.eye(2), B=np.ones((2, 1)), C=np.ones((1, 3))), "'C'"),
            (dict(A=np.eye(2), B=np.ones((2, 1)), C=np.ones((1, 2)), D=np.ones((2, 1))), "'D'"),
            (dict(A=np.eye(2), B=np.ones((2, 1)), C=np.ones((1, 2)), x0=[1.0]), "'x0'"),
            (dict(A=[[np.nan]], B=1.0, C=1.0), "'A'"),
            (dict(A=1.0, B=1.0, C=1.0, method="euler"), "'method'"),
        ],
    )
    def test_bad_parameters_raise_naming_them(self, kwargs, name):
        with pytest.raises(ValueError, match=name):
            DiscreteStateSpace(**kwargs)

    def test_shape_error_names_expected_shape(self):
        with pytest.raises(ValueError, match=r"\(2, m\)"):
            DiscreteStateSpace(np.eye(2), np.ones((3, 1)), np.ones((1, 2)))

    def test_discrete_model_needs_no_period(self):
        block = DiscreteStateSpace(0.5, 1.0, 1.0)
        block.bind(None)
        assert block.output(0.0, block.initial_state(), {"u": np.ones(1)})["y"][0] == 0.0


class TestAdvance:
    @pytest.mark.parametrize("n", [1, 2, 10, CHUNK, CHUNK + 1, 3 * CHUNK + 7, 500])
    @pytest.mark.parametrize("shape", [(1, 1, 1), (3, 2, 2), (4, 1, 3)])
    @pytest.mark.parametrize("with_d", [False, True])
    def test_matches_reference_loop(self, n, shape, with_d):
        rng = np.random.default_rng(n * 7 + sum(shape))
        A, B, C, D = random_stable(rng, *shape, with_d=with_d)
        block = DiscreteStateSpace(A, B, C, D, x0=rng.normal(size=shape[0]))
        block.bind(Fraction(1, 1000))
        inputs = {"u": rng.normal(size=shape[1])}
        x0 = block.initial_state()
        state, out = block.advance(0.25, x0.copy(), inputs, n)
        ref_state, ref_out = Block.advance(block, 0.25, x0.copy(), inputs, n)
        assert out["y"].shape == (n, shape[2])
        assert_close_relative(out["y"], ref_out["y"])
        assert_close_relative(state, ref_state)

    def test_repeated_calls_use_cache_consistently(self):
        block = DiscreteStateSpace(0.8, 0.5, 2.0)
        inputs = {"u": np.array([1.0])}
        state = block.initial_state()
        ys = []
        for n in (3, 64, 3, 130):
            state, out = block.advance(0.0, state, inputs, n)
            ys.append(out["y"])
        ref_state, ref_out = Block.advance(block, 0.0, block.initial_state(), inputs, 200)
        assert_close_relative(np.vstack(ys), ref_out["y"])
        assert_close_relative(state, ref_state)

    def test_zero_steps_keep_state(self):
        block = DiscreteStateSpace(0.8, 0.5, [[1.0], [2.0]], x0=3.0)
        state, out = block.advance(0.0, block.initial_state(), {"u": np.ones(1)}, 0)
        np.testing.assert_array_equal(state, [3.0])
        assert out["y"].shape == (0, 2)

    def test_has_fast_advance(self):
        assert DiscreteStateSpace(0.5, 1.0, 1.0).has_fast_advance()

    @given(st.integers(1, 4), st.integers(1, 3), st.integers(1, 3), st.integers(1, 300),
           st.integers(0, 2**32 - 1))
    @settings(max_examples=40)
    def test_matches_reference_loop_property(self, n_states, m, p, steps, seed):
        rng = np.random.default_rng(seed)
        A, B, C, _ = random_stable(rng, n_states, m, p, with_d=False)
        block = DiscreteStateSpace(A, B, C, x0=rng.normal(size=n_states))
        inputs = {"u": rng.normal(size=m)}
        state, out = block.advance(0.0, block.initial_state(), inputs, steps)
        ref_state, ref_out = Block.advance(block, 0.0, block.initial_state(), inputs, steps)
        assert_close_relative(out["y"], ref_out["y"])
        assert_close_relative(state, ref_state)


class TestDiscretisation:
    @pytest.mark.parametrize("a, period", [(2.0, Fraction(1, 10)), (0.5, Fraction(1, 3)), (10.0, Fraction(1, 1000))])
    def test_zoh_first_order_matches_exponential(self, a, period):
        T = float(period)
        block = DiscreteStateSpace(-a, 1.0, 1.0, method="zoh")
        block.bind(period)
        assert block.A[0, 0] == pytest.approx(math.exp(-a * T), rel=1e-12)
        assert block.B[0, 0] == pytest.approx((1.0 - math.exp(-a * T)) / a, rel=1e-10)
        assert block.D[0, 0] == 0.0
        assert not block.has_feedthrough()

    def test_zoh_step_response_samples_continuous_one(self):
        a, T = 3.0, 0.05
        block = DiscreteTransferFunction([a], [1.0, a], method="zoh")
        block.bind(Fraction(1, 20))
        y = simulate(block, np.ones(40))[:, 0]
        k = np.arange(40)
        np.testing.assert_allclose(y, 1.0 - np.exp(-a * T * k), rtol=1e-10, atol=1e-12)

    def test_tustin_first_order_matches_bilinear_difference_equation(self):
        a, T = 2.0, 0.1
        block = DiscreteTransferFunction([a], [1.0, a], method="tustin")
        block.bind(Fraction(1, 10))
        assert block.has_feedthrough()
        rng = np.random.default_rng(3)
        u = rng.normal(size=30)
        y = simulate(block, u)[:, 0]
        # a/(s+a) with s = (2/T)(z-1)/(z+1):
        # (1 + aT/2) y[k] = (1 - aT/2) y[k-1] + (aT/2) (u[k] + u[k-1])
        expected, y_prev, u_prev = [], 0.0, 0.0
        for uk in u:
            y_prev = ((1 - a * T / 2) * y_prev + (a * T / 2) * (uk + u_prev)) / (1 + a * T / 2)
            u_prev = uk
            expected.append(y_prev)
        np.testing.assert_allclose(y, expected, rtol=1e-12, atol=1e-14)

    def test_tustin_pole_matches_closed_form(self):
        a, T = 4.0, 0.02
        block = DiscreteStateSpace(-a, 1.0, 1.0, method="tustin")
        block.bind(Fraction(1, 50))
        assert block.A[0, 0] == pytest.approx((1 - a * T / 2) / (1 + a * T / 2), rel=1e-13)
        # the feedthrough tustin creates: D_d = (T/2) C (1 + aT/2)^-1 B for this model
        assert block.D[0, 0] == pytest.approx((T / 2) / (1 + a * T / 2), rel=1e-12)

    def test_tustin_initial_state_gives_continuous_initial_output(self):
        A = np.array([[0.0, 1.0], [-4.0, -0.4]])
        C = np.array([[1.0, 0.5]])
        x0 = np.array([1.5, -0.5])
        block = DiscreteStateSpace(A, [[0.0], [1.0]], C, x0=x0, method="tustin")
        block.bind(Fraction(1, 100))
        y0 = block.output(0.0, block.initial_state(), {"u": np.zeros(1)})["y"]
        np.testing.assert_allclose(y0, C @ x0, rtol=1e-12)

    def test_zoh_keeps_initial_state(self):
        block = DiscreteStateSpace(-1.0, 1.0, 1.0, x0=2.0, method="zoh")
        block.bind(Fraction(1, 10))
        np.testing.assert_array_equal(block.initial_state(), [2.0])

    def test_continuous_model_needs_a_period(self):
        block = DiscreteStateSpace(-1.0, 1.0, 1.0, method="zoh")
        with pytest.raises(ValueError, match="period"):
            block.bind(None)

    def test_running_before_bind_raises(self):
        block = DiscreteStateSpace(-np.eye(2), np.ones((2, 1)), np.ones((1, 2)), method="zoh")
        with pytest.raises(BlockError, match="bind"):
            block.update(0.0, block.initial_state(), {"u": np.ones(1)})

    def test_rebinding_discretises_from_the_continuous_model(self):
        block = DiscreteStateSpace(-1.0, 1.0, 1.0, method="zoh")
        block.bind(Fraction(1, 10))
        block.advance(0.0, block.initial_state(), {"u": np.ones(1)}, 5)
        block.bind(Fraction(1, 2))
        assert block.A[0, 0] == pytest.approx(math.exp(-0.5), rel=1e-12)
        state, out = block.advance(0.0, block.initial_state(), {"u": np.ones(1)}, 5)
        ref_state, ref_out = Block.advance(block, 0.0, block.initial_state(), {"u": np.ones(1)}, 5)
        assert_close_relative(out["y"], ref_out["y"])


class TestDiscreteTransferFunction:
    def test_step_response_matches_difference_equation(self):
        num, den = [0.5, -0.2, 0.1], [1.0, -1.1, 0.3]
        block = DiscreteTransferFunction(num, den)
        assert block.inputs == {"u": 1} and block.outputs == {"y": 1}
        u = np.ones(25)
        y = simulate(block, u)[:, 0]
        # y[k] = 1.1 y[k-1] - 0.3 y[k-2] + 0.5 u[k] - 0.2 u[k-1] + 0.1 u[k-2]
        expected = np.zeros(25)
        for k in range(25):
            ym1 = expected[k - 1] if k >= 1 else 0.0
            ym2 = expected[k - 2] if k >= 2 else 0.0
            um1 = u[k - 1] if k >= 1 else 0.0
            um2 = u[k - 2] if k >= 2 else 0.0
            expected[k] = 1.1 * ym1 - 0.3 * ym2 + 0.5 * u[k] - 0.2 * um1 + 0.1 * um2
        np.testing.assert_allclose(y, expected, rtol=1e-12, atol=1e-14)
        assert y[-1] == pytest.approx(0.4 / 0.2, rel=1e-3)

    def test_strictly_proper_has_delay_and_no_feedthrough(self):
        block = DiscreteTransferFunction([1.0], [1.0, -0.5])
        assert not block.has_feedthrough()
        y = simulate(block, [1.0, 0.0, 0.0, 0.0])[:, 0]
        np.testing.assert_allclose(y, [0.0, 1.0, 0.5, 0.25])

    def test_biproper_has_feedthrough(self):
        assert DiscreteTransferFunction([2.0, 1.0], [1.0, -0.5]).has_feedthrough()

    def test_coefficients_are_normalised(self):
        a = simulate(DiscreteTransferFunction([0.0, 2.0, 1.0], [2.0, -1.0, 0.25]), np.ones(10))
        b = simulate(DiscreteTransferFunction([1.0, 0.5], [1.0, -0.5, 0.125]), np.ones(10))
        np.testing.assert_allclose(a, b, rtol=1e-14)

    def test_pure_gain_is_stateless(self):
        block = DiscreteTransferFunction([3.0], [2.0])
        assert block.initial_state() is None
        assert block.has_feedthrough()
        assert block.output(0.0, None, {"u": np.array([4.0])})["y"][0] == pytest.approx(6.0)

    def test_initial_state_of_realisation(self):
        block = DiscreteTransferFunction([1.0], [1.0, -0.5], x0=[2.0])
        y = simulate(block, np.zeros(3))[:, 0]
        np.testing.assert_allclose(y, [2.0, 1.0, 0.5])

    def test_advance_matches_reference_loop(self):
        block = DiscreteTransferFunction([0.1, 0.05], [1.0, -1.5, 0.7, -0.1])
        inputs = {"u": np.array([2.0])}
        state, out = block.advance(0.0, block.initial_state(), inputs, 150)
        ref_state, ref_out = Block.advance(block, 0.0, block.initial_state(), inputs, 150)
        assert_close_relative(out["y"], ref_out["y"])
        assert_close_relative(state, ref_state)

    @pytest.mark.parametrize(
        "num, den, name",
        [([1.0, 0.0, 1.0], [1.0, 1.0], "improper"), ([1.0], [0.0, 0.0], "den"),
         ([np.nan], [1.0, 1.0], "num"), ([1.0], [[1.0, 1.0]], "den")],
    )
    def test_bad_polynomials_raise(self, num, den, name):
        with pytest.raises(ValueError, match=name):
            DiscreteTransferFunction(num, den)

    def test_bad_method_and_x0_raise(self):
        with pytest.raises(ValueError, match="method"):
            DiscreteTransferFunction([1.0], [1.0, 1.0], method="foh")
        with pytest.raises(ValueError, match="x0"):
            DiscreteTransferFunction([1.0], [1.0, 1.0], x0=[0.0, 0.0])
