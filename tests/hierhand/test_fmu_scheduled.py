"""The re-grasp's hierarchical controller exported for FMI 3 scheduled execution.

Its two rates leave as two clocks, 1 ms (the reflex and the suppresser, priority 0) and
10 ms (the manipulation PD and the object's support, priority 1), with exact intervals.
A scheduler written in the test on FMPy's low-level ``FMU3ScheduledExecution`` API alone,
fed the plant's signals of the native re-grasp at each 1 ms tick, activates the partitions
on the rate grid in priority order: the controller's torques and the support's force are
the native run's, bit for bit.
"""

from __future__ import annotations

import shutil
import zipfile
from fractions import Fraction
from xml.etree import ElementTree as ET

import numpy as np
import pytest
import yaml
from fmpy.validation import validate_fmu

import blocks
from hierhand.fmu_export import export_diagram_fmu
from tests.blocks.fmu_export.scheduler import Scheduler

from .test_fmu_export_diagrams import COMPARED, PLANT_PORTS, REGRASP, REPO, regrasp_controller

MS = Fraction(1, 1000)


@pytest.fixture(scope="module")
def controller_se(tmp_path_factory):
    folder = tmp_path_factory.mktemp("controller_se")
    diagram = blocks.load_diagram(regrasp_controller(folder))
    return export_diagram_fmu(diagram, folder / "ctrl_se.fmu", 3, scheduled=True)


@pytest.fixture(scope="module")
def native_with_controller(tmp_path_factory):
    """The native re-grasp, logging the plant's signals at 1 ms and the controller's outputs."""
    folder = tmp_path_factory.mktemp("regrasp_logged")
    shutil.copy(REPO / "diagrams" / "controller.yaml", folder / "controller.yaml")
    doc = yaml.safe_load(REGRASP.read_text(encoding="utf-8"))
    doc["log"] = [{"signal": f"plant.{port}", "decimate": 10} for port in PLANT_PORTS]
    doc["log"] += ["ctrl.suppress.tau", "support.y"]
    path = folder / "regrasp.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return blocks.simulate(blocks.load_diagram(path))


def test_the_controller_declares_two_exact_clocks_and_clocked_variables(controller_se):
    assert validate_fmu(str(controller_se)) == []
    with zipfile.ZipFile(controller_se) as archive:
        root = ET.fromstring(archive.read("modelDescription.xml"))
    assert root.find("ScheduledExecution") is not None
    clocks = {c.get("name"): c for c in root.iter("Clock")}
    assert set(clocks) == {"clock_1ms", "clock_10ms"}
    fast, slow = clocks["clock_1ms"], clocks["clock_10ms"]
    assert Fraction(int(fast.get("intervalCounter")), int(fast.get("resolution"))) == Fraction(1, 1000)
    assert Fraction(int(slow.get("intervalCounter")), int(slow.get("resolution"))) == Fraction(1, 100)
    assert (fast.get("priority"), slow.get("priority")) == ("0", "1")  # rate-monotonic
    variables = {v.get("name"): v for v in root.find("ModelVariables")}
    assert variables["tau[1]"].get("clocks") == fast.get("valueReference")  # the suppresser's, at 1 ms
    assert variables["f_ext[1]"].get("clocks") == slow.get("valueReference")  # the support's, at 10 ms
    assert variables["qd[1]"].get("clocks") == slow.get("valueReference")  # read by the PD alone
    assert variables["tip[1]"].get("clocks") == fast.get("valueReference")  # read by the reflex alone
    assert variables["q[1]"].get("clocks") is None  # read at both rates


def test_an_fmpy_scheduler_fed_the_plant_reproduces_the_native_controller(controller_se, native_with_controller,
                                                                          tmp_path):
    native = native_with_controller
    s = Scheduler(controller_se, tmp_path / "run")
    columns = {port: [v.name for v in s.md.modelVariables
                      if v.causality == "input" and v.name.split("[")[0] == port] for port in PLANT_PORTS}

    def plant_signals(t: Fraction) -> dict[str, float]:
        row = int(t / MS)  # the plant's samples at each 1 ms tick, which the controller reads
        return {name: float(value) for port in PLANT_PORTS
                for name, value in zip(columns[port], native[f"plant.{port}"][1][row])}

    outputs = [f"tau[{i}]" for i in range(1, 10)] + [f"f_ext[{i}]" for i in range(1, 4)]
    try:
        times, rows = s.run(Fraction(1), outputs, plant_signals)
    finally:
        s.close()
    assert s.messages == [] and s.locked == 0 and s.lock_calls == 1001 + 101
    assert times == [k * MS for k in range(1001)]
    t, tau = native["ctrl.suppress.tau"]
    np.testing.assert_array_equal(np.array([float(x) for x in times]), t)
    np.testing.assert_array_equal(rows[:, :9], tau)
    t_f, force = native["support.y"]
    np.testing.assert_array_equal(rows[::10, 9:], force)
    assert np.abs(tau).max() > 0.01 and np.abs(force).max() > 0.1  # the torques and the support act


def test_the_cli_exports_scheduled_execution_and_refuses_it_for_fmi_2(tmp_path, capsys):
    from hierhand import cli

    assert cli.main(["fmu", "export", str(REPO / "diagrams" / "controller.yaml"), "--fmi", "3",
                     "--scheduled-execution", "-o", str(tmp_path)]) == 0
    written = tmp_path / "hand-controller_fmi3_se.fmu"
    assert capsys.readouterr().out.strip() == f"wrote {written}"
    with zipfile.ZipFile(written) as archive:
        assert "resources/clocks.bin" in archive.namelist()
        assert ET.fromstring(archive.read("modelDescription.xml")).find("ScheduledExecution") is not None
    assert cli.main(["fmu", "export", str(REPO / "diagrams" / "controller.yaml"), "--scheduled-execution"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--fmi 3" in err[0], err


def test_the_controller_imported_back_as_an_fmu_block_runs_the_native_regrasp(controller_se, native_regrasp,
                                                                              tmp_path):
    """The FMU block activates the controller's two clocks on their ticks (1 ms, and 10 ms
    after it at the instants they share), the native plant around it: the re-grasp to the bit."""
    doc = yaml.safe_load(REGRASP.read_text(encoding="utf-8"))
    doc["name"] = "regrasp-scheduled-controller"
    doc["blocks"] = {"plant": doc["blocks"]["plant"],
                     "ctrl": {"type": "FMU", "period": "1 ms", "params": {"path": str(controller_se)}}}
    doc["connections"] = [f"plant.{p} -> ctrl.{p}" for p in PLANT_PORTS] + ["ctrl.tau -> plant.tau",
                                                                            "ctrl.f_ext -> plant.f_ext"]
    doc["log"] = [{"signal": signal, "decimate": 10} for signal in COMPARED]  # the plant's rows at 1 ms
    path = tmp_path / "regrasp_se.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    diagram = blocks.load_diagram(path)
    assert diagram.blocks["ctrl"].block.interface == "scheduled execution"
    via = blocks.simulate(diagram)
    assert via.complete
    for signal in COMPARED:
        np.testing.assert_array_equal(via[signal][0], native_regrasp[signal][0])
        np.testing.assert_array_equal(via[signal][1], native_regrasp[signal][1], err_msg=signal)
