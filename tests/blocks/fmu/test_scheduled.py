"""Scheduled-execution FMUs (FMI 3.0) as FMU blocks.

A test FMU with the clock kinds of the Reference FMUs' ``Clocks`` model (sources/
clocks_fmi3.c, its modelDescription that model's): a constant clock every second, a
triggered clock driven from an input port's rising edges at 0, 1, 8 and 9 s, a countdown
clock the FMU asks for at 4 s, and an output clock. The block produces the ticks the
Reference FMU documents, the counters of each partition, and the output clock's ticks
where the total count reaches a multiple of 5.
"""

from __future__ import annotations

import zipfile

import numpy as np
import pytest

import blocks
from blocks import Block, DiagramBuilder, DiagramError
from blocks.fmu import FMU
from blocks.library import Constant

from .build import EXT, build_error, compile_library, zip_files

SOURCES_XML = "clocks_fmi3.xml"


@pytest.fixture(scope="module")
def clocks_fmu(tmp_path_factory):
    why = build_error()
    if why:
        pytest.skip(why)
    build = tmp_path_factory.mktemp("clocks")
    library = compile_library(build / f"Clocks3{EXT}", "clocks_fmi3.c", "fmi3_unsupported.c",
                              defines={"SCHEDULED_EXECUTION": "1", "NO_CO_SIMULATION": "1"})
    from .build import SOURCES

    return zip_files(build / "clocks.fmu", {"modelDescription.xml": (SOURCES / SOURCES_XML).read_text(),
                                            f"binaries/x86_64-linux/Clocks3{EXT}": library})


class Trigger(Block):
    """1 at the given times, 0 at the other hits."""

    def __init__(self, times):
        self.times = set(times)
        self.inputs, self.outputs = {}, {"y": 1}
        self.time_varying = True

    def output(self, t, state, inputs):
        return {"y": np.array([1.0 if round(t, 9) in self.times else 0.0])}


def clocks_diagram(path, t_end: str = "9.5 s") -> blocks.Diagram:
    b = DiagramBuilder("clocks", t_end=t_end)
    b.add("fmu", FMU(path), period="0.5 s")
    b.add("trigger", Trigger([0.0, 1.0, 8.0, 9.0]), period="0.5 s")
    b.add("input2", Constant(value=7))
    b.connect("trigger.y", "fmu.inClock2")
    b.connect("input2.y", "fmu.input2")
    for port in ("inClock1Ticks", "inClock2Ticks", "inClock3Ticks", "totalInClockTicks", "result2", "output3",
                 "outClock"):
        b.log(f"fmu.{port}")
    return b.build()


def test_the_clocks_of_the_reference_clocks_model_tick_as_documented(clocks_fmu):
    d = clocks_diagram(clocks_fmu)
    fmu = d.blocks["fmu"].block
    assert fmu.interface == "scheduled execution"
    assert "inClock2" in fmu.inputs and "outClock" in fmu.outputs and "inClock1" not in fmu.inputs
    r = blocks.simulate(d)
    assert r.complete
    t = r["fmu.inClock1Ticks"][0]
    np.testing.assert_array_equal(t, np.arange(20) * 0.5)
    at = {name: dict(zip(t, r[f"fmu.{name}"][1][:, 0])) for name in
          ("inClock1Ticks", "inClock2Ticks", "inClock3Ticks", "totalInClockTicks", "result2", "output3", "outClock")}
    seconds = np.arange(10.0)
    assert [at["inClock1Ticks"][s] for s in seconds] == list(range(1, 11))  # every second from 0 on
    assert [at["inClock2Ticks"][s] for s in seconds] == [1, 2, 2, 2, 2, 2, 2, 2, 3, 4]  # at 0, 1, 8 and 9 s
    assert [at["inClock3Ticks"][s] for s in seconds] == [0, 0, 0, 0, 1, 1, 1, 1, 1, 1]  # asked for at 4 s
    assert at["output3"][3.5] == 0 and at["output3"][4.0] == 1000
    assert at["totalInClockTicks"][9.5] == 15 and at["result2"][9.5] == 4 * 7  # input2 read at each inClock2
    assert [t for t, ticked in at["outClock"].items() if ticked] == [2.0, 6.0, 9.0]  # totals 5, 10, 15
    assert at["inClock1Ticks"][0.5] == at["inClock1Ticks"][0.0]  # held between ticks


def test_a_period_off_the_clock_grid_is_refused(clocks_fmu):
    b = DiagramBuilder("off", t_end="2 s")
    b.add("fmu", FMU(clocks_fmu), period="0.3 s")
    with pytest.raises(DiagramError, match="does not divide the interval 1 s"):
        b.build()


def test_scheduled_execution_in_a_process_of_its_own_is_refused(clocks_fmu):
    with pytest.raises(ValueError, match="drop 'isolation: process'"):
        FMU(clocks_fmu, isolation="process")


@pytest.mark.parametrize("attributes, why", [
    ('intervalCounter="1" resolution="0" supportsFraction="true"', "its intervalCounter is not a whole counter of a "
                                                                    "positive resolution"),
    ('intervalDecimal="1e-300"', "its intervalDecimal is out of range (1e-12 s to 1e9 s)"),
])
def test_a_clock_interval_that_is_no_time_is_refused_in_one_line(clocks_fmu, tmp_path, attributes, why):
    with zipfile.ZipFile(clocks_fmu) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    xml = members["modelDescription.xml"].decode()
    members["modelDescription.xml"] = xml.replace('intervalDecimal="1.0"', attributes).encode()
    broken = zip_files(tmp_path / "broken.fmu", members)
    with pytest.raises(ValueError) as info:
        FMU(broken)
    assert str(info.value).splitlines() == [f"FMU '{broken}': clock 'inClock1': {why}"]
