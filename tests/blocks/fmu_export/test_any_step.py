"""Exported FMUs stepped at any communication step (blocks.fmu_export, export_step.c).

Importers such as OMSimulator step every FMU of a system at the smallest step of all, so
an exported multirate diagram must take steps shorter than, and off, its grid: a step runs
every grid point up to its end with the inputs set at its start, and between grid points
the outputs hold the last one's, as the diagram's samples hold between hits. The FMUs also
answer reads of their outputs before their inputs are set with an OK status (OMSimulator
takes a warning for an error).
"""

from __future__ import annotations

import ctypes
import textwrap

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

import blocks
from blocks.fmu_export import export_fmu

from .slave import Slave, run

SLOW_PI = """\
name: slow-pi
description: a PI controller whose every block runs at 10 ms
blocks:
  integ: {type: DiscreteStateSpace, period: 10 ms,
          params: {A: [[1.0]], B: [[0.2]], C: [[1.0]], D: [[0.0]]}}
  prop:  {type: Gain, period: 10 ms, params: {k: 5.0}}
  u:     {type: Sum, params: {signs: "++"}}
connections:
  - integ.y -> u.u0
  - prop.y -> u.u1
inputs: {e: [integ.u, prop.u]}
outputs: {u: u.y}
"""

LOOP = """\
name: loop-{what}
time: {{t_end: 0.3 s}}
blocks:
  ref:   {{type: Sine, period: 1 ms, params: {{amplitude: 1.0, frequency: 7.0}}}}
  err:   {{type: Sum, params: {{signs: "+-"}}}}
  plant: {{type: DiscreteStateSpace, period: 1 ms,
          params: {{A: [[0.99]], B: [[1.0e-3]], C: [[1.0]], D: [[0.0]]}}}}
  ctrl:  {ctrl}
connections:
  - ref.y -> err.u0
  - plant.y -> err.u1
  - err.y -> ctrl.e
  - ctrl.u -> plant.u
log: [plant.y]
"""


@pytest.fixture(scope="module")
def slow_pi(tmp_path_factory):
    folder = tmp_path_factory.mktemp("slow_pi")
    (folder / "pi.yaml").write_text(SLOW_PI)
    d = blocks.load_diagram(folder / "pi.yaml")
    return folder, {fmi: export_fmu(d, folder / f"pi{fmi}.fmu", fmi) for fmi in (2, 3)}


@pytest.mark.parametrize("fmi", [2, 3])
def test_a_10_ms_subsystem_stepped_at_1_ms_in_its_loop_is_the_subsystem_itself(slow_pi, fmi):
    """The loop's plant and error change every 1 ms; the exported controller, stepped at
    1 ms, samples its input at its own 10 ms hits only and holds its output in between:
    the loop equals the loop with the subsystem inline, to the last bit."""
    folder, fmus = slow_pi
    assert validate_fmu(str(fmus[fmi])) == []
    outputs = read_model_description(str(fmus[fmi])).outputs
    assert [o.variable.variability for o in outputs] == ["discrete"]  # a sampled block's output
    (folder / "inline.yaml").write_text(LOOP.format(what="inline", ctrl="{diagram: pi.yaml}"))
    (folder / f"fmu{fmi}.yaml").write_text(LOOP.format(
        what="fmu", ctrl=f'{{type: FMU, period: 1 ms, params: {{path: "{fmus[fmi]}", feedthrough: true}}}}'))
    inline = blocks.simulate(blocks.load_diagram(folder / "inline.yaml"))
    via_fmu = blocks.simulate(blocks.load_diagram(folder / f"fmu{fmi}.yaml"))
    assert via_fmu.complete, via_fmu.status
    np.testing.assert_array_equal(via_fmu["plant.y"][0], inline["plant.y"][0])
    np.testing.assert_array_equal(via_fmu["plant.y"][1], inline["plant.y"][1])


def held(results, signal: str, times: np.ndarray) -> np.ndarray:
    """A native run's samples of ``signal`` held at ``times`` (the last sample at or before)."""
    t, values = results[signal]
    return values[np.searchsorted(t, times + 1e-12, side="right") - 1]


@pytest.mark.parametrize("fmi", [2, 3])
@pytest.mark.parametrize("step", [1e-3, 1.5e-3, 7e-3, 25e-3])
def test_steps_off_the_grid_hold_the_last_grid_points_outputs(tmp_path, fmi, step):
    (tmp_path / "ramp.yaml").write_text(textwrap.dedent("""\
        name: slow-ramp
        time: {t_end: 0.2 s}
        blocks:
          ramp: {type: Ramp, period: 10 ms, params: {slope: 1.0}}
          acc: {type: DiscreteIntegrator, period: 10 ms, params: {}}
        connections: [ramp.y -> acc.u]
        log: [ramp.y, acc.y]
        """))
    d = blocks.load_diagram(tmp_path / "ramp.yaml")
    path = export_fmu(d, tmp_path / "ramp.fmu", fmi)
    n = int(0.15 // step)
    rows = run(path, tmp_path / "run", ["ramp.y", "acc.y"], step, n)
    native = blocks.simulate(d)
    times = np.arange(n + 1) * step
    for column, signal in enumerate(("ramp.y", "acc.y")):
        np.testing.assert_array_equal(rows[:, column], held(native, signal, times)[:, 0], err_msg=signal)


@pytest.mark.parametrize("fmi", [2, 3])
def test_a_state_saved_between_grid_points_rewinds_exactly(slow_pi, fmi, tmp_path):
    slave = Slave(slow_pi[1][fmi], tmp_path)

    def steps(k0: int, n: int) -> np.ndarray:
        out = []
        for k in range(k0, k0 + n):
            slave.set(e=np.sin(0.3 * k))
            slave.step(k * 3e-3, 3e-3)
            out.append(slave.get(["u"]))
        return np.array(out)

    try:
        slave.initialize()
        steps(0, 7)  # at 21 ms: between the grid points 20 and 30 ms
        saved = slave.fmu.getFMUState()
        first = steps(7, 20)
        slave.fmu.setFMUState(saved)
        np.testing.assert_array_equal(steps(7, 20), first)
        restored = slave.serialized_copy(saved)
        slave.fmu.setFMUState(restored)
        np.testing.assert_array_equal(steps(7, 20), first)
        assert len(np.unique(first)) > 5
        slave.free_states(saved, restored)
    finally:
        slave.close()


def test_outputs_read_before_the_inputs_are_set_answer_ok(tmp_path):
    """A division by an input that is still 0 in initialization mode: the outputs wait for
    the input (status OK, a logged event), and are computed once it is set."""
    (tmp_path / "div.yaml").write_text(textwrap.dedent("""\
        name: divide
        blocks:
          one: {type: Constant, params: {value: 1.0}}
          div: {type: Divide, period: 1 ms, params: {}}
        connections: [one.y -> div.u0]
        inputs: {d: div.u1}
        outputs: {q: div.y}
        """))
    path = export_fmu(blocks.load_diagram(tmp_path / "div.yaml"), tmp_path / "div.fmu", 2)
    slave = Slave(path, tmp_path / "unzipped", logging_on=True)
    try:
        functions, component = slave.fmu._functions, slave.fmu.component  # the raw calls and their statuses
        assert functions["fmi2EnterInitializationMode"](component) == 0
        vr, value = (ctypes.c_uint * 1)(slave.vr["q"]), (ctypes.c_double * 1)()
        assert functions["fmi2GetReal"](component, vr, 1, value) == 0
        assert slave.messages and all(status == 0 for status, _, _ in slave.messages)  # logged, not warned
        slave.set(d=4.0)
        assert functions["fmi2GetReal"](component, vr, 1, value) == 0 and value[0] == 0.25
        assert functions["fmi2ExitInitializationMode"](component) == 0
    finally:
        slave.close()
