"""Diagrams of FMU blocks exported as SSPs (``blocks.ssp.writer``): the SSD validates against
the SSP schemas, runs back through the importer and in libcosim as the native diagram."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from fractions import Fraction

import numpy as np
import pytest

from blocks import DiagramBuilder, DiagramError, load_diagram, simulate
from blocks.ssp import export_ssp

from .conftest import schema_errors


def multirate(fmu, delay: int = 0, extra: bool = False):
    """A fast first-order FMU (100 ms) driving a slow one (200 ms) by an element of its
    vector output, and the slow one's output back into the fast one; ``extra``: a Sum of
    the slow one's output and a 300 ms hold of the fast one's, inheriting their rates
    (hits at 0, 0.2, 0.3, 0.4, 0.6 s: not evenly spaced)."""
    b = DiagramBuilder("multirate", t_end="2 s")
    b.add("fast", "FMU", period="100 ms", params={"path": str(fmu), "start_values": {"x0": 1.0, "scale": 2}})
    b.add("slow", "FMU", period="200 ms", params={"path": str(fmu), "start_values": {"a": 0.9, "b": 0.1}})
    if extra:
        b.add("gain", "Gain", params={"k": 2.0})
        b.connect("fast.y", "gain.u")
        b.add("every", "ZeroOrderHold", period="300 ms")
        b.connect("fast.y", "every.u")
        b.add("sum", "Sum", params={"signs": "++"})
        b.connect("slow.y", "sum.u0")
        b.connect("every.y", "sum.u1")
    b.connect("fast.z[1]", "slow.u", delay=delay)
    b.connect("slow.y", "fast.u")
    b.log_all()
    return b.build()


def export_unpacked(first_order, tmp_path, annotations: str = "system"):
    """The multirate diagram, its SSP (``annotations`` as export_ssp takes it) and the SSP's folder."""
    fmu = tmp_path / "fo.fmu"
    fmu.write_bytes(first_order)
    diagram = multirate(fmu)
    path = export_ssp(diagram, tmp_path / f"multirate-{annotations}.ssp", annotations=annotations)
    folder = tmp_path / f"unpacked-{annotations}"
    with zipfile.ZipFile(path) as zf:
        zf.extractall(folder)
    return diagram, path, folder


@pytest.fixture
def exported(first_order, tmp_path):
    return export_unpacked(first_order, tmp_path)


def test_tool_annotations_go_where_omsimulator_reads_them_or_nowhere(first_order, tmp_path):
    """OMSimulator 3.0 refuses an ssd:Annotations inside an ssd:Component (the schema allows
    one) and reads only the first ssc:Annotation of a system: by default the components
    carry none, the system's first is OMSimulator's; each SSD validates and reads back with
    the components' steps as the diagram's periods where blocks' annotations are written."""
    from lxml import etree

    from blocks.ssp.xml import q

    periods = {}
    for annotations in ("system", "components", "none"):
        diagram, path, folder = export_unpacked(first_order, tmp_path, annotations)
        assert schema_errors(folder / "SystemStructure.ssd") == []
        root = etree.parse(str(folder / "SystemStructure.ssd")).getroot()
        in_components = root.findall(f".//{q('ssd', 'Component')}/{q('ssd', 'Annotations')}")
        kinds = [a.get("type") for a in root.iter(q("ssc", "Annotation"))]
        if annotations == "system":
            assert in_components == [] and kinds[0] == "org.openmodelica" and "org.hierhand.blocks" in kinds
        elif annotations == "components":
            assert len(in_components) == 2 and "com.opensimulationplatform" in kinds
        else:
            assert kinds == []
        back = load_diagram(path, step="100 ms")
        periods[annotations] = {n: b.period for n, b in back.blocks.items()}
    assert periods["system"] == periods["components"] == {n: diagram.blocks[n].period for n in ("fast", "slow")}
    assert periods["none"] == {"fast": Fraction(1, 10), "slow": Fraction(1, 10)}  # no step given but --step


def test_the_exported_ssd_validates_and_runs_back_as_the_native_diagram(exported):
    diagram, path, folder = exported
    assert schema_errors(folder / "SystemStructure.ssd") == []
    assert sorted(p.name for p in (folder / "resources").iterdir()) == ["fo.fmu"]
    back = load_diagram(path)
    assert {n: b.period for n, b in back.blocks.items()} == {"fast": diagram.blocks["fast"].period,
                                                              "slow": diagram.blocks["slow"].period}
    native, again = simulate(diagram), simulate(back)
    for signal in ("fast.y", "fast.z", "slow.y"):
        np.testing.assert_array_equal(native[signal][0], again[signal][0])
        np.testing.assert_array_equal(native[signal][1], again[signal][1])


def test_libcosim_runs_the_exported_ssp_as_the_native_diagram(first_order, tmp_path):
    """With the step hints libcosim reads in each component (``annotations="components"``)."""
    cosim = pytest.importorskip("libcosimpy.CosimExecution", reason="libcosimpy (the test extra's libcosim) is not "
                                "installed; it has wheels for Linux x86-64 only")
    from libcosimpy.CosimObserver import CosimObserver

    diagram, path, _ = export_unpacked(first_order, tmp_path, "components")
    execution = cosim.CosimExecution.from_ssp_file(str(path))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    fast, slow = (execution.slave_index_from_instance_name(n) for n in ("fast", "slow"))
    seen = {"fast": [], "slow": []}
    for _ in range(20):
        execution.step()
        seen["fast"].append(observer.last_real_values(fast, [7])[0])
        seen["slow"].append(observer.last_real_values(slow, [7])[0])
    native = simulate(diagram)
    np.testing.assert_allclose(seen["fast"], native["fast.y"][1][1:21, 0], rtol=0, atol=1e-9)
    slow_native = native["slow.y"][1][1:, 0]  # at 0.2, 0.4, ... s; libcosim reports it at every base step
    np.testing.assert_allclose(seen["slow"][1::2], slow_native[:10], rtol=0, atol=1e-9)


def test_library_blocks_become_fmus_of_their_own_and_run_back_as_the_native_diagram(first_order, tmp_path):
    """The Gain inherits the fast FMU's 100 ms, the ZeroOrderHold has 300 ms: each is a
    component whose FMU the exporter writes; the Gain's outputs feed through as natively."""
    fmu = tmp_path / "fo.fmu"
    fmu.write_bytes(first_order)
    b = DiagramBuilder("with-gain", t_end="2 s")
    b.add("fast", "FMU", period="100 ms", params={"path": str(fmu), "start_values": {"x0": 1.0}})
    b.add("gain", "Gain", params={"k": 2.0})
    b.add("hold", "ZeroOrderHold", period="300 ms")
    b.connect("fast.y", "gain.u")
    b.connect("gain.y", "hold.u")
    b.log_all()
    diagram = b.build()
    path = export_ssp(diagram, tmp_path / "g.ssp")
    back = load_diagram(path)
    assert {n: (s.type_name, s.period) for n, s in back.blocks.items()} == {
        "fast": ("FMU", Fraction(1, 10)), "gain": ("FMU", Fraction(1, 10)), "hold": ("FMU", Fraction(3, 10))}
    assert back.blocks["gain"].params["feedthrough"] is True
    native, again = simulate(diagram), simulate(back)
    for signal in ("gain.y", "hold.y"):
        np.testing.assert_array_equal(native[signal][0], again[signal][0])
        np.testing.assert_array_equal(native[signal][1], again[signal][1], err_msg=signal)


def test_an_unevenly_firing_block_and_a_delayed_connection_are_one_error_each(first_order, tmp_path):
    fmu = tmp_path / "fo.fmu"
    fmu.write_bytes(first_order)
    with pytest.raises(DiagramError) as caught:
        export_ssp(multirate(fmu, delay=1, extra=True), tmp_path / "x.ssp")
    messages = [i.message for i in caught.value.issues]
    assert len(messages) == 2, messages
    assert messages[0] == ("block 'sum' (Sum) cannot become an SSP component: it fires when the blocks feeding it "
                           "do, not at one period")
    assert "a delay has no place in an SSD" in messages[1]
    assert not (tmp_path / "x.ssp").exists()


def test_the_command_line_exports_and_refuses_with_exit_code_2(first_order, tmp_path):
    (tmp_path / "fo.fmu").write_bytes(first_order)
    (tmp_path / "d.yaml").write_text(
        "name: pair\ntime: {t_end: 1 s}\nblocks:\n"
        "  a: {type: FMU, period: 100 ms, params: {path: fo.fmu}}\n"
        "  b: {type: FMU, period: 100 ms, params: {path: fo.fmu}}\n"
        "  g: {type: FMU, period: 100 ms, offset: 50 ms, params: {path: fo.fmu}}\n"
        "connections: [a.y -> b.u, a.y -> g.u]\n")
    out = tmp_path / "pair.ssp"
    bad = subprocess.run([sys.executable, "-m", "blocks", "ssp", "export", str(tmp_path / "d.yaml"), "-o", str(out)],
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and "d.yaml:6: block 'g': an offset (50 ms) has no place in an SSD" in bad.stderr
    assert "Traceback" not in bad.stderr
    (tmp_path / "d.yaml").write_text((tmp_path / "d.yaml").read_text().replace(", a.y -> g.u", "")
                                     .replace("  g: {type: FMU, period: 100 ms, offset: 50 ms, params: {path: fo.fmu}}\n", ""))
    good = subprocess.run([sys.executable, "-m", "blocks", "ssp", "export", str(tmp_path / "d.yaml"), "-o", str(out),
                           "--set", "a.x0=3", "--annotations", "none"], capture_output=True, text=True, timeout=120)
    assert good.returncode == 0, good.stderr
    assert load_diagram(out, step="100 ms").blocks["a"].params["start_values"] == {"x0": 3}
    with zipfile.ZipFile(out) as zf:
        assert b"<ssd:Annotations" not in zf.read("SystemStructure.ssd")  # left out on request


def test_a_subsystem_the_fmu_exporter_refuses_is_one_error_at_its_block(first_order, tmp_path):
    fmu = tmp_path / "fo.fmu"
    fmu.write_bytes(first_order)
    inner = DiagramBuilder("inner")
    inner.add("f", "FMU", period="100 ms", params={"path": str(fmu)})
    inner.output("y", "f.y")
    b = DiagramBuilder("outer", t_end="1 s")
    b.add_subsystem("sub", inner)
    b.log("sub.f.y")
    with pytest.raises(DiagramError) as caught:
        export_ssp(b.build(), tmp_path / "x.ssp")
    [issue] = caught.value.issues
    assert issue.message == ("subsystem 'sub' cannot become an SSP component: block 'f' (FMU) cannot be exported: "
                             "the FMU an FMU block runs is not carried inside an exported FMU")
    assert issue.file == __file__ and not (tmp_path / "x.ssp").exists()
