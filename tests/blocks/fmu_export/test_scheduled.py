"""Diagrams exported for FMI 3 scheduled execution (export_fmu(..., scheduled=True)),
run by a scheduler written on FMPy's low-level API (``scheduler.Scheduler``).

One constant periodic input clock per rate, exact (``intervalCounter / resolution``),
rate-monotonic priorities; the modelDescription passes ``fmpy validate`` and the FMI 3
schema. Activated on the tick grid in priority order, the partitions give the native run's
samples (to round-off where a native run advances a state-space block over a span in closed
form, which a partition steps hit by hit); activations out of order are refused with a
logged error; FMU states rewind a scheduled run exactly.
"""

from __future__ import annotations

import shutil
import subprocess
import zipfile
from fractions import Fraction
from pathlib import Path

import fmpy
import numpy as np
import pytest
import yaml
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree

import blocks
from blocks import DiagramError, loads_diagram
from blocks.fmu_export import export_fmu

from ..test_diagram_fuzz import FUZZ_SETTINGS, wired_document
from .scheduler import Scheduler
from .slave import run

REPO = Path(__file__).resolve().parents[3]
TOY = REPO / "diagrams" / "toy.yaml"
SCHEMA = Path(fmpy.__file__).parent / "schema" / "fmi3" / "fmi3ModelDescription.xsd"


@pytest.fixture(scope="module")
def toy_se(tmp_path_factory):
    return export_fmu(blocks.load_diagram(TOY), tmp_path_factory.mktemp("se") / "toy_se.fmu", 3, scheduled=True)


def samples(native, signal: str, base: Fraction, times: list[Fraction], rows: np.ndarray):
    """The native samples of ``signal`` and the scheduled run's rows at the same instants."""
    t, values = native[signal]
    at = {round(float(x) / base): i for i, x in enumerate(times)}
    ticks = [round(x / float(base)) for x in t]
    kept = [k for k, tick in enumerate(ticks) if tick in at]
    return values[kept].reshape(len(kept), -1), rows[[at[ticks[k]] for k in kept]]


def test_the_toy_declares_exact_clocks_and_passes_validation_and_the_schema(toy_se):
    assert validate_fmu(str(toy_se)) == []
    with zipfile.ZipFile(toy_se) as archive:
        text = archive.read("modelDescription.xml")
    schema = etree.XMLSchema(file=str(SCHEMA))
    assert schema.validate(etree.fromstring(text)), schema.error_log
    root = etree.fromstring(text)
    assert root.find("ScheduledExecution") is not None and root.find("CoSimulation") is None
    clocks = {c.get("name"): c for c in root.iter("Clock")}
    periods = {name: Fraction(int(c.get("intervalCounter")), int(c.get("resolution"))) for name, c in clocks.items()}
    assert periods == {"clock_100us": Fraction(1, 10000), "clock_1ms": Fraction(1, 1000),
                       "clock_10ms": Fraction(1, 100)}
    assert [clocks[n].get("priority") for n in ("clock_100us", "clock_1ms", "clock_10ms")] == ["0", "1", "2"]
    assert {c.get("intervalVariability") for c in clocks.values()} == {"constant"}
    output = next(v for v in root.iter("Float64") if v.get("name") == "plant.y")
    assert output.get("clocks") == clocks["clock_100us"].get("valueReference")  # the plant's rate


def test_the_toy_scheduled_gives_the_native_samples_and_locks_each_partition(toy_se, tmp_path):
    d = blocks.load_diagram(TOY)
    native = blocks.simulate(d)
    s = Scheduler(toy_se, tmp_path / "run")
    try:
        times, rows = s.run(Fraction(1, 10), ["plant.y"])
    finally:
        s.close()
    assert len(times) == 1001 and s.messages == []
    assert s.lock_calls == 1001 + 101 + 11 and s.locked == 0  # every activation locked, and unlocked
    mine, theirs = samples(native, "plant.y", Fraction(1, 10000), times, rows)
    assert len(mine) == 1001
    # the native run advances the plant between events in closed form; a partition steps it
    np.testing.assert_allclose(theirs, mine, rtol=1e-12, atol=1e-15)


def test_activations_out_of_order_are_refused_with_the_reason(toy_se, tmp_path):
    s = Scheduler(toy_se, tmp_path / "order")
    fast, middle, slow = (c.valueReference for c in s.clocks)
    try:
        s.fmu.enterInitializationMode()
        s.fmu.exitInitializationMode()
        with pytest.raises(FMICallException):
            s.fmu.activateModelPartition(middle, 0.0)  # before the 0.1 ms clock at t = 0
        assert "priority order" in s.messages[-1][1]
        s.fmu.activateModelPartition(fast, 0.0)
        s.fmu.activateModelPartition(middle, 0.0)
        with pytest.raises(FMICallException):
            s.fmu.activateModelPartition(fast, 1e-4)  # the 10 ms clock at t = 0 is missing
        s.fmu.activateModelPartition(slow, 0.0)
        with pytest.raises(FMICallException):
            s.fmu.activateModelPartition(fast, 2e-4)  # 0.1 ms was skipped
        with pytest.raises(FMICallException):
            s.fmu.activateModelPartition(fast, 1.5e-4)  # not a tick
        s.fmu.activateModelPartition(fast, 1e-4)
    finally:
        s.close()
    assert [status for status, _ in s.messages] == [3] * 4


def test_fmu_states_rewind_a_scheduled_run(toy_se, tmp_path):
    s = Scheduler(toy_se, tmp_path / "state")
    fast = s.clocks[0].valueReference
    y = [s.vr["plant.y"]]
    instants = s.instants(Fraction(3, 100))
    try:
        s.fmu.enterInitializationMode()
        s.fmu.exitInitializationMode()

        def through(part):
            out = []
            for t, clocks in part:
                for c in clocks:
                    s.fmu.activateModelPartition(c.valueReference, float(t))
                out.append(s.fmu.getFloat64(y)[0])
            return out

        through(instants[:150])
        state = s.fmu.getFMUState()
        copy = s.fmu.deserializeFMUState(s.fmu.serializeFMUState(state))
        first = through(instants[150:])
        s.fmu.setFMUState(state)
        again = through(instants[150:])
        s.fmu.setFMUState(copy)
        serialized = through(instants[150:])
        with pytest.raises(FMICallException):  # the state's position holds: 0.1 ms at t=0.015 s is done
            s.fmu.activateModelPartition(fast, float(instants[149][0]))
    finally:
        s.close()
    assert first == again == serialized and len(set(first)) > 1


@settings(max_examples=40, suppress_health_check=[*FUZZ_SETTINGS.get("suppress_health_check", ()),
                                                  HealthCheck.function_scoped_fixture],
          derandomize=True)
@given(doc=wired_document(), ticks=st.integers(min_value=5, max_value=60))
def test_random_library_diagrams_leave_both_ways_with_the_native_samples(doc, ticks, tmp_path):
    try:
        d = loads_diagram(yaml.safe_dump(doc, sort_keys=False), filename="random.yaml", base_dir=tmp_path)
        base = blocks.build_schedule(d, None).base_tick
        native = blocks.simulate(d, t_end=ticks * base)
        folder = tmp_path / f"random{abs(hash(yaml.safe_dump(doc)))}"
        scheduled = export_fmu(d, folder / "se.fmu", 3, scheduled=True)
    except DiagramError:
        return
    if not d.log or not native.complete:
        return
    cosim = export_fmu(d, folder / "cs.fmu", 3)
    s = Scheduler(scheduled, folder / "se")
    names = [v.name for v in s.md.modelVariables if v.causality == "output"]
    try:
        times, rows = s.run(ticks * base, names)
    finally:
        s.close()
    assert [m for m in s.messages if m[0] >= 2] == []
    grid = Fraction(fmpy.read_model_description(str(cosim)).defaultExperiment.stepSize).limit_denominator(10**9)
    steps = int(ticks * base / grid)  # the co-simulation FMU's grid: the periods it advances over
    stepped = run(cosim, folder / "cs", names, float(grid), steps)
    cs_times = [k * grid for k in range(steps + 1)]
    column = 0
    for e in d.log:
        width = d.width(e.signal)
        scale = 1e-12 * max(1.0, float(np.abs(native[e.signal][1]).max(initial=0.0)))
        for when, got in ((times, rows), (cs_times, stepped)):
            mine, theirs = samples(native, e.signal, base, when, got[:, column:column + width])
            np.testing.assert_allclose(theirs, mine, rtol=1e-12, atol=scale, err_msg=e.signal)
        column += width


def test_a_diagram_without_rates_is_refused_in_one_line(tmp_path):
    d = loads_diagram(yaml.safe_dump({"name": "still", "blocks": {"c": {"type": "Constant", "params": {"value": 2}},
                                                                   "g": {"type": "Gain", "params": {"k": 3}}},
                                      "connections": ["c.y -> g.u"], "log": ["g.y"]}), filename="still.yaml",
                      base_dir=tmp_path)
    with pytest.raises(DiagramError) as caught:
        export_fmu(d, tmp_path / "still.fmu", 3, scheduled=True)
    assert len(caught.value.issues) == 1 and "no block with a period" in str(caught.value)


def test_a_scheduled_fmu_rebuilt_from_its_sources_runs_the_same(toy_se, tmp_path):
    """As an importer on another platform would: drop the binary, compile the C files
    buildDescription.xml lists (against the FMI headers, with libm), schedule it. (fmpy's
    own builder knows co-simulation and model exchange only.)"""
    from fmpy import extract

    compiler = shutil.which("cc") or shutil.which("gcc")
    if compiler is None:
        pytest.skip("no C compiler")
    unzipped = Path(extract(str(toy_se), str(tmp_path / "unzipped")))
    identifier = etree.parse(str(unzipped / "modelDescription.xml")).find("ScheduledExecution").get("modelIdentifier")
    build = etree.parse(str(unzipped / "sources" / "buildDescription.xml"))
    sources = [str(unzipped / "sources" / f.get("name")) for f in build.iter("SourceFile")]
    library = next((unzipped / "binaries").glob(f"*/{identifier}.so"))
    library.unlink()
    headers = Path(fmpy.__file__).parent / "c-code"
    subprocess.run([compiler, "-std=c99", "-O1", "-ffp-contract=off", "-shared", "-fPIC", f"-I{headers}",
                    f"-I{unzipped / 'sources'}", *sources, "-o", str(library), "-lm"], check=True, timeout=300)
    rebuilt = tmp_path / "rebuilt.fmu"
    with zipfile.ZipFile(rebuilt, "w") as archive:
        for f in unzipped.rglob("*"):
            if f.is_file():
                archive.write(f, f.relative_to(unzipped).as_posix())
    results = []
    for path, where in ((toy_se, "original"), (rebuilt, "rebuilt")):
        s = Scheduler(path, tmp_path / where)
        try:
            results.append(s.run(Fraction(1, 100), ["plant.y"])[1])
        finally:
            s.close()
    np.testing.assert_array_equal(results[0], results[1])
