"""PID against python-control's discrete transfer functions, and its limits, anti-windup,
tracking and reset against the semantics Simulink's Discrete PID Controller documents.

Linear (no limits): every form, integrator rule, filter rule and the unfiltered derivative
give control.forced_response of C(z) = P + I a(z) + D N / (1 + N b(z)) (ideal: P times
[1 + I a + D N / (1 + N b)]) to 1e-9 of the output's size. With limits, the output is the
clipped linear output of the integral the anti-windup rule leaves.
"""

from __future__ import annotations

from fractions import Fraction

import control
import numpy as np
import pytest

import blocks
from blocks.library import PID

from .stepping import PERIOD, series, step

T = float(PERIOD)


def rule(method: str):
    """a(z) or b(z) of a method, as python-control transfer functions."""
    return {"forward": control.tf([T], [1, -1], T), "backward": control.tf([T, 0], [1, -1], T),
            "trapezoidal": control.tf([T / 2, T / 2], [1, -1], T)}[method]


def reference(P, I, D, N, form="parallel", integrator="forward", filter="forward", filtered=True):  # noqa: E741
    one = control.tf([1], [1], T)
    derivative = (D * N * control.feedback(one, N * rule(filter)) if filtered
                  else control.tf([D, -D], [T, 0], T))
    inner = I * rule(integrator) + derivative
    return P * (one + inner) if form == "ideal" else P * one + inner


def response(system, u):
    t = np.arange(len(u)) * T
    return control.forced_response(system, T=t, U=u).outputs


CASES = [dict(integrator=i, filter=f) for i in ("forward", "backward", "trapezoidal")
         for f in ("forward", "backward", "trapezoidal")]


@pytest.mark.parametrize("form", ["parallel", "ideal"])
@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c['integrator']}-{c['filter']}")
def test_linear_pid_is_the_transfer_function(form, case):
    u = series(400, seed=3)
    gains = dict(P=2.0, I=30.0, D=0.05, N=200.0)
    y = step(PID(**gains, form=form, **case), {"u": u})["y"][:, 0]
    expected = response(reference(**gains, form=form, **case), u)
    np.testing.assert_allclose(y, expected, rtol=0, atol=1e-9 * np.abs(expected).max())


@pytest.mark.parametrize("integrator", ["forward", "backward", "trapezoidal"])
def test_unfiltered_derivative_is_d_times_z_minus_1_over_t_z(integrator):
    u = series(300, seed=4)
    y = step(PID(P=0.5, I=4.0, D=0.02, filtered=False, integrator=integrator), {"u": u})["y"][:, 0]
    expected = response(reference(0.5, 4.0, 0.02, 1.0, integrator=integrator, filtered=False), u)
    np.testing.assert_allclose(y, expected, rtol=0, atol=1e-9 * np.abs(expected).max())


def test_vector_gains_are_one_controller_per_element():
    u = np.column_stack([series(200, seed=5), series(200, seed=6)])
    block = PID(P=[1.0, 3.0], I=[10.0, 0.0], D=[0.0, 0.01], N=100.0)
    y = step(block, {"u": u})["y"]
    for i, (P, I, D) in enumerate(((1.0, 10.0, 0.0), (3.0, 0.0, 0.01))):
        np.testing.assert_allclose(y[:, i], response(reference(P, I, D, 100.0), u[:, i]), atol=1e-9)


def test_initial_integrator_value_is_the_integral_terms_start():
    y = step(PID(P=0.0, I=1.0, initial_integrator=0.7), {"u": np.zeros(5)})["y"][:, 0]
    np.testing.assert_array_equal(y, 0.7)


def clipped(P, I, e, lower, upper, anti_windup, Kb=1.0):
    """A PI controller with the forward-Euler integral, written out: y = clip(P e + x),
    x' = x + T v, v = I e (0 while clamping holds), + Kb (y - unclipped) back-calculating."""
    x, out = 0.0, []
    for ek in e:
        unclipped = P * ek + x
        y = min(max(unclipped, lower), upper)
        v = I * ek
        if anti_windup == "clamping" and unclipped != y and (unclipped - y) * v > 0:
            v = 0.0
        if anti_windup == "back_calculation":
            v += Kb * (y - unclipped)
        x += T * v
        out.append(y)
    return np.array(out)


@pytest.mark.parametrize("anti_windup", ["none", "clamping", "back_calculation"])
def test_limits_and_anti_windup(anti_windup):
    e = np.concatenate((np.full(300, 2.0), np.full(300, -2.0)))
    y = step(PID(P=0.2, I=20.0, lower=-1.0, upper=1.0, anti_windup=anti_windup, Kb=5.0), {"u": e})["y"][:, 0]
    expected = clipped(0.2, 20.0, e, -1.0, 1.0, anti_windup, Kb=5.0)
    np.testing.assert_allclose(y, expected, rtol=0, atol=1e-12)
    assert y.max() <= 1.0 and y.min() >= -1.0


def test_anti_windup_lets_the_output_leave_the_limit_sooner():
    """After a long saturation, the error reverses: without anti-windup the wound-up
    integral holds the output at the upper limit for a while; with it, it leaves at once."""
    e = np.concatenate((np.full(500, 2.0), np.full(200, -0.5)))
    leave = {}
    for anti_windup in ("none", "clamping", "back_calculation"):
        # back-calculation settles where I e + Kb (1 - (P e + x)) = 0: x = 0.8, unlimited 1.2
        y = step(PID(P=0.2, I=20.0, lower=-1.0, upper=1.0, anti_windup=anti_windup, Kb=200.0), {"u": e})["y"][:, 0]
        below = np.flatnonzero(y[500:] < 1.0)
        leave[anti_windup] = int(below[0]) if below.size else None
    assert leave["clamping"] == 0 and leave["back_calculation"] == 0
    assert leave["none"] is None  # x wound up to about 20: it takes 1900 hits at -0.5 to come back


def test_clamping_freezes_the_integral_while_saturated_and_pushed_further():
    e = np.full(50, 10.0)
    block = PID(P=1.0, I=5.0, upper=1.0, anti_windup="clamping")
    step(block, {"u": e})
    state = block.initial_state()
    for k in range(50):
        state = block.update(k * T, state, {"u": np.array([10.0])})
    assert state[0] == 0.0  # the output is saturated by P e alone: nothing integrates


def test_tracking_pulls_the_output_to_the_track_signal():
    n = 2000
    y = step(PID(P=0.0, I=1.0, tracking=True, Kt=50.0), {"u": np.zeros(n), "track": np.full(n, 0.8)})["y"][:, 0]
    # the integral obeys x' = x + T Kt (0.8 - x): 0.8 (1 - (1 - T Kt)^k)
    expected = 0.8 * (1.0 - (1.0 - T * 50.0) ** np.arange(n))
    np.testing.assert_allclose(y, expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize("kind, reset, restarts", [
    ("rising", [0, 0, 1, 1, 0, 1], [2, 5]),
    ("falling", [1, 1, 0, 0, 1, 0], [2, 5]),
    ("either", [0, 1, 1, 0, 0, 0], [1, 3]),
    ("level", [0, 1, 1, 0, 0, 0], [1, 2]),
])
def test_reset_restarts_integrator_and_filter(kind, reset, restarts):
    n = len(reset)
    y = step(PID(P=0.0, I=1.0, initial_integrator=0.5, reset=kind), {"u": np.full(n, 1000.0), "reset": reset})
    x, expected = 0.5, []
    for k in range(n):
        if k in restarts:
            x = 0.5
        expected.append(x)
        x += T * 1000.0
    np.testing.assert_allclose(y["y"][:, 0], expected, atol=1e-12)


def test_ports_and_feedthrough_follow_the_configuration():
    assert PID().inputs == {"u": None} and PID().reads("y") == {"u"}
    pure_i = PID(P=0.0, I=2.0)
    assert pure_i.reads("y") == frozenset() and not pure_i.has_feedthrough()  # a loop may close through it
    assert PID(P=0.0, I=2.0, integrator="backward").reads("y") == {"u"}
    full = PID(tracking=True, reset="rising")
    assert full.inputs == {"u": None, "track": None, "reset": 1}
    assert full.reads("y") == {"u", "reset"}  # tracking acts on the next state only


@pytest.mark.parametrize("params, word", [
    (dict(form="series"), "'form'"), (dict(N=0.0), "'N'"), (dict(P="x"), "'P'"),
    (dict(integrator="euler"), "'integrator'"), (dict(anti_windup="yes"), "'anti_windup'"),
    (dict(lower=1.0, upper=-1.0), "'lower'"), (dict(P=[1.0, 2.0], I=[1.0, 2.0, 3.0]), "one width"),
    (dict(filtered="no"), "'filtered'"), (dict(reset="up"), "'reset'"),
])
def test_bad_parameters_are_named(params, word):
    with pytest.raises(ValueError, match=word):
        PID(**params)


def test_period_and_filter_stability_are_checked_at_the_period():
    with pytest.raises(ValueError, match="needs a period"):
        PID().bind(None)
    with pytest.raises(ValueError, match="unstable"):
        PID(D=1.0, N=3000.0).bind(Fraction(1, 1000))
    PID(D=1.0, N=3000.0, filter="backward").bind(Fraction(1, 1000))


LOOP = """
name: pid-loop
time: {t_end: 3 s}
blocks:
  ref:   {type: Step, period: 1 ms, params: {time: 0.1, after: 1.0}}
  err:   {type: Sum, params: {signs: "+-"}}
  pid:   {type: PID, period: 1 ms, params: {P: 2.0, I: 20.0, D: 0.01, N: 100, lower: -2, upper: 2,
                                            anti_windup: back_calculation, Kb: 2.0}}
  plant: {type: DiscreteTransferFunction, period: 1 ms, params: {num: [1.0], den: [0.1, 1.0], method: zoh}}
connections:
  - ref.y -> err.u0
  - {from: plant.y, to: err.u1, delay: 1}
  - err.y -> pid.u
  - pid.y -> plant.u
log: [plant.y, pid.y]
"""


def test_a_closed_loop_settles_and_runs_the_same_compiled_and_in_python(monkeypatch):
    diagram = blocks.loads_diagram(LOOP)
    compiled = blocks.simulate(diagram)
    with monkeypatch.context() as m:
        m.setattr(blocks.engine.compiled, "usable_kernel", lambda *args: None)
        python = blocks.simulate(diagram)
    for name in ("plant.y", "pid.y"):
        np.testing.assert_array_equal(compiled[name][1], python[name][1])
    y = compiled["plant.y"][1][:, 0]
    assert abs(y[-1] - 1.0) < 1e-3 and compiled["pid.y"][1].max() <= 2.0
