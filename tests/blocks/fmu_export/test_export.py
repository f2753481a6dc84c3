"""Diagrams of library blocks exported as FMUs (blocks.fmu_export), against native runs.

An exported FMU runs the diagram's own op table over the same C kernels, so its outputs at
communication points are the native run's samples: to the last bit where the points fall
on the diagram's events, to round-off where a step cuts the advance of a state-space
block in two (its closed form over n steps is then two shorter ones). The FMUs pass
``fmpy validate``, declare units, refuse blocks that cannot leave Python with one line
each, rewind through FMU states, run side by side, and their binaries need no Python.
"""

from __future__ import annotations

import ctypes
import shutil
import subprocess
import textwrap
from pathlib import Path

import numpy as np
import pytest
import yaml
from fmpy import read_model_description
from fmpy.validation import validate_fmu
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import blocks
from blocks import DiagramError, loads_diagram
from blocks.fmu_export import export_fmu

from ..library.test_library_diagram import diagram as every_block_diagram
from ..test_diagram_fuzz import FUZZ_SETTINGS, wired_document
from ..builder.test_subsystems import PI, TOP
from .slave import Slave, run

REPO = Path(__file__).resolve().parents[3]
TOY = REPO / "diagrams" / "toy.yaml"


def held(results, signal: str, times: np.ndarray) -> np.ndarray:
    """A native run's samples of ``signal`` held at ``times`` (the last sample at or before)."""
    t, values = results[signal]
    return values[np.searchsorted(t, times + 1e-12, side="right") - 1]


@pytest.fixture(scope="module")
def toy_fmus(tmp_path_factory):
    folder = tmp_path_factory.mktemp("toy")
    d = blocks.load_diagram(TOY)
    return {fmi: export_fmu(d, folder / f"toy{fmi}.fmu", fmi) for fmi in (2, 3)}


@pytest.mark.parametrize("fmi", [2, 3])
def test_the_toy_leaves_as_a_valid_fmu_whose_samples_are_the_native_runs(toy_fmus, fmi, tmp_path):
    path = toy_fmus[fmi]
    assert validate_fmu(str(path)) == []
    md = read_model_description(str(path))
    assert md.coSimulation.canHandleVariableCommunicationStepSize
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    assert float(md.defaultExperiment.stepSize) == 1e-4 and float(md.defaultExperiment.stopTime) == 1.0
    assert [v.name for v in md.modelVariables if v.causality == "output"] == ["plant.y"]  # the logged signal
    assert {"prop.k", "ref.value"} <= {v.name for v in md.modelVariables if v.causality == "parameter"}
    native = blocks.simulate(blocks.load_diagram(TOY))
    on_events = run(path, tmp_path / "a", ["plant.y"], 1e-3, 1000)
    np.testing.assert_array_equal(on_events[:, 0], held(native, "plant.y", np.arange(1001) * 1e-3)[:, 0])
    every_tick = run(path, tmp_path / "b", ["plant.y"], 1e-4, 10000)
    np.testing.assert_allclose(every_tick[:, 0], native["plant.y"][1][:, 0], rtol=1e-12, atol=0)


def test_every_signal_block_of_the_library_leaves_with_the_native_samples(tmp_path):
    d = every_block_diagram(tmp_path)
    path = export_fmu(d, tmp_path / "every.fmu", 3)
    assert validate_fmu(str(path)) == []
    slave = Slave(path, tmp_path / "unzipped")
    names = slave.names("output")
    slave.close()
    rows = run(path, tmp_path / "run", names, 1e-3, 500)
    native = blocks.simulate(d)
    times = np.arange(501) * 1e-3
    column = 0
    for e in d.log:
        width = d.width(e.signal)
        np.testing.assert_array_equal(rows[:, column:column + width], held(native, e.signal, times).reshape(-1, width),
                                      err_msg=e.signal)
        column += width
    assert column == len(names)


@settings(max_examples=120, suppress_health_check=[*FUZZ_SETTINGS.get("suppress_health_check", ()),
                                                   HealthCheck.function_scoped_fixture],
          derandomize=True)
@given(doc=wired_document(), ticks=st.integers(min_value=5, max_value=60))
def test_random_library_diagrams_leave_with_the_native_samples(doc, ticks, tmp_path):
    try:
        d = loads_diagram(yaml.safe_dump(doc, sort_keys=False), filename="random.yaml", base_dir=tmp_path)
        native = blocks.simulate(d, t_end=ticks * blocks.build_schedule(d, None).base_tick)
    except DiagramError:
        return
    if not d.log or not native.complete:
        return
    folder = tmp_path / f"random{abs(hash(yaml.safe_dump(doc)))}"
    path = export_fmu(d, folder / "random.fmu", 2)
    slave = Slave(path, folder / "probe")
    names, grid = slave.names("output"), float(slave.md.defaultExperiment.stepSize)
    slave.close()
    base = float(blocks.build_schedule(d, None).base_tick)
    steps = int(round(ticks * base / grid))
    rows = run(path, folder / "run", names, grid, steps)
    times = np.arange(steps + 1) * grid
    column = 0
    for e in d.log:
        width = d.width(e.signal)
        t, values = native[e.signal]
        at = np.isin(np.round(times / base), np.round(t / base))  # the points the native run logged
        logged = np.isin(np.round(t / base), np.round(times / base))
        mine = rows[at, column:column + width]
        np.testing.assert_allclose(mine, values[logged].reshape(-1, width), rtol=1e-12,
                                   atol=1e-12 * max(1.0, float(np.abs(values).max(initial=0.0))), err_msg=e.signal)
        column += width


def toy_with(what: str, ctrl: str) -> str:
    """The toy of the subsystem tests with its controller block given as ``ctrl``."""
    return TOP.replace("name: toy-composed", f"name: toy-{what}").replace("{diagram: lib/pi.yaml}", ctrl)


@pytest.mark.parametrize("fmi,isolation", [(2, "none"), (3, "process")])
def test_a_subsystem_leaves_with_its_inputs_and_outputs_and_feeds_through_as_native(tmp_path, fmi, isolation):
    """The toy's controller (inputs: and outputs:, a 10 ms gain beside a 1 ms integral) as
    an FMU stepped at 1 ms: its output depends on its input, which the ModelStructure says;
    the toy with the FMU wired back without any annotation, in the run's process or in one
    of its own, is the toy with the subsystem, to the last bit. With 'feedthrough: false'
    (the Jacobi exchange) its output lags a step behind from the gain's first hit."""
    (tmp_path / "pi.yaml").write_text(PI)
    pi = blocks.load_diagram(tmp_path / "pi.yaml")
    path = export_fmu(pi, tmp_path / f"pi{fmi}.fmu", fmi)
    assert validate_fmu(str(path)) == []
    md = read_model_description(str(path))
    assert [(u.variable.name, [d.name for d in u.dependencies]) for u in md.outputs] == [("u", ["e"])]
    (tmp_path / "composed.yaml").write_text(toy_with("composed", "{diagram: pi.yaml}"))
    (tmp_path / "fmu.yaml").write_text(toy_with(
        "fmu", f'{{type: FMU, period: 1 ms, params: {{path: "{path}", isolation: {isolation}}}}}'))
    composed = blocks.simulate(blocks.load_diagram(tmp_path / "composed.yaml"))
    via_fmu = blocks.simulate(blocks.load_diagram(tmp_path / "fmu.yaml"))
    assert via_fmu.complete
    np.testing.assert_array_equal(via_fmu["plant.y"][0], composed["plant.y"][0])
    np.testing.assert_array_equal(via_fmu["plant.y"][1], composed["plant.y"][1])
    jacobi = blocks.simulate(blocks.load_diagram(tmp_path / "fmu.yaml", overrides={"ctrl.feedthrough": False}),
                             t_end=0.05)
    apart = np.abs(jacobi["plant.y"][1] - composed["plant.y"][1][:len(jacobi["plant.y"][1])])[:, 0]
    assert apart[:101].max() == 0.0 and apart.max() > 1e-6     # equal up to the gain's second hit (10 ms)


def test_blocks_that_cannot_leave_python_are_refused_one_line_each(tmp_path, toy_fmus):
    (tmp_path / "twice.py").write_text(textwrap.dedent("""\
        from blocks import Block

        class Twice(Block):
            def __init__(self):
                self.inputs, self.outputs, self.feedthrough = {"u": 1}, {"y": 1}, True

            def output(self, t, state, inputs):
                return {"y": 2 * inputs["u"]}
        """))
    (tmp_path / "mixed.yaml").write_text(textwrap.dedent(f"""\
        name: mixed
        time: {{t_end: 10 ms}}
        blocks:
          src: {{type: Sine, period: 1 ms, params: {{amplitude: 1, frequency: 1}}}}
          two: {{type: "python:twice:Twice"}}
          fmu: {{type: FMU, period: 1 ms, params: {{path: "{toy_fmus[2]}"}}}}
        connections: [src.y -> two.u]
        log: [two.y, fmu.plant_y]
        """))
    d = blocks.load_diagram(tmp_path / "mixed.yaml", trust=True)
    with pytest.raises(DiagramError) as info:
        export_fmu(d, tmp_path / "mixed.fmu")
    assert [str(issue) for issue in info.value.issues] == [
        f"{tmp_path / 'mixed.yaml'}:5: block 'two' (Twice) cannot be exported: it has no compiled kernel (hint: an "
        "exported FMU runs compiled blocks only (library and application blocks with a C kernel))",
        f"{tmp_path / 'mixed.yaml'}:6: block 'fmu' (FMU) cannot be exported: the FMU an FMU block runs is not "
        "carried inside an exported FMU (hint: an exported FMU runs compiled blocks only (library and application "
        "blocks with a C kernel))"]
    assert not (tmp_path / "mixed.fmu").exists()
    done = subprocess.run(["python", "-m", "blocks", "fmu", "export", "mixed.yaml", "--trust"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 2, done.stderr


@pytest.mark.parametrize("fmi", [2, 3])
def test_tunable_parameters_are_the_native_overrides_and_checked(toy_fmus, fmi, tmp_path):
    native = blocks.simulate(blocks.load_diagram(TOY, overrides={"prop.k": 2.5, "ref.value": 0.5}))
    rows = run(toy_fmus[fmi], tmp_path / "tuned", ["plant.y"], 1e-3, 200, start={"prop.k": 2.5, "ref.value": 0.5})
    np.testing.assert_array_equal(rows[:, 0], held(native, "plant.y", np.arange(201) * 1e-3)[:, 0])
    slave = Slave(toy_fmus[fmi], tmp_path / "bad")
    try:
        slave.set(prop__k=float("inf"))
        with pytest.raises(Exception, match="ExitInitializationMode"):
            slave.initialize()
        assert slave.errors() == ["invalid parameter: prop.k must be finite, got inf"]
    finally:
        slave.close()


@pytest.mark.parametrize("fmi", [2, 3])
def test_get_and_set_state_rewinds_a_run_exactly(toy_fmus, fmi, tmp_path):
    slave = Slave(toy_fmus[fmi], tmp_path)

    def steps(k0: int, n: int) -> np.ndarray:
        out = []
        for k in range(k0, k0 + n):
            slave.step(k * 5e-4, 5e-4)
            out.append(slave.get(["plant.y"]))
        return np.array(out)

    try:
        slave.initialize()
        steps(0, 33)
        saved = slave.fmu.getFMUState()
        first = steps(33, 40)
        slave.fmu.setFMUState(saved)
        np.testing.assert_array_equal(steps(33, 40), first)
        restored = slave.serialized_copy(saved)
        slave.fmu.setFMUState(restored)
        np.testing.assert_array_equal(steps(33, 40), first)
        assert np.abs(first[-1] - first[0]).max() > 1e-4
        slave.free_states(saved, restored)
    finally:
        slave.close()


def test_several_instances_of_several_diagrams_run_side_by_side(toy_fmus, tmp_path):
    (tmp_path / "pi.yaml").write_text(PI)
    pi = export_fmu(blocks.load_diagram(tmp_path / "pi.yaml"), tmp_path / "pi.fmu", 2)
    toys = [Slave(toy_fmus[2], tmp_path / f"toy{i}", f"toy{i}") for i in range(2)]
    toy3 = Slave(toy_fmus[3], tmp_path / "toy3", "toy3")
    pis = [Slave(pi, tmp_path / f"pi{i}", f"pi{i}") for i in range(2)]
    try:
        toys[1].set(prop__k=2.5)
        for s in (*toys, toy3, *pis):
            s.initialize()
        rows: dict[str, list] = {"toy0": [], "toy1": [], "toy3": [], "pi0": [], "pi1": []}
        for k in range(100):
            for i, s in enumerate(pis):
                s.set(e=0.5 * (i + 1))
                s.step(k * 1e-3, 1e-3)
                rows[f"pi{i}"].append(s.get(["u"])[0])
            for key, s in (("toy0", toys[0]), ("toy1", toys[1]), ("toy3", toy3)):
                s.step(k * 1e-3, 1e-3)
                rows[key].append(s.get(["plant.y"])[0])
    finally:
        for s in (*toys, toy3, *pis):
            s.close()
    alone = {"toy0": run(toy_fmus[2], tmp_path / "a0", ["plant.y"], 1e-3, 100)[1:, 0],
             "toy1": run(toy_fmus[2], tmp_path / "a1", ["plant.y"], 1e-3, 100, start={"prop.k": 2.5})[1:, 0]}
    np.testing.assert_array_equal(rows["toy0"], alone["toy0"])
    np.testing.assert_array_equal(rows["toy3"], alone["toy0"])
    np.testing.assert_array_equal(rows["toy1"], alone["toy1"])
    assert not np.array_equal(rows["toy0"], rows["toy1"])
    # u = integ + prop with e held: the integrator ramps at 0.02 e per ms, twice as fast for e = 1
    assert rows["pi1"][-1] == pytest.approx(2 * rows["pi0"][-1])


@pytest.mark.parametrize("fmi", [2, 3])
def test_a_stop_block_ends_the_fmu(tmp_path, fmi):
    (tmp_path / "stop.yaml").write_text(textwrap.dedent("""\
        name: stopping
        time: {t_end: 1 s}
        blocks:
          ramp: {type: Ramp, period: 1 ms, params: {slope: 1.0}}
          stop: {type: Stop, params: {}}
          over: {type: Compare, params: {op: ">=", constant: 0.0105}}
        connections: [ramp.y -> over.u, over.y -> stop.u]
        log: [ramp.y]
        """))
    path = export_fmu(blocks.load_diagram(tmp_path / "stop.yaml"), tmp_path / "stop.fmu", fmi)
    slave = Slave(path, tmp_path / "unzipped")
    try:
        slave.initialize()
        t = 0.0
        ended = None
        for _ in range(30):
            if fmi == 2:
                functions = slave.fmu._functions  # the raw calls: fmpy's raise on a discard
                status = functions["fmi2DoStep"](slave.fmu.component, t, 2e-3, 1)
                if status == 2:  # fmi2Discard with fmi2Terminated, at fmi2LastSuccessfulTime
                    flag, last = ctypes.c_int(0), ctypes.c_double(0.0)
                    assert functions["fmi2GetBooleanStatus"](slave.fmu.component, 3, ctypes.byref(flag)) == 0
                    assert flag.value == 1
                    assert functions["fmi2GetRealStatus"](slave.fmu.component, 2, ctypes.byref(last)) == 0
                    ended = last.value
                    break
            else:
                _, terminate, _, last = slave.fmu.doStep(t, 2e-3)
                if terminate:
                    ended = last
                    break
            t += 2e-3
        assert ended == pytest.approx(0.012)  # asked at 11 ms (ramp >= 0.0105), ended at its next hit
        assert slave.get(["ramp.y"])[0] == pytest.approx(0.012)
    finally:
        slave.close()


@pytest.mark.parametrize("fmi", [2, 3])
def test_the_stop_time_is_enforced(toy_fmus, fmi, tmp_path):
    slave = Slave(toy_fmus[fmi], tmp_path, stop_time=5e-3)
    try:
        slave.initialize()
        for k in range(5):
            slave.step(k * 1e-3, 1e-3)
        with pytest.raises(Exception, match="DoStep"):
            slave.step(5e-3, 1e-3)
        assert slave.errors() == ["a step to t=0.006 s passes the stop time 0.005 s"]
    finally:
        slave.close()


def _tool(name: str) -> str:
    found = shutil.which(name)
    if found is None:
        pytest.skip(f"{name} is not installed")
    return found


def test_the_library_binary_needs_no_python(toy_fmus, tmp_path):
    from fmpy import extract

    md = read_model_description(str(toy_fmus[3]))
    library = next(Path(extract(str(toy_fmus[3]), tmp_path)).glob(f"binaries/*/{md.coSimulation.modelIdentifier}.so"))
    needed = subprocess.run([_tool("readelf"), "-d", str(library)], capture_output=True, text=True, check=True).stdout
    assert "python" not in needed.lower()
    undefined = subprocess.run([_tool("nm"), "-D", "--undefined-only", str(library)], capture_output=True, text=True,
                               check=True).stdout.split()
    assert not [s for s in undefined if s.startswith(("Py", "_Py"))]


def test_units_are_declared_where_the_blocks_give_them(tmp_path):
    (tmp_path / "units.yaml").write_text(textwrap.dedent("""\
        name: units
        time: {t_end: 10 ms}
        blocks:
          sine: {type: Sine, period: 1 ms, params: {amplitude: 1, frequency: 2}}
          mux:  {type: Mux, params: {widths: [1, 1], labels: [a, b]}}
        connections: [sine.y -> mux.u0, sine.y -> mux.u1]
        log: [mux.y]
        """))
    d = blocks.load_diagram(tmp_path / "units.yaml")
    md = read_model_description(str(export_fmu(d, tmp_path / "u.fmu", 3)))
    outputs = {v.name: v for v in md.modelVariables if v.causality == "output"}
    assert set(outputs) == {"mux.y[1]", "mux.y[2]"}
    assert "element a" in outputs["mux.y[1]"].description and "element b" in outputs["mux.y[2]"].description
    time = next(v for v in md.modelVariables if v.name == "time")
    assert time.unit == "s" and "s" in {u.name for u in md.unitDefinitions}


def test_the_units_and_element_names_a_diagram_gives_its_ports_are_the_fmus(tmp_path):
    (tmp_path / "annotated.yaml").write_text(textwrap.dedent("""\
        name: annotated
        time: {t_end: 10 ms}
        blocks:
          pose: {type: Constant, params: {value: [0.1, 0.2, 0.5]},
                 units: {y: [mm, mm, deg]}, elements: {y: [x, y, theta]}}
          turn: {type: Gain, period: 1 ms, params: {k: 2.0}}
          rate: {type: DiscreteStateSpace, period: 1 ms, params: {A: [[0.5]], B: [[1.0]], C: [[1.0]], D: [[0.0]]}}
        connections:
          - pose.y[theta] -> turn.u
        units: {turn.u: deg, turn.y: deg, rate.u: deg/s, rate.y: deg/s}
        inputs: {w: rate.u}
        outputs: {pose: pose.y, turn: turn.y, rate: rate.y}
        """))
    md = read_model_description(str(export_fmu(blocks.load_diagram(tmp_path / "annotated.yaml"),
                                               tmp_path / "a.fmu", 2)))
    by_name = {v.name: v for v in md.modelVariables}
    assert [(n, by_name[n].unit) for n in ("pose[1]", "pose[2]", "pose[3]", "turn", "w", "rate")] == [
        ("pose[1]", "mm"), ("pose[2]", "mm"), ("pose[3]", "deg"), ("turn", "deg"), ("w", "deg/s"), ("rate", "deg/s")]
    assert "element theta" in by_name["pose[3]"].description
    units = {u.name: u.baseUnit for u in md.unitDefinitions}
    assert (units["mm"].m, units["mm"].factor) == (1, 0.001)
    assert units["deg/s"].rad == 1 and units["deg/s"].s == -1 and units["deg/s"].factor == pytest.approx(np.pi / 180)
    assert validate_fmu(str(tmp_path / "a.fmu")) == []
