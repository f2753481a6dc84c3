"""Hand diagrams exported as native FMUs (hierhand fmu export DIAGRAM), against native runs.

The re-grasp's controller (diagrams/controller.yaml with the re-grasp's parameters, and
the object's support) leaves as one FMU with the controller's inputs and outputs; wired
with the plant FMU, no annotation needed, it gives the native re-grasp to the last bit.
The whole closed loop leaves as an FMU without inputs that fmpy, a C host without Python
and libcosim step. Parameters keep their checks and derived values; the FMUs declare units.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import yaml
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

import blocks
from hierhand.fmu_export import export_diagram_fmu, export_plant_fmu
from tests.blocks.fmu_export.slave import Slave

REPO = Path(__file__).resolve().parents[2]
REGRASP = REPO / "diagrams" / "regrasp.yaml"
PLANT_PORTS = ("q", "qd", "tip", "fn", "ft", "normal", "obj")
COMPARED = ("plant.q", "plant.obj", "plant.fn", "plant.contact")
STEP = 1e-3


def regrasp_controller(folder: Path) -> Path:
    """The re-grasp's controller as a diagram of its own in ``folder``: the controller
    subsystem with the re-grasp's parameters (read from regrasp.yaml) and the object's
    support, its inputs the plant's signals, its outputs the torques and the support's force."""
    shutil.copy(REPO / "diagrams" / "controller.yaml", folder / "controller.yaml")
    task = yaml.safe_load(REGRASP.read_text(encoding="utf-8"))["blocks"]
    doc = {"name": "regrasp-controller",
           "description": "the re-grasp's hierarchical controller and the object's support",
           "references": {"plant": "HandPlant"},
           "blocks": {"ctrl": task["ctrl"], "support": task["support"]},
           "connections": ["support.y -> ctrl.support"],
           "inputs": {port: f"ctrl.{port}" for port in PLANT_PORTS},
           "outputs": {"tau": "ctrl.tau", "f_ext": "support.y"}}
    path = folder / "regrasp_controller.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    """The re-grasp's controller, the closed loop and the plant, exported for FMI 2 and 3."""
    folder = tmp_path_factory.mktemp("diagram_fmus")
    controller = blocks.load_diagram(regrasp_controller(folder))
    loop = blocks.load_diagram(REGRASP)
    out = {}
    for fmi in (2, 3):
        out["ctrl", fmi] = export_diagram_fmu(controller, folder / f"ctrl{fmi}.fmu", fmi)
        out["loop", fmi] = export_diagram_fmu(loop, folder / f"loop{fmi}.fmu", fmi)
        out["plant", fmi] = export_plant_fmu(folder / f"plant{fmi}.fmu", fmi=fmi)
    return out


def two_fmus(folder: Path, plant: Path, ctrl: Path, jacobi: bool = False) -> blocks.Diagram:
    """The re-grasp with the plant FMU and the controller FMU, exchanging every 1 ms in the
    order their ModelStructures declare, or (``jacobi``) with 'feedthrough: false' on the
    controller."""
    doc = yaml.safe_load(REGRASP.read_text(encoding="utf-8"))
    doc["name"] = "regrasp-two-fmus"
    doc["blocks"] = {"plant": {"type": "FMU", "period": "1 ms", "params": {"path": str(plant)}},
                     "ctrl": {"type": "FMU", "period": "1 ms",
                              "params": {"path": str(ctrl), **({"feedthrough": False} if jacobi else {})}}}
    doc["connections"] = [f"plant.{p} -> ctrl.{p}" for p in PLANT_PORTS] + ["ctrl.tau -> plant.tau",
                                                                            "ctrl.f_ext -> plant.f_ext"]
    doc["log"] = list(COMPARED)
    path = folder / f"two_fmus_{int(jacobi)}.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return blocks.load_diagram(path)


def names(signal: str, width: int) -> list[str]:
    return [f"{signal}[{i}]" for i in range(1, width + 1)]


@pytest.mark.parametrize("fmi", [2, 3])
def test_the_controller_and_the_loop_leave_as_valid_fmus_with_units(fmus, fmi):
    for what in ("ctrl", "loop"):
        assert validate_fmu(str(fmus[what, fmi])) == [], what
    md = read_model_description(str(fmus["ctrl", fmi]))
    inputs = {v.name: v for v in md.modelVariables if v.causality == "input"}
    assert {name.split("[")[0] for name in inputs} == set(PLANT_PORTS)
    assert inputs["q[4]"].unit == "rad" and "fore" in inputs["q[4]"].description
    outputs = {v.name: v for v in md.modelVariables if v.causality == "output"}
    assert set(outputs) == set(names("tau", 9) + names("f_ext", 3))
    assert outputs["tau[1]"].unit == "N m"
    assert {"N m", "rad", "m", "N"} <= {u.name for u in md.unitDefinitions}
    assert float(md.defaultExperiment.stepSize) == STEP  # the reflex's tick; the PD at 10 ms inside
    loop = read_model_description(str(fmus["loop", fmi]))
    assert not [v for v in loop.modelVariables if v.causality == "input"]  # a closed system
    assert float(loop.defaultExperiment.stopTime) == 1.0


@pytest.mark.parametrize("fmi", [2, 3])
def test_the_controller_fmu_with_the_plant_fmu_is_the_native_regrasp(fmus, fmi, native_regrasp, tmp_path):
    via = blocks.simulate(two_fmus(tmp_path, fmus["plant", fmi], fmus["ctrl", fmi]))
    assert via.complete
    for signal in COMPARED:
        np.testing.assert_array_equal(via[signal][0], native_regrasp[signal][0])
        np.testing.assert_array_equal(via[signal][1], native_regrasp[signal][1], err_msg=signal)


@pytest.mark.parametrize("fmi", [2, 3])
def test_the_closed_loop_fmu_run_by_fmpy_is_the_native_regrasp(fmus, fmi, native_regrasp, tmp_path):
    wanted = {signal: names(signal, native_regrasp[signal][1].shape[1]) for signal in COMPARED}
    result = simulate_fmu(extract(str(fmus["loop", fmi]), tmp_path / "loop"), output_interval=STEP,
                          output=[n for group in wanted.values() for n in group])
    for signal, columns in wanted.items():
        t, values = native_regrasp[signal]
        np.testing.assert_allclose(result["time"], t, rtol=0, atol=1e-12)  # fmpy sums its steps
        np.testing.assert_array_equal(np.column_stack([result[c] for c in columns]), values, err_msg=signal)


def test_a_c_host_without_python_runs_the_closed_loop_as_natively(fmus, c_host, native_regrasp, tmp_path):
    path = fmus["loop", 2]
    md = read_model_description(str(path))
    folder = Path(extract(str(path), tmp_path))
    library = next(folder.glob(f"binaries/*/{md.coSimulation.modelIdentifier}.so"))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    columns = names("plant.q", 9) + names("plant.obj", 3)
    done = subprocess.run([str(c_host), str(library), md.guid, (folder / "resources").as_uri(), repr(STEP), "1000",
                           ",".join(str(vr[c]) for c in columns)],
                          capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"}, timeout=120)
    assert done.returncode == 0, done.stderr
    rows = np.array([[float(x) for x in line.split()] for line in done.stdout.splitlines()])
    np.testing.assert_allclose(rows[:, 0], native_regrasp["plant.q"][0], rtol=0, atol=1e-12)  # the host sums
    np.testing.assert_array_equal(rows[:, 1:10], native_regrasp["plant.q"][1])
    np.testing.assert_array_equal(rows[:, 10:], native_regrasp["plant.obj"][1])


def test_a_parameter_and_what_derives_from_it_follow_as_in_a_native_run(fmus, tmp_path):
    """plant.object.mass alone: the plant's inertia follows, and so do the controller's and
    the support's models of the hand, as when a diagram sets it."""
    native = blocks.simulate(blocks.load_diagram(REGRASP, overrides={"plant.object.mass": 0.4}), t_end=0.3)
    obj = names("plant.obj", 3)
    result = simulate_fmu(extract(str(fmus["loop", 3]), tmp_path / "loop"), stop_time=0.3, output_interval=STEP,
                          output=obj, start_values={"plant.object.mass": 0.4})
    np.testing.assert_array_equal(np.column_stack([result[c] for c in obj]), native["plant.obj"][1])


@pytest.mark.parametrize("fmi", [2, 3])
def test_an_invalid_controller_parameter_is_a_logged_error_as_the_diagram_says(fmus, fmi, tmp_path):
    said = "parameter 'ki' must be a positive number, got -1.0"
    with pytest.raises(blocks.DiagramError, match=said):
        blocks.load_diagram(REGRASP, overrides={"ctrl.reflex.ki": -1.0})
    slave = Slave(fmus["ctrl", fmi], tmp_path)
    try:
        slave.set_named({"ctrl.reflex.ki": -1.0})
        with pytest.raises(Exception, match="ExitInitializationMode"):
            slave.initialize()
        assert slave.errors() == [f"invalid parameter: block 'ctrl.reflex' (GraspReflex): {said}"]
    finally:
        slave.close()


LIBCOSIM_MISSING = ("libcosimpy (libcosim's Python binding) is not installed: the test extra installs it on "
                    "Linux x86_64 where PyPI has a wheel for this Python (pip install -e '.[test]')")


def libcosim_run(plant: Path, ctrl: Path, n_steps: int) -> np.ndarray:
    """The plant FMU and the controller FMU connected in libcosim (its fixed-step
    algorithm, 1 ms): the plant's q after each step."""
    try:
        from libcosimpy.CosimExecution import CosimExecution
        from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
        from libcosimpy.CosimObserver import CosimObserver
        from libcosimpy.CosimSlave import CosimLocalSlave
    except ImportError:
        pytest.skip(LIBCOSIM_MISSING)
    log_output_level(CosimLogLevel.WARNING)
    described = {which: read_model_description(str(path)) for which, path in (("plant", plant), ("ctrl", ctrl))}
    vr = {which: {v.name: v.valueReference for v in md.modelVariables} for which, md in described.items()}
    execution = CosimExecution.from_step_size(step_size=int(round(STEP * 1e9)))
    index = {which: execution.add_local_slave(CosimLocalSlave(fmu_path=str(path), instance_name=which))
             for which, path in (("plant", plant), ("ctrl", ctrl))}
    for v in described["ctrl"].modelVariables:
        if v.causality == "input":
            execution.connect_real_variables(index["plant"], vr["plant"][v.name], index["ctrl"], v.valueReference)
        elif v.causality == "output":
            execution.connect_real_variables(index["ctrl"], v.valueReference, index["plant"], vr["plant"][v.name])
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    q = [vr["plant"][n] for n in names("q", 9)]
    rows = []
    for _ in range(n_steps):
        assert execution.step()
        rows.append(observer.last_real_values(index["plant"], q))
    return np.array(rows)


def test_libcosim_runs_the_controller_fmu_with_the_plant_fmu_as_blocks_does(fmus, tmp_path):
    """libcosim's fixed-step algorithm is Jacobi: every FMU steps on the others' outputs of
    the last communication point, so the torques reach the plant one step (1 ms) later than
    in the native diagram, where the controller reads the plant's outputs of the same tick.
    Its run is the blocks run of the same two FMUs exchanged the same way ('feedthrough:
    false' on the controller)."""
    rows = libcosim_run(fmus["plant", 2], fmus["ctrl", 2], 1000)
    jacobi = blocks.simulate(two_fmus(tmp_path, fmus["plant", 2], fmus["ctrl", 2], jacobi=True))
    t, q = jacobi["plant.q"]
    np.testing.assert_allclose(rows, q[1:], rtol=1e-9, atol=1e-12)


def test_the_cli_exports_the_controller_and_refuses_a_hand_file_with_a_diagram(tmp_path, capsys):
    from hierhand import cli

    assert cli.main(["fmu", "export", str(REPO / "diagrams" / "controller.yaml"), "--fmi", "3",
                     "--set", "reflex.ki=40", "-o", str(tmp_path)]) == 0
    written = tmp_path / "hand-controller_fmi3.fmu"
    assert capsys.readouterr().out.strip() == f"wrote {written}"
    md = read_model_description(str(written))
    assert md.fmiVersion == "3.0"
    assert next(v for v in md.modelVariables if v.name == "reflex.ki").start == "40.0"
    assert cli.main(["fmu", "export", str(REPO / "diagrams" / "controller.yaml"), "--hand", "h.yaml"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--hand is for the plant export" in err[0], err
