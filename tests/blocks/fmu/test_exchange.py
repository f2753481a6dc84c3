"""Model-exchange FMUs as blocks, on test models compiled at test time (``sources/me_model.h``).

Each model is an FMI 2 and an FMI 3 FMU: ``linear.c``, a damped oscillator driven by its
input (closed form: the zero-order-hold discretisation of the linear system);
``bouncing.c``, a bouncing ball (a state event per bounce; closed form: the bounce times of
the parabolas); ``stair.c``, a staircase of time events with a step event and a second
pass of event iteration (closed form: the integral of the staircase). The block's results
are compared with the closed forms and with ``fmpy.simulate_fmu(fmi_type='ModelExchange')``
at the same output points, for both solvers.
"""

from __future__ import annotations

import re
import zipfile

import numpy as np
import pytest
import scipy.linalg

from blocks import DiagramError, loads_diagram, simulate

fmpy = pytest.importorskip("fmpy")

from .build import ME_MODELS, build_error, me_fmu, typed_fmu, zip_files  # noqa: E402

G, E, H0 = 9.81, 0.8, 1.0  # the bouncing ball's defaults
STEP_INPUT = "{type: Step, period: 0.1 s, params: {time: 0.3, before: 1.0, after: 2.0}}"
FMPY_STEP_INPUT = np.array([(0.0, 1.0), (0.3, 1.0), (0.3, 2.0), (10.0, 2.0)], dtype=[("time", float), ("u", float)])


@pytest.fixture(scope="module")
def me(tmp_path_factory) -> dict:
    why = build_error()
    if why:
        pytest.skip(why)
    build = tmp_path_factory.mktemp("me_fmus")
    fmus = {(model, fmi): me_fmu(build, model, fmi) for model in ME_MODELS for fmi in (2, 3)}
    fmus["build"] = build
    return fmus


def diagram(path, params: str = "", period: str = "0.1 s", t_end: str = "2 s", source: str | None = None,
            filename: str = "me.yaml"):
    wired = f"  src: {source}\nconnections: [src.y -> f.u]\n" if source else ""
    return loads_diagram(f"""
time: {{t_end: {t_end}}}
blocks:
  f: {{type: FMU, period: {period}, params: {{path: '{path}'{', ' + params if params else ''}}}}}
{wired}log: all
""", filename=filename)


def run(path, params: str = "", **kwargs):
    results = simulate(diagram(path, params, **kwargs))
    assert results.complete, results.status
    return results


def ours(results, port: str) -> np.ndarray:
    return results[f"f.{port}"][1][:, 0]


def oscillator(t: np.ndarray, u: np.ndarray, k: float = 4.0, c: float = 0.4, x0=(1.0, 0.0)) -> np.ndarray:
    """x' = v, v' = -k x - c v + u with u held over each interval: exact (matrix exponential)."""
    a, b = np.array([[0.0, 1.0], [-k, -c]]), np.array([0.0, 1.0])
    x, rows = np.array(x0, dtype=float), [np.array(x0, dtype=float)]
    for i in range(len(t) - 1):
        ad = scipy.linalg.expm(a * (t[i + 1] - t[i]))
        x = ad @ x + np.linalg.solve(a, (ad - np.eye(2)) @ b) * u[i]
        rows.append(x)
    return np.array(rows)


def ball(t: np.ndarray, e: float = E) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The bouncing ball's height, number of bounces and time of the last bounce at ``t``."""
    times, speeds = [np.sqrt(2 * H0 / G)], [e * np.sqrt(2 * H0 * G)]
    while times[-1] < t.max():
        times.append(times[-1] + 2 * speeds[-1] / G)
        speeds.append(e * speeds[-1])
    count = np.searchsorted(times, t, side="right")
    since = t - np.where(count > 0, np.take(times, count - 1), 0.0)
    height = np.where(count > 0, np.take(speeds, count - 1) * since - G * since**2 / 2, H0 - G * t**2 / 2)
    return height, count, np.where(count > 0, np.take(times, count - 1), 0.0)


def staircase(t: np.ndarray, period: float) -> np.ndarray:
    """The integral of the staircase that steps up by one at period, 2 period, ..."""
    steps = np.floor(t / period + 1e-9)
    return steps * t - period * steps * (steps + 1) / 2


def reference(path, **kwargs) -> np.ndarray:
    """fmpy's model-exchange simulation at the output points 0, 0.1, ... (no event rows)."""
    return fmpy.simulate_fmu(str(path), fmi_type="ModelExchange", output_interval=0.1, record_events=False,
                             **{"stop_time": 2.0, **kwargs})


# -- against the closed forms and fmpy -------------------------------------------------------


@pytest.mark.parametrize("fmi", [2, 3])
def test_a_linear_system_matches_its_closed_form_and_fmpy_with_cvode(me, fmi):
    path = me["linear", fmi]
    r = run(path, "tolerance: 1e-8", source=STEP_INPUT)
    t = r["f.x"][0]
    np.testing.assert_allclose(t, np.arange(21) / 10)
    exact = oscillator(t, np.where(t < 0.3 - 1e-9, 1.0, 2.0))   # the input held over each hit's interval
    assert np.abs(ours(r, "x") - exact[:, 0]).max() < 5e-7
    assert np.abs(ours(r, "v") - exact[:, 1]).max() < 5e-7
    theirs = reference(path, relative_tolerance=1e-8, input=FMPY_STEP_INPUT)
    assert np.abs(ours(r, "x") - theirs["x"]).max() < 1e-8
    tighter = run(path, "tolerance: 1e-10", source=STEP_INPUT)
    assert np.abs(ours(tighter, "x") - exact[:, 0]).max() < 5e-9
    ramp = run(path, "tolerance: 1e-9", source="{type: Ramp, period: 0.1 s, params: {slope: 1.0}}")
    held = ramp["src.y"][1][:, 0]                                # a new input at every hit: an event at each
    assert np.abs(ours(ramp, "x") - oscillator(t, held)[:, 0]).max() < 2e-7


@pytest.mark.parametrize("fmi", [2, 3])
def test_euler_is_the_euler_recursion_and_fmpys_euler(me, fmi):
    path = me["linear", fmi]
    r = run(path, "solver: euler, substep: 25 ms", source=STEP_INPUT)
    a, b = np.array([[0.0, 1.0], [-4.0, -0.4]]), np.array([0.0, 1.0])
    x, rows = np.array([1.0, 0.0]), [np.array([1.0, 0.0])]
    for k in range(80):  # 2 s of 25 ms sub-steps, the input held over each 0.1 s hit
        x = x + 0.025 * (a @ x + b * (1.0 if k < 12 else 2.0))
        if k % 4 == 3:
            rows.append(x)
    np.testing.assert_allclose(ours(r, "x"), np.array(rows)[:, 0], rtol=1e-12, atol=1e-14)
    one_step = run(path, "solver: euler, substep: 0.1 s", source=STEP_INPUT)
    theirs = reference(path, solver="Euler", step_size=0.1, input=FMPY_STEP_INPUT)
    np.testing.assert_allclose(ours(one_step, "x"), theirs["x"], rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("fmi", [2, 3])
def test_a_bouncing_ball_bounces_where_the_closed_form_does(me, fmi):
    """The state events (h = 0) are located by CVode's root finding: the bounce times to
    the solver's tolerance, the number of bounces exactly."""
    path = me["bouncing", fmi]
    r = run(path, "tolerance: 1e-8")
    t = r["f.h"][0]
    height, count, last = ball(t)
    assert np.array_equal(ours(r, "bounces"), count) and count[-1] == 3
    assert np.abs(ours(r, "t_bounce") - last).max() < 1e-7
    assert np.abs(ours(r, "h") - height).max() < 2e-7
    theirs = reference(path, relative_tolerance=1e-8)
    assert np.array_equal(ours(r, "bounces"), theirs["bounces"])
    assert np.abs(ours(r, "t_bounce") - theirs["t_bounce"]).max() < 1e-7
    assert np.abs(ours(r, "h") - theirs["h"]).max() < 2e-7


@pytest.mark.parametrize("fmi", [2, 3])
def test_euler_locates_a_state_event_on_its_step_to_the_tolerance(me, fmi):
    """Euler's first bounce is where its straight step from above the floor to below crosses
    it, to tolerance times the sub-step; halving the sub-step halves the error (first order)."""
    path = me["bouncing", fmi]
    r = run(path, "solver: euler, substep: 5 ms, tolerance: 1e-6", t_end="0.6 s")
    h, v, k = H0, 0.0, 0
    while h + 0.005 * v > 0:
        h, v, k = h + 0.005 * v, v - G * 0.005, k + 1
    crossing = 0.005 * (k + h / (h - (h + 0.005 * v)))
    assert ours(r, "bounces")[-1] == 1
    assert abs(ours(r, "t_bounce")[-1] - crossing) <= 1e-6 * 0.005 + 1e-15
    errors = []
    for substep in ("10 ms", "5 ms", "2.5 ms"):
        res = run(path, f"solver: euler, substep: {substep}")
        errors.append(np.abs(ours(res, "h") - ball(res["f.h"][0])[0]).max())
    assert 1.8 < errors[1] / errors[2] < 2.2


@pytest.mark.parametrize("fmi", [2, 3])
@pytest.mark.parametrize("solver", ["cvode", "euler"])
def test_time_events_are_hit_exactly_and_iterated(me, fmi, solver):
    """The staircase steps at T = 0.23 s, off the hit and sub-step grids: x is exact to
    round-off with either solver, count steps at every time event, and level (set in each
    event's second pass of the discrete update) follows it."""
    path = me["stair", fmi]
    r = run(path, f"solver: {solver}, start_values: {{T: 0.23}}")
    t = r["f.x"][0]
    np.testing.assert_allclose(ours(r, "x"), staircase(t, 0.23), rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(ours(r, "count"), np.floor(t / 0.23 + 1e-9))
    np.testing.assert_array_equal(ours(r, "level"), ours(r, "count"))


@pytest.mark.parametrize("fmi", [2, 3])
def test_step_events_come_at_the_end_of_the_step_that_asked_as_in_fmpy(me, fmi):
    """x crosses limit 0.5 at 0.625 s; completedIntegratorStep asks for an event at the end
    of the step where it sees x >= limit: CVode's step to the hit at 0.7 s, Euler's
    sub-step to 0.63 s. fmpy gives the same, with CVode and with Euler's 10 ms steps."""
    path = me["stair", fmi]
    cvode = run(path)
    theirs = reference(path)
    np.testing.assert_allclose(ours(cvode, "x"), theirs["x"], rtol=1e-12, atol=1e-12)
    for port in ("count", "level", "above", "t_above"):
        np.testing.assert_allclose(ours(cvode, port), theirs[port].astype(float), rtol=1e-12, atol=1e-12)
    assert ours(cvode, "t_above")[-1] == pytest.approx(0.7)
    euler = run(path, "solver: euler")  # the sub-step: the DefaultExperiment's 10 ms
    theirs = fmpy.simulate_fmu(str(path), fmi_type="ModelExchange", solver="Euler", step_size=0.01,
                               output_interval=0.01, record_events=False, stop_time=2.0)[::10]
    for port in ("x", "count", "level", "above", "t_above"):
        np.testing.assert_allclose(ours(euler, port), theirs[port].astype(float), rtol=1e-12, atol=1e-12)
    assert ours(euler, "t_above")[-1] == pytest.approx(0.63)
    assert ours(euler, "above").tolist() == [0.0] * 7 + [1.0] * 14


# -- the block's features, as for co-simulation ----------------------------------------------


@pytest.mark.parametrize("solver", ["cvode", "euler"])
def test_start_values_units_and_reruns_of_one_pooled_instance(me, solver):
    d = diagram(me["linear", 2], f"solver: {solver}, start_values: {{k: 9.0, c: 0.0, x0: 0.5}}")
    block = d.blocks["f"].block
    assert block.interface == "model exchange" and block.port_units("x") == "m"
    first = simulate(d)
    assert block._model.idle and block._model.live == 0
    second = simulate(d)
    np.testing.assert_array_equal(first["f.x"][1], second["f.x"][1])   # reset and restarted alike
    t, x = first["f.x"]
    expected = 0.5 * np.cos(3.0 * t)                                   # k = 9, c = 0, no input
    assert np.abs(x[:, 0] - expected).max() < (1e-4 if solver == "cvode" else 0.1)


def test_a_fmu_with_both_interfaces_runs_co_simulation_unless_asked(tmp_path):
    why = build_error()
    if why:
        pytest.skip(why)
    path = typed_fmu(tmp_path, 2)
    both = "  c: {type: Constant, params: {value: 2.5}}\nconnections: [c.y -> f.r_in]\nlog: all\n"
    text = f"time: {{t_end: 0.3 s}}\nblocks:\n  f: {{type: FMU, period: 0.1 s, params: {{path: '{path}'PARAMS}}}}\n{both}"
    plain = loads_diagram(text.replace("PARAMS", "")).blocks["f"].block
    asked = loads_diagram(text.replace("PARAMS", ", interface: model_exchange, solver: euler"))
    assert plain.interface == "co-simulation" and plain.kernel() is None  # an Integer port: Python
    assert asked.blocks["f"].block.interface == "model exchange"
    assert asked.blocks["f"].block.describe().startswith(f"FMI 2.0 model exchange FMU '{path}' (euler, sub-step")
    r = simulate(asked)
    assert r.complete, r.status
    assert ours(r, "r_out").tolist() == [2.5] * 4 and ours(r, "time_out").tolist() == pytest.approx([0, 0.1, 0.2, 0.3])


def test_a_failing_model_fails_the_run_with_its_call_time_and_log(me, tmp_path):
    """The derivatives fail from t = 0.35 s: the run fails in the step from the hit at 0.3 s,
    naming the function, the time of the failed call (where the solver evaluated them) and
    the FMU's message; the results before it are kept."""
    for fmi, solver in ((2, "cvode"), (2, "euler"), (3, "cvode"), (3, "euler")):
        path = me_fmu(tmp_path, "linear", fmi, defines={"FAIL_DERIVATIVES_AT": "0.35"}, name=f"failing{fmi}")
        r = simulate(diagram(path, f"solver: {solver}"))
        function = "fmi2GetDerivatives" if fmi == 2 else "fmi3GetContinuousStateDerivatives"
        assert re.search(rf"^failed at t=0.3 s: block 'f' \(FMU\) update: FMU '.*': {function} at t=0\.3[5-9]\d* s "
                         r"returned status 'error'; FMU log: \[error\] logStatusError: the derivatives cannot be "
                         r"computed at t = 0\.3[5-9]", r.status), r.status
        np.testing.assert_allclose(r["f.x"][0], [0.0, 0.1, 0.2, 0.3])


@pytest.mark.parametrize("status", [0, 3], ids=["ok", "error"])
@pytest.mark.parametrize("solver, hit", [("cvode", 0.1), ("euler", 0.2)])
def test_ctrl_c_inside_the_integration_is_an_interrupt(me, tmp_path, status, solver, hit):
    """SIGINT arrives inside fmi2GetDerivatives at t >= 0.2 s, which then logs (the
    KeyboardInterrupt is raised in the log callback, where ctypes loses it) and returns ok
    or an error. Either way the run stops as interrupted, in the step that made the call
    (CVode's from 0.1 s looks past the hit at 0.2 s), results kept. (In the run's process:
    the SIGINT is the FMU's own process's.)"""
    path = me_fmu(tmp_path, "linear", 2, defines={"SIGINT_AT": "0.2", "SIGINT_STATUS": str(status)},
                  name=f"interrupting{status}{solver}")
    try:
        r = simulate(diagram(path, f"solver: {solver}, isolation: none"))
    except KeyboardInterrupt:  # pragma: no cover - would otherwise stop the whole test session
        pytest.fail("the interrupt escaped the run")
    assert r.status == f"interrupted at t={hit} s", r.status
    np.testing.assert_allclose(r["f.x"][0], np.arange(round(hit * 10) + 1) / 10)


def test_loading_never_runs_the_binary(me, tmp_path):
    """validate and load_diagram read only the modelDescription: an ME FMU whose binary is
    not a shared library loads, and fails only when a run starts."""
    with zipfile.ZipFile(me["linear", 2]) as zf:
        xml = zf.read("modelDescription.xml")
    library = f"binaries/{fmpy.platform}/Linear2{fmpy.sharedLibraryExtension}"
    path = zip_files(tmp_path / "hollow.fmu", {"modelDescription.xml": xml, library: b"not a library"})
    d = diagram(path)
    assert "cvode, tolerance 1e-08" in d.blocks["f"].block.describe()
    r = simulate(d)
    assert not r.complete and "cannot load the binary" in r.status


def test_fmu_info_describes_the_model_exchange_interface(me):
    from blocks.fmu import describe_fmu

    text = describe_fmu(me["bouncing", 3])
    assert "interfaces: model exchange (model identifier Bouncing3)" in text
    assert "model exchange: 2 continuous states, 1 event indicators; does not need completedIntegratorStep" in text
    assert "needs completedIntegratorStep" in describe_fmu(me["stair", 2])


# -- the parameters and their messages ------------------------------------------------------


def load_error(call) -> str:
    with pytest.raises(DiagramError) as info:
        call()
    return str(info.value)


def test_the_defaults_come_from_the_default_experiment(me):
    linear = diagram(me["linear", 3]).blocks["f"].block          # tolerance 1e-8, stepSize 0.01
    assert linear.tolerance == 1e-8 and linear.integration.solver == "cvode"
    assert "(cvode, tolerance 1e-08; 2 continuous states, 0 event indicators)" in linear.describe()
    euler = diagram(me["linear", 3], "solver: euler").blocks["f"].block
    assert euler.integration.substeps == 10 and "euler, sub-step 10 ms" in euler.describe()
    uneven = diagram(me["linear", 3], "solver: euler", period="25 ms").blocks["f"].block
    assert uneven.integration.substeps == 3                      # 8.33 ms: the 10 ms made to divide 25 ms
    ball = diagram(me["bouncing", 2]).blocks["f"].block          # no tolerance declared: fmpy's default
    assert ball.tolerance == 1e-5 and "1 event indicator" in ball.describe()
    default_period = loads_diagram(f"time: {{t_end: 0.1 s}}\nblocks:\n  f: {{type: FMU, params: {{path: "
                                   f"'{me['stair', 2]}'}}}}\n")
    assert default_period.blocks["f"].period == pytest.approx(0.01)


@pytest.mark.parametrize("params, message", [
    ("solver: rk4", "parameter 'solver' must be one of cvode, euler, got 'rk4'"),
    ("substep: 1 ms", "parameter 'substep' is the fixed step of 'solver: euler'; CVode chooses its own steps"),
    ("solver: euler, substep: -1 ms", "parameter 'substep' must be positive"),
    ("solver: euler, substep: fast", "parameter 'substep': cannot read 'fast' as a duration"),
    ("interface: exchange", "parameter 'interface' must be one of co_simulation, model_exchange, scheduled_execution, got 'exchange'"),
    ("interface: co_simulation", "has no co-simulation interface (it provides only model exchange); drop "
                                 "'interface: co_simulation' to run it as model exchange"),
])
def test_bad_parameters_are_named(me, params, message):
    msg = load_error(lambda: diagram(me["linear", 2], params))
    assert msg.startswith("me.yaml:4: block 'f' (FMU): ") and message in msg, msg


def test_a_period_that_is_no_whole_number_of_sub_steps_is_refused(me):
    msg = load_error(lambda: diagram(me["linear", 2], "solver: euler, substep: 30 ms"))
    assert ("me.yaml:4: block 'f' (FMU): the period 100 ms is not a whole multiple of the sub-step 30 ms; use a "
            "sub-step that divides it, e.g. 'substep: 25 ms'") in msg, msg
    assert "e.g. 'substep: 100 ms'" in load_error(lambda: diagram(me["linear", 2], "solver: euler, substep: 0.2 s"))


def test_solver_parameters_on_a_co_simulation_fmu_are_refused(tmp_path):
    why = build_error()
    if why:
        pytest.skip(why)
    both = typed_fmu(tmp_path, 3)
    msg = load_error(lambda: diagram(both, "solver: euler"))
    assert ("parameter 'solver' is for model-exchange FMUs; FMU '" in msg and "runs as co-simulation, with its own "
            "solver (ask for 'interface: model_exchange' to integrate it with the block's solver)") in msg, msg
    only = typed_fmu(tmp_path, 3, only="CoSimulation")
    assert "(it has no model-exchange interface)" in load_error(lambda: diagram(only, "solver: cvode"))
    msg = load_error(lambda: diagram(only, "interface: model_exchange"))
    assert ("has no model exchange interface (it provides only co-simulation); drop 'interface: model_exchange' "
            "to run it as co-simulation") in msg, msg
