"""The re-grasp exported as an SSP (hierhand ssp export diagrams/regrasp.yaml): the plant,
the controller subsystem and the object's support each a component whose FMU the
diagram-FMU exporter writes. Run back by blocks it is the native re-grasp to the last bit
(the controller's outputs read after its inputs are set, as its ModelStructure declares
them dependent, and as its blocks:Stepping annotation asks: without the annotation too);
libcosim and ecos, whose fixed-step algorithms step every FMU on the others' outputs of the
last communication point, run it as blocks runs it with 'feedthrough: false' on the
controller (ecos with every component at the 1 ms base step: the support's 10 ms FMU holds
between its hits)."""

from __future__ import annotations

import ctypes
import os
import shutil
import sys
import zipfile
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

import blocks
from blocks.ssp import export_ssp
from tests.blocks.ssp.conftest import schema_errors

REPO = Path(__file__).resolve().parents[2]
REGRASP = REPO / "diagrams" / "regrasp.yaml"
COMPARED = ("plant.q", "plant.obj", "plant.fn", "plant.contact")
STEPPING = '<ssc:Annotation type="org.hierhand.blocks">'


@pytest.fixture(scope="module")
def regrasp_ssp(tmp_path_factory):
    """The re-grasp's SSP and its unpacked folder."""
    folder = tmp_path_factory.mktemp("regrasp_ssp")
    path = export_ssp(blocks.load_diagram(REGRASP), folder / "regrasp.ssp")
    with zipfile.ZipFile(path) as zf:
        zf.extractall(folder / "unpacked")
    return path, folder / "unpacked"


def unannotated_copy(unpacked: Path, folder: Path) -> Path:
    """The SSP's folder without the blocks:Stepping annotations, as another tool writes it."""
    target = folder / "unannotated"
    (target / "resources").mkdir(parents=True)
    for fmu in (unpacked / "resources").iterdir():
        shutil.copy(fmu, target / "resources" / fmu.name)
    text = (unpacked / "SystemStructure.ssd").read_text(encoding="utf-8")
    start = text.index(STEPPING)
    end = text.index("</ssc:Annotation>", start) + len("</ssc:Annotation>")
    (target / "SystemStructure.ssd").write_text(text[:start] + text[end:], encoding="utf-8")
    return target


@pytest.fixture(scope="module")
def jacobi_regrasp(regrasp_ssp, tmp_path_factory):
    """blocks' run of the re-grasp SSP with the controller read on the outputs of the last
    communication point ('feedthrough: false'), as libcosim and ecos step it."""
    without = blocks.load_diagram(unannotated_copy(regrasp_ssp[1], tmp_path_factory.mktemp("jacobi")),
                                  overrides={"ctrl.feedthrough": False})
    assert not any(s.block.has_feedthrough() for s in without.blocks.values())
    return blocks.simulate(without)


def test_the_regrasp_leaves_as_three_components_with_units_and_a_valid_ssd(regrasp_ssp):
    path, unpacked = regrasp_ssp
    assert schema_errors(unpacked / "SystemStructure.ssd") == []
    assert sorted(p.name for p in (unpacked / "resources").iterdir()) == ["ctrl.fmu", "plant.fmu", "support.fmu"]
    back = blocks.load_diagram(path)
    assert {n: (s.period, s.params.get("feedthrough", False)) for n, s in back.blocks.items()} == {
        "plant": (Fraction(1, 1000), False), "ctrl": (Fraction(1, 1000), True), "support": (Fraction(1, 100), False)}
    assert back.port_units("ctrl", "tau") == "N m" and back.port_units("plant", "q") == "rad"
    assert back.port_units("plant", "f_ext") == ["N", "N", "N m"]  # element connectors of different units
    ssd = (unpacked / "SystemStructure.ssd").read_text(encoding="utf-8")
    assert '<ssc:Unit name="N m">' in ssd and 'kg="1" m="2" s="-2"' in ssd
    ctrl = read_model_description(str(unpacked / "resources" / "ctrl.fmu"))
    assert {"reflex.ki", "suppress.S_b[4]", "suppress.time_constant"} <= {v.name for v in ctrl.modelVariables if v.causality == "parameter"}
    declared = {v.name: v for v in ctrl.modelVariables}
    assert {v.variability for v in ctrl.modelVariables if v.causality == "output"} == {"discrete"}  # sampled torques
    assert (declared["reflex.margin"].min, declared["reflex.margin"].max) == ("0.0", "1.0")  # the reflex's range
    assert (declared["suppress.S_b[4]"].min, declared["suppress.S_b[4]"].max) == (None, None)  # any number
    plant = read_model_description(str(unpacked / "resources" / "plant.fmu"))
    assert {v.variability for v in plant.modelVariables if v.causality == "output"} == {"continuous"}
    assert validate_fmu(str(unpacked / "resources" / "ctrl.fmu")) == []


def test_the_regrasp_ssp_run_back_is_the_native_regrasp(regrasp_ssp, native_regrasp):
    via = blocks.simulate(blocks.load_diagram(regrasp_ssp[0]))
    assert via.complete
    for signal in COMPARED:
        np.testing.assert_array_equal(via[signal][0], native_regrasp[signal][0])
        np.testing.assert_array_equal(via[signal][1], native_regrasp[signal][1], err_msg=signal)


def test_a_component_parameter_set_on_the_ssp_is_the_native_override(regrasp_ssp):
    key = {"ctrl.reflex.ki": 40.0, "ctrl.suppress.time_constant": 0.03}
    native = blocks.simulate(blocks.load_diagram(REGRASP, overrides=key), t_end=0.3)
    via = blocks.simulate(blocks.load_diagram(regrasp_ssp[0], overrides=key), t_end=0.3)
    np.testing.assert_array_equal(via["plant.q"][1], native["plant.q"][1])
    assert not np.array_equal(via["plant.q"][1], blocks.simulate(blocks.load_diagram(regrasp_ssp[0]),
                                                                 t_end=0.3)["plant.q"][1])


def test_without_the_annotations_the_regrasp_ssp_runs_in_the_order_the_fmus_declare(regrasp_ssp, tmp_path):
    """Another tool's SSP carries no blocks:Stepping: the controller's declared dependencies
    order the exchange all the same, so the run is the native re-grasp."""
    native = blocks.simulate(blocks.load_diagram(REGRASP), t_end=0.3)
    without = blocks.load_diagram(unannotated_copy(regrasp_ssp[1], tmp_path))
    assert without.blocks["ctrl"].block.has_feedthrough()
    via = blocks.simulate(without, t_end=0.3)
    np.testing.assert_array_equal(via["plant.q"][1], native["plant.q"][1])


def test_libcosim_runs_the_regrasp_ssp_as_blocks_does_without_feedthrough(regrasp_ssp, native_regrasp,
                                                                          jacobi_regrasp):
    """libcosim's fixed-step algorithm steps every due FMU at once and only then hands the
    outputs over: the controller's torques reach the plant one step (1 ms) later than in
    the native diagram, where the controller reads the plant's outputs of the same tick."""
    try:
        from libcosimpy.CosimExecution import CosimExecution
        from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
        from libcosimpy.CosimObserver import CosimObserver
    except ImportError:
        pytest.skip("libcosimpy (libcosim's Python binding) is not installed: the test extra installs it on Linux "
                    "x86_64 where PyPI has a wheel for this Python (pip install -e '.[test]')")
    path, unpacked = regrasp_ssp
    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_ssp_file(str(path))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    plant = execution.slave_index_from_instance_name("plant")
    md = read_model_description(str(unpacked / "resources" / "plant.fmu"))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    q = [vr[f"q[{i}]"] for i in range(1, 10)]
    rows = []
    for _ in range(1000):
        assert execution.step()
        rows.append(observer.last_real_values(plant, q))
    np.testing.assert_allclose(np.array(rows), jacobi_regrasp["plant.q"][1][1:], rtol=1e-9, atol=1e-12)
    assert np.abs(np.array(rows) - native_regrasp["plant.q"][1][1:]).max() > 1e-4  # the lag shows


def ecospy():
    """The ecospy package (ecos, a co-simulation engine whose wheel bundles its binaries),
    its TBB library loaded first: the engine needs libtbb.so.12, which the test extra's
    ``tbb`` wheel puts in the environment's lib folder, where the loader does not look."""
    for library in ("libtbb.so.12", os.path.join(sys.prefix, "lib", "libtbb.so.12")):
        try:
            ctypes.CDLL(library, mode=ctypes.RTLD_GLOBAL)
            break
        except OSError:
            continue
    try:
        import ecospy as module
    except (ImportError, OSError) as exc:
        pytest.skip(f"ecospy (ecos's Python package) cannot be loaded ({exc}): the test extra installs it with "
                    "tbb on Linux x86_64 (pip install -e '.[test]')")
    return module


def test_ecos_runs_the_regrasp_ssp_as_blocks_does_without_feedthrough(regrasp_ssp, native_regrasp, jacobi_regrasp):
    """ecos reads no step annotation of this SSP (the default export keeps them out of the
    components, where OMSimulator refuses them) and steps every component at the 1 ms it
    is given, Jacobi-fashion: the same run as blocks' without feedthrough, to the last bit."""
    ecos = ecospy()
    ecos.EcosLib.set_log_level("warn")
    simulation = ecos.EcosSimulation(step_size=1e-3, ssp_path=str(regrasp_ssp[0]))
    try:
        simulation.init()
        rows = []
        for _ in range(1000):
            simulation.step()
            rows.append([simulation.get_real(f"plant::q[{i}]") for i in range(1, 10)])
    finally:
        simulation.terminate()
    np.testing.assert_array_equal(np.array(rows), jacobi_regrasp["plant.q"][1][1:])
    assert np.abs(np.array(rows) - native_regrasp["plant.q"][1][1:]).max() > 1e-4  # the lag shows
