"""FMI conformance of the FMU block, on small C FMUs compiled at test time.

``typed_fmi2.c`` / ``typed_fmi3.c`` have an input and an output of every type of their
FMI version (each output copies its input, at initialisation and in every step), an FMI 3
alias and matrix output, String / Binary / Clock variables, and ask to terminate when a
step reaches their parameter ``stop_at``. Every test runs twice, on the FMUs as
co-simulation FMUs and as model-exchange FMUs (their other interface removed from the
modelDescription, so the block picks the one left). Checked: every numeric type is a port
with an exact round trip; values a type cannot hold stop the run; conversions are listed;
inputs are set before initialisation ends, as FMPy does; termination ends the run as
complete; archives with identical duplicate members load; CSV columns keep the FMU's
indices.
"""

from __future__ import annotations

import csv
import json
import re
import zipfile
from pathlib import Path

import numpy as np
import pytest

from blocks import DiagramError, Results, build_schedule, loads_diagram, simulate
from blocks.fmu.archive import ArchiveError, extract_archive

fmpy = pytest.importorskip("fmpy")

from .build import build_error, typed_fmu  # noqa: E402

INT_TYPES = {"i8": (-2**7, 2**7 - 1), "u8": (0, 2**8 - 1), "i16": (-2**15, 2**15 - 1),
             "u16": (0, 2**16 - 1), "i32": (-2**31, 2**31 - 1), "u32": (0, 2**32 - 1)}


class TypedFMUs(dict):
    """The typed FMUs by FMI version, offering only the interface ``fmi_type`` (fmpy's name)."""

    def __init__(self, build: Path, fmi_type: str):
        super().__init__({fmi: typed_fmu(build, fmi, only=fmi_type) for fmi in (2, 3)})
        self.fmi_type = fmi_type


@pytest.fixture(scope="module", params=["CoSimulation", "ModelExchange"])
def typed(tmp_path_factory, request) -> TypedFMUs:
    why = build_error()
    if why:
        pytest.skip(why)
    return TypedFMUs(tmp_path_factory.mktemp("typed_fmus"), request.param)


def fmu_diagram(path: Path, sources: dict[str, float], connections: list[str], t_end: str = "0.3 s",
                start_values: str = "{}", log: str = "all", extra: str = ""):
    """A diagram with the FMU first (so only the planner can put its sources before it) and
    one Constant per entry of ``sources``."""
    blocks = "\n".join(f"  {name}: {{type: Constant, params: {{value: {value!r}}}}}"
                       for name, value in sources.items())
    wires = "\n".join(f"  - {c}" for c in connections) or "  []"
    return loads_diagram(f"""
time: {{t_end: {t_end}}}
blocks:
  fmu: {{type: FMU, period: 0.1 s, params: {{path: '{path}', start_values: {start_values}}}}}
{blocks}
{extra}
connections:
{wires}
log: {log}
""", filename="typed.yaml")


# -- types ---------------------------------------------------------------------------


def test_every_numeric_type_is_a_port_with_its_fmi_type(typed):
    d2 = fmu_diagram(typed[2], {}, [])
    fmu2 = d2.blocks["fmu"].block
    assert set(fmu2.inputs) == {"r_in", "i_in", "b_in", "e_in"}
    assert {p: fmu2.port_type(p) for p in fmu2.outputs} == {
        "r_out": "Float64", "time_out": "Float64", "i_out": "Int32", "b_out": "Boolean", "e_out": "Enumeration"}
    d3 = fmu_diagram(typed[3], {}, [])
    fmu3 = d3.blocks["fmu"].block
    names = ["f32", "i8", "u8", "i16", "u16", "i32", "u32", "i64", "u64", "b", "e"]
    assert set(fmu3.inputs) == {"f_in"} | {f"{n}_in" for n in names}
    assert set(fmu3.outputs) == {"f_out", "f_alias", "m_out", "time_out"} | {f"{n}_out" for n in names}
    assert fmu3.port_type("u64_in") == "UInt64" and fmu3.port_type("e_out") == "Enumeration"
    assert fmu3.outputs["m_out"] == 4


@pytest.mark.parametrize("extreme", [0, 1])
def test_integers_up_to_32_bits_round_trip_exactly_at_their_extremes(typed, extreme):
    sources = {f"c_{n}": float(limits[extreme]) for n, limits in INT_TYPES.items()}
    wires = [f"c_{n}.y -> fmu.{n}_in" for n in INT_TYPES]
    r = simulate(fmu_diagram(typed[3], sources, wires))
    assert r.complete
    for n, limits in INT_TYPES.items():
        _, v = r[f"fmu.{n}_out"]
        assert v[:, 0].tolist() == [float(limits[extreme])] * len(v), n


@pytest.mark.parametrize("value", [2**53, -2**53, 2**62, -2**63, (2**53 - 1) * 2**9])
def test_64_bit_integers_round_trip_every_value_a_float64_holds(typed, value):
    sources = {"c": float(value)}
    wires = ["c.y -> fmu.i64_in"] + (["c.y -> fmu.u64_in"] if value >= 0 else [])
    r = simulate(fmu_diagram(typed[3], sources, wires))
    assert r.complete, r.status
    for port in ("i64_out", "u64_out") if value >= 0 else ("i64_out",):
        _, v = r[f"fmu.{port}"]
        assert [int(x) for x in v[:, 0]] == [value] * len(v)
    big = simulate(fmu_diagram(typed[3], {"c": 2.0**64 - 2**11}, ["c.y -> fmu.u64_in"]))
    assert int(big["fmu.u64_out"][1][-1, 0]) == 2**64 - 2**11


def test_a_64_bit_input_start_value_a_float64_cannot_hold_is_refused(typed):
    with pytest.raises(DiagramError, match=r"start value of 'u64_in' is 9007199254740993, which its "
                                           r"float64 port cannot hold exactly"):
        fmu_diagram(typed[3], {}, [], start_values=f"{{u64_in: {2**53 + 1}}}")
    d = fmu_diagram(typed[3], {}, [], start_values=f"{{u64_in: {2**60}}}")
    assert int(simulate(d)["fmu.u64_out"][1][0, 0]) == 2**60


def test_fmi2_integer_boolean_and_enumeration_ports(typed):
    r = simulate(fmu_diagram(typed[2], {"i": -2.0**31, "b": 1.0, "e": -7.0, "x": 0.125},
                             ["i.y -> fmu.i_in", "b.y -> fmu.b_in", "e.y -> fmu.e_in", "x.y -> fmu.r_in"]))
    assert r.complete, r.status
    assert r["fmu.i_out"][1][:, 0].tolist() == [-2.0**31] * 4
    assert r["fmu.b_out"][1][:, 0].tolist() == [1.0] * 4
    assert r["fmu.e_out"][1][:, 0].tolist() == [-7.0] * 4
    assert r["fmu.r_out"][1][:, 0].tolist() == [0.125] * 4


def test_a_64_bit_output_a_float64_cannot_hold_stops_the_run(typed):
    d = fmu_diagram(typed[3], {}, [], start_values=f"{{u64_offset: {2**53 + 1}}}")
    r = simulate(d)
    assert not r.complete
    assert "output 'u64_out' (UInt64) is 9007199254740993 at t=0 s, which a float64 port cannot hold " \
           "exactly" in r.status
    assert "block 'fmu' (FMU)" in r.status


@pytest.mark.parametrize("port, value, rule", [
    ("i8_in", 128.0, "whole numbers from -128 to 127"),
    ("u8_in", -1.0, "whole numbers from 0 to 255"),
    ("i32_in", 2.5, "whole numbers from -2147483648 to 2147483647"),
    ("u64_in", 2.0**64, "whole numbers from 0 to 18446744073709551615"),
    ("i64_in", 2.0**63, "whole numbers from -9223372036854775808 to 9223372036854775807"),
    ("b_in", 0.5, "0 (false) or 1 (true)"),
    ("i16_in", -32768.5, "whole numbers from -32768 to 32767"),
])
def test_a_value_an_input_type_cannot_hold_stops_the_run_naming_it(typed, port, value, rule):
    r = simulate(fmu_diagram(typed[3], {"c": value}, [f"c.y -> fmu.{port}"]))
    assert not r.complete
    kind = {"i8_in": "Int8", "u8_in": "UInt8", "i32_in": "Int32", "u64_in": "UInt64", "i64_in": "Int64",
            "b_in": "Boolean", "i16_in": "Int16"}[port]
    assert f"input '{port}' ({kind}) got {value:.17g} at t=0 s; it takes {rule}" in r.status
    assert r.status.startswith("failed at t=0 s: block 'fmu' (FMU)")


def test_validate_lists_every_conversion_with_its_rule(typed, tmp_path, capsys):
    from hierhand.cli import main

    (tmp_path / "d.yaml").write_text(f"""
time: {{t_end: 0.3 s}}
blocks:
  fmu: {{type: FMU, period: 0.1 s, params: {{path: '{typed[3]}'}}}}
  c: {{type: Constant, params: {{value: 1}}}}
connections:
  - c.y -> fmu.b_in
  - fmu.u8_out -> fmu.i16_in
  - fmu.u64_out -> fmu.f_in
  - fmu.f_out -> fmu.f32_in
""")
    assert main(["validate", str(tmp_path / "d.yaml")]) == 0
    out = capsys.readouterr().out
    section = out[out.index("conversions"):].splitlines()
    assert "  c.y (Float64) -> fmu.b_in (Boolean): 0 (false) or 1 (true); any other value stops the run" in section
    assert "  fmu.u8_out (UInt8) -> fmu.i16_in (Int16): whole numbers from -32768 to 32767; any other value " \
           "stops the run" in section
    assert "  fmu.u64_out (UInt64) -> fmu.f_in (Float64): exact up to 2^53 in magnitude; a larger value " \
           "stops the run" in section
    assert "  fmu.f_out (Float64) -> fmu.f32_in (Float32): any number, rounded to the nearest Float32" in section


@pytest.mark.parametrize("fmi, port, what", [
    (2, "s_in", "'s_in' is a String variable, which cannot be a port (ports carry numbers); give it a "
                "value with start_values"),
    (3, "bin_in", "'bin_in' is a Binary variable, which cannot be a port"),
    (3, "tick", "'tick' is a Clock, which is not a port"),
    (3, "stop_at", "'stop_at' is a parameter of the FMU, not a port; set it with start_values"),
])
def test_variables_that_are_not_ports_say_why(typed, fmi, port, what):
    with pytest.raises(DiagramError) as info:
        fmu_diagram(typed[fmi], {"c": 1.0}, [f"c.y -> fmu.{port}"])
    message = str(info.value)
    assert f"block 'fmu' (FMU) has no input '{port}'" in message and what in message
    with pytest.raises(DiagramError, match=f"has no output '{port}'.*{what[:20]}"):
        fmu_diagram(typed[fmi], {}, [], log=f"[fmu.{port}]")


def test_an_alias_output_is_a_port_of_its_own(typed):
    r = simulate(fmu_diagram(typed[3], {"c": 0.75}, ["c.y -> fmu.f_in"]))
    np.testing.assert_array_equal(r["fmu.f_alias"][1], r["fmu.f_out"][1])
    assert r["fmu.f_alias"][1][0, 0] == 0.75
    np.testing.assert_array_equal(r["fmu.m_out"][1][-1], [0.75, 1.5, 2.25, 3.0])


# -- initialisation ------------------------------------------------------------------------


@pytest.mark.parametrize("fmi, port", [(2, "r"), (3, "f")])
def test_initial_outputs_follow_the_connected_inputs_as_in_fmpy(typed, fmi, port):
    """The FMU is listed before its source: only inputs set in initialisation mode, with the
    source computed first, give the input's value at t = 0."""
    r = simulate(fmu_diagram(typed[fmi], {"c": 3.5}, [f"c.y -> fmu.{port}_in"]))
    ours = r[f"fmu.{port}_out"][1][:, 0]
    signal = np.array([(0.0, 3.5), (1.0, 3.5)], dtype=[("time", float), (f"{port}_in", float)])
    theirs = fmpy.simulate_fmu(str(typed[fmi]), stop_time=0.3, output_interval=0.1, input=signal,
                               output=[f"{port}_out"], fmi_type=typed.fmi_type)
    np.testing.assert_array_equal(ours, theirs[f"{port}_out"])
    assert ours[0] == 3.5


def test_an_input_fed_back_from_the_fmu_keeps_its_start_value_at_t0(typed):
    d = fmu_diagram(typed[3], {"c": 5.0}, ["c.y -> fmu.i8_in", "fmu.i8_out -> fmu.i16_in"],
                    start_values="{i16_in: -3}")
    held = [(h.block, h.port) for h in build_schedule(d, None).initial_held]
    assert held == [("fmu", "i16_in")]
    r = simulate(d)
    assert r["fmu.i8_out"][1][:, 0].tolist() == [5.0] * 4
    assert r["fmu.i16_out"][1][:, 0].tolist() == [-3.0, 5.0, 5.0, 5.0]


# -- termination ---------------------------------------------------------------------------


@pytest.mark.parametrize("fmi", [2, 3])
@pytest.mark.parametrize("stop_at, end, reached", [(0.25, 0.3, 0.25), (0.3, 0.3, 0.3)])
def test_termination_requested_by_the_fmu_ends_the_run_complete(typed, fmi, stop_at, end, reached):
    fast = "  clock: {type: Ramp, period: 0.05 s, params: {slope: 1}}"
    d = fmu_diagram(typed[fmi], {}, [], t_end="1 s", start_values=f"{{stop_at: {stop_at}}}", extra=fast,
                    log="[fmu.time_out, clock.y]")
    r = simulate(d)
    assert r.complete and r.status == "complete"
    assert r.ended_by["block"] == "fmu" and r.ended_by["time"] == pytest.approx(end)
    assert "requested to terminate the simulation" in r.ended_by["reason"]
    t, v = r["fmu.time_out"]
    assert t[-1] == pytest.approx(end) and v[-1, 0] == pytest.approx(reached)
    t_clock, _ = r["clock.y"]
    assert t_clock[-1] == pytest.approx(end) and len(t_clock) == round(end / 0.05) + 1


def test_termination_through_the_cli_exits_0_and_records_who_ended_the_run(typed, tmp_path, capsys):
    from hierhand.cli import main

    (tmp_path / "d.yaml").write_text(f"""
time: {{t_end: 2 s}}
blocks:
  stair: {{type: FMU, period: 0.1 s, params: {{path: '{typed[2]}', start_values: {{stop_at: 0.85}}}}}}
log: [stair.time_out]
""")
    assert main(["run", str(tmp_path / "d.yaml"), "-o", str(tmp_path / "out"), "--csv"]) == 0
    out = capsys.readouterr().out
    assert "ended at t=0.9 s by block 'stair' (FMU)" in out
    info = json.loads((tmp_path / "out" / "run.json").read_text())
    assert info["status"] == "complete" and info["ended_by"]["block"] == "stair"
    rows = list(csv.reader((tmp_path / "out" / "signals.csv").open()))
    assert float(rows[-1][0]) == pytest.approx(0.9) and float(rows[-1][1]) == pytest.approx(0.85)


# -- archives and files ---------------------------------------------------------------------


@pytest.mark.filterwarnings("ignore:Duplicate name")
def test_identical_duplicate_archive_members_are_read_once(typed, tmp_path):
    """Like the Reference FMUs' own build, which writes extra/ twice."""
    with zipfile.ZipFile(typed[3]) as zf:
        members = {i.filename: zf.read(i) for i in zf.infolist()}
    path = tmp_path / "dup.fmu"
    with zipfile.ZipFile(path, "w") as zf:
        for round_ in range(2):
            zf.writestr("extra/", b"")
            zf.writestr("extra/org.example/notes.txt", b"same bytes")
            if round_ == 0:
                for name, data in members.items():
                    zf.writestr(name, data)
    dest = tmp_path / "x"
    dest.mkdir()
    extract_archive(path, dest)
    assert (dest / "extra/org.example/notes.txt").read_bytes() == b"same bytes"
    assert simulate(fmu_diagram(path, {"c": 2.0}, ["c.y -> fmu.f_in"])).complete


@pytest.mark.filterwarnings("ignore:Duplicate name")
def test_differing_duplicate_archive_members_are_refused(tmp_path):
    path = tmp_path / "dup.zip"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("extra/a.txt", b"one")
        zf.writestr("extra/a.txt", b"two")
    dest = tmp_path / "x"
    dest.mkdir()
    with pytest.raises(ArchiveError, match="member 'extra/a.txt' occurs twice with different contents"):
        extract_archive(path, dest)
    assert list(dest.iterdir()) == []


def test_csv_columns_of_fmu_vectors_keep_the_fmus_indices(typed, tmp_path):
    r = simulate(fmu_diagram(typed[3], {"c": 1.0}, ["c.y -> fmu.f_in"], log="[fmu.m_out, fmu.f_out]"))
    r.save(tmp_path, csv=True)
    header = next(csv.reader((tmp_path / "signals.csv").open()))
    assert header == ["time", "fmu.m_out[1,1]", "fmu.m_out[1,2]", "fmu.m_out[2,1]", "fmu.m_out[2,2]", "fmu.f_out"]
    again = tmp_path / "again"
    Results.load(tmp_path).save(again, csv=True)
    assert (again / "signals.csv").read_text() == (tmp_path / "signals.csv").read_text()


def test_scheduled_execution_with_a_changing_clock_is_refused_and_the_message_says_why(typed, tmp_path):
    with zipfile.ZipFile(typed[3]) as zf:
        xml = zf.read("modelDescription.xml").decode()
    xml = re.sub(r"<(CoSimulation|ModelExchange) [^>]*/>", '<ScheduledExecution modelIdentifier="Typed3"/>', xml)
    xml = xml.replace('intervalVariability="triggered"', 'intervalVariability="changing"')
    path = tmp_path / "clocked.fmu"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("modelDescription.xml", xml)
    with pytest.raises(DiagramError) as info:
        fmu_diagram(path, {}, [])
    assert "the input clock 'tick' is changing without an interval the modelDescription gives; the FMU block " \
           "activates periodic, triggered and countdown clocks" in str(info.value)


def test_fmu_info_lists_every_variable_type(typed):
    from blocks.fmu import describe_fmu

    text = describe_fmu(typed[3])
    for kind in ("UInt64", "Int8", "Boolean", "Enumeration", "Binary", "Clock"):
        assert f" {kind}" in text


def test_port_units_come_from_the_variables_or_their_declared_types(typed, tmp_path):
    fmu2 = fmu_diagram(typed[2], {}, []).blocks["fmu"].block
    assert fmu2.port_units("r_in") == "rad"  # FMI 2 <SimpleType name="Angle"><Real unit="rad"/>
    assert fmu2.port_units("r_out") == "m"  # <Real unit="m"/>
    assert fmu2.port_units("i_out") is None and fmu2.port_units("time_out") is None
    d3 = fmu_diagram(typed[3], {"c": 1.0}, ["c.y -> fmu.f_in"], log="[fmu.m_out, fmu.time_out, fmu.i8_out]")
    fmu3 = d3.blocks["fmu"].block
    assert fmu3.port_units("f_in") == "rad" and fmu3.port_units("time_out") == "s"
    assert fmu3.port_units("m_out") == "m"  # FMI 3 <Float64Type name="Length" unit="m"/>, an array
    simulate(d3).save(tmp_path)
    again = Results.load(tmp_path)
    assert again.info["units"] == {"fmu.m_out": "m", "fmu.time_out": "s"}
    assert again.units("fmu.m_out") == ["m"] * 4 and again.unit("fmu.time_out") == "s"
    assert again.units("fmu.i8_out") is None


def test_fmu_info_shows_units_of_declared_types(typed):
    from blocks.fmu import describe_fmu

    lines = describe_fmu(typed[2]).splitlines()
    assert next(line for line in lines if line.strip().startswith("r_in ")).endswith(" rad")
