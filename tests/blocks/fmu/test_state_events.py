"""State events of model-exchange FMUs are handed over past the crossing, with both solvers.

FMI asks the importer to give the FMU, before event mode, a time and states at which the
event indicator has changed its domain. An FMU whose event handler reads a state's sign
(as generated code does) rather than the indicator sees no event at the crossing itself
(the indicator exactly 0), and then none ever again. Two models built with such handlers
(``sources/``): ``sawtooth.c`` (x' = -1, and where x < 0: x + 1), whose crossings on a
binary grid land the located state exactly on 0 for Euler's bisection, and ``bouncing.c``
built with ``STRICT_SIGN`` (it bounces only where h < 0), against its closed form.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("fmpy")

from .build import build_error, me_fmu  # noqa: E402
from .test_exchange import G, ball, ours, run  # noqa: E402

PERIOD = 0.125     # the hits, and the sawtooth's default Euler sub-step: a binary grid
TOLERANCE = 1e-8


@pytest.fixture(scope="module")
def models(tmp_path_factory) -> dict:
    why = build_error()
    if why:
        pytest.skip(why)
    build = tmp_path_factory.mktemp("state_event_fmus")
    found = {}
    for fmi in (2, 3):
        found["sawtooth", fmi] = me_fmu(build, "sawtooth", fmi)
        found["ball", fmi] = me_fmu(build, "bouncing", fmi, defines={"STRICT_SIGN": "1"},
                                    name=f"StrictBouncing{fmi}")
    return found


@pytest.mark.parametrize("fmi", [2, 3])
@pytest.mark.parametrize("solver", ["cvode", "euler"])
@pytest.mark.parametrize("x0", [0.75, 0.5, 0.3])
def test_an_event_handler_that_reads_the_states_sign_sees_every_crossing(models, fmi, solver, x0):
    """x falls at rate 1 from x0 and crosses 0 at x0, x0 + 1, ...: every crossing is a tooth,
    handed over at (not before) its time, and x never falls below the floor."""
    r = run(models["sawtooth", fmi], f"solver: {solver}, tolerance: {TOLERANCE}, start_values: {{x0: {x0}}}",
            period=f"{PERIOD} s", t_end="4 s")
    t, teeth, x = r["f.x"][0], ours(r, "teeth"), ours(r, "x")
    crossings = x0 + np.arange(4.0)
    expected = np.searchsorted(crossings, t, side="right")
    away = np.abs(t[:, None] - crossings[None, :]).min(axis=1) > 1e-6   # a hit at a crossing may see it or not
    assert np.array_equal(teeth[away], expected[away])
    assert teeth[-1] == 4
    late = TOLERANCE * PERIOD if solver == "euler" else 1e-9   # Euler's bisection keeps the end past it
    assert 0.0 <= ours(r, "t_tooth")[-1] - crossings[-1] <= late + 1e-12
    assert x.min() >= -1e-12 and x.max() <= 1.0
    between = np.where(expected > 0, t - np.take(crossings, np.maximum(expected - 1, 0)), t - x0 + 1.0)
    assert np.abs(x[away] - (1.0 - between[away])).max() < 1e-6


@pytest.mark.parametrize("fmi", [2, 3])
@pytest.mark.parametrize("solver", ["cvode", "euler"])
def test_a_ball_that_bounces_only_below_the_floor_bounces_where_the_closed_form_does(models, fmi, solver):
    """Bounce times and heights against the closed form: to CVode's tolerance, and to
    Euler's first-order error (a 1 ms sub-step)."""
    params = "tolerance: 1e-8" if solver == "cvode" else "solver: euler, substep: 1 ms, tolerance: 1e-6"
    r = run(models["ball", fmi], params, period="0.01 s")
    t = r["f.h"][0]
    height, count, last = ball(t)
    near = np.abs(t[:, None] - np.unique(last)[None, :]).min(axis=1) < 0.02  # a hit next to a bounce
    assert np.array_equal(ours(r, "bounces")[~near], count[~near]) and ours(r, "bounces")[-1] == count[-1] == 3
    times, heights = (1e-7, 2e-7) if solver == "cvode" else (6e-3, 3e-2)
    assert np.abs(ours(r, "t_bounce") - last)[~near].max() < times
    assert np.abs(ours(r, "h") - height)[~near].max() < heights
    assert ours(r, "h").min() >= -G * 1e-6       # never sinks below the floor (by more than a step's worth)
