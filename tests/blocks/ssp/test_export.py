"""Diagrams of FMU blocks exported as SSPs (``blocks.ssp.writer``): the SSD validates against
the SSP schemas, runs back through the importer and in libcosim as the native diagram."""

from __future__ import annotations

import subprocess
import sys
import zipfile

import numpy as np
import pytest

from blocks import DiagramBuilder, DiagramError, load_diagram, simulate
from blocks.ssp import export_ssp

from .conftest import schema_errors


def multirate(fmu, delay: int = 0, extra: bool = False):
    """A fast first-order FMU (100 ms) driving a slow one (200 ms) by an element of its
    vector output, and the slow one's output back into the fast one."""
    b = DiagramBuilder("multirate", t_end="2 s")
    b.add("fast", "FMU", period="100 ms", params={"path": str(fmu), "start_values": {"x0": 1.0, "scale": 2}})
    b.add("slow", "FMU", period="200 ms", params={"path": str(fmu), "start_values": {"a": 0.9, "b": 0.1}})
    if extra:
        b.add("gain", "Gain", params={"k": 2.0})
        b.connect("fast.y", "gain.u")
    b.connect("fast.z[1]", "slow.u", delay=delay)
    b.connect("slow.y", "fast.u")
    b.log_all()
    return b.build()


@pytest.fixture
def exported(first_order, tmp_path):
    fmu = tmp_path / "fo.fmu"
    fmu.write_bytes(first_order)
    diagram = multirate(fmu)
    path = export_ssp(diagram, tmp_path / "multirate.ssp")
    folder = tmp_path / "unpacked"
    with zipfile.ZipFile(path) as zf:
        zf.extractall(folder)
    return diagram, path, folder


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


def test_libcosim_runs_the_exported_ssp_as_the_native_diagram(exported):
    cosim = pytest.importorskip("libcosimpy.CosimExecution", reason="libcosimpy (the test extra's libcosim) is not "
                                "installed; it has wheels for Linux x86-64 only")
    from libcosimpy.CosimObserver import CosimObserver

    diagram, path, _ = exported
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


def test_a_block_that_is_no_fmu_and_a_delayed_connection_are_one_error_each(first_order, tmp_path):
    fmu = tmp_path / "fo.fmu"
    fmu.write_bytes(first_order)
    with pytest.raises(DiagramError) as caught:
        export_ssp(multirate(fmu, delay=1, extra=True), tmp_path / "x.ssp")
    messages = [i.message for i in caught.value.issues]
    assert len(messages) == 2, messages
    assert "block 'gain' (Gain) cannot become an SSP component" in messages[0]
    assert "a delay has no place in an SSD" in messages[1]
    assert not (tmp_path / "x.ssp").exists()


def test_the_command_line_exports_and_refuses_with_exit_code_2(first_order, tmp_path):
    (tmp_path / "fo.fmu").write_bytes(first_order)
    (tmp_path / "d.yaml").write_text(
        "name: pair\ntime: {t_end: 1 s}\nblocks:\n"
        "  a: {type: FMU, period: 100 ms, params: {path: fo.fmu}}\n"
        "  b: {type: FMU, period: 100 ms, params: {path: fo.fmu}}\n"
        "  g: {type: Gain, params: {k: 2}}\n"
        "connections: [a.y -> b.u, a.y -> g.u]\n")
    out = tmp_path / "pair.ssp"
    bad = subprocess.run([sys.executable, "-m", "blocks", "ssp", "export", str(tmp_path / "d.yaml"), "-o", str(out)],
                         capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and "d.yaml:6: block 'g' (Gain) cannot become an SSP component" in bad.stderr
    assert "Traceback" not in bad.stderr
    (tmp_path / "d.yaml").write_text((tmp_path / "d.yaml").read_text().replace(", a.y -> g.u", "")
                                     .replace("  g: {type: Gain, params: {k: 2}}\n", ""))
    good = subprocess.run([sys.executable, "-m", "blocks", "ssp", "export", str(tmp_path / "d.yaml"), "-o", str(out),
                           "--set", "a.x0=3"], capture_output=True, text=True, timeout=120)
    assert good.returncode == 0, good.stderr
    assert load_diagram(out).blocks["a"].params["start_values"] == {"x0": 3}
