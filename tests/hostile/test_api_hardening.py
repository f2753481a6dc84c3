"""Hostile values through the Python API and the rules behind the corpus's classes: unit
texts that pint would compute, wrong argument types, products that size a block's memory,
the environment of the processes the tool starts, and control characters on a terminal."""

from __future__ import annotations

from pathlib import Path

import pytest

import blocks.units
from blocks import DiagramBuilder, DiagramError, build_schedule, dump_diagram, save_diagram, simulate
from blocks.library.discrete import MovingAverage
from blocks.limits import check_block_size
from blocks.process.module_path import protect_children
from blocks.process.terminal import escape_controls
from blocks.units import base_unit, same_unit, unit_problem

COMPUTING = ["9**9**9**9", "((m)^12)^12", "m^13", "2^3", "m**-99", "10**10 m", "m.__class__", "(" * 5 + "m" + ")" * 5,
             "m " * 60, "m^", "1" * 21 + " m", "m/(s", "m)", "__import__('os')", "m; s", "m\x00"]
"""Unit texts the grammar refuses: each would compute, or is no unit at all."""


@pytest.mark.parametrize("unit", ["rad", "N m", "m/s^2", "1", "N·m", "kg m/s^2", "radian / second", "deg/s", "degC",
                                  "%", "µm", "1/s", "m**2", "s^-1", "(m/s)^2", "kg*m**2/(s**3*A)", "1e-3 m", "",
                                  "m^12", "((m/s)/kg)"])
def test_the_unit_grammar_takes_units_as_people_write_them(unit):
    assert unit_problem(unit) is None


@pytest.mark.parametrize("unit", COMPUTING)
def test_a_refused_unit_text_never_reaches_pint(unit, monkeypatch):
    def no_pint():
        raise AssertionError(f"pint was asked to read {unit!r}")

    monkeypatch.setattr(blocks.units, "_registry", no_pint)
    blocks.units._pint_same.cache_clear()
    blocks.units.base_unit.cache_clear()
    assert unit_problem(unit)
    assert base_unit(unit) is None
    assert same_unit(unit, unit + "x") is False  # not one text, and pint never asked


def test_units_pint_reads_still_compare_and_convert():
    assert same_unit("N", "kg m/s^2") and not same_unit("mm", "m")
    assert base_unit("(m/s)^2").exponents == (("m", 2), ("s", -2))


def test_a_computing_unit_given_to_the_builder_is_refused_at_the_call():
    b = DiagramBuilder("u", t_end="10 ms")
    b.add("ramp", "Ramp", period="1 ms", params={"slope": 1.0}, units={"y": "10**10**10"})
    b.log("ramp.y")
    with pytest.raises(DiagramError) as caught:
        b.build()
    (issue,) = caught.value.issues
    assert Path(issue.file).name == Path(__file__).name and "10**10**10" in issue.message


@pytest.mark.parametrize("wrong", ["diagrams/toy.yaml", Path("toy.yaml"), None, 3, "builder"])
@pytest.mark.parametrize("call", [simulate, lambda d: build_schedule(d, None), dump_diagram,
                                  lambda d: save_diagram(d, "never.yaml")])
def test_a_diagram_argument_of_another_type_is_a_type_error_naming_it(call, wrong, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    if wrong == "builder":
        wrong = DiagramBuilder("b", t_end="1 ms")
    with pytest.raises(TypeError, match=r"^diagram must be a Diagram, got \w+"):
        call(wrong)
    assert not (tmp_path / "never.yaml").exists()


def test_exports_refuse_a_path_for_a_diagram(tmp_path):
    from blocks.fmu_export import export_fmu
    from blocks.ssp import export_ssp

    for export in (export_fmu, export_ssp):
        with pytest.raises(TypeError, match="load the file first"):
            export("diagrams/toy.yaml", tmp_path / "x")


def test_a_block_size_is_the_product_of_its_factors_and_bounded():
    assert check_block_size(("window", 1000), ("width", 1000)) == 10**6
    with pytest.raises(ValueError, match=r"^window 100000 x width 1000 make 1e\+08 values to hold, more than"):
        check_block_size(("window", 100_000), ("width", 1000))


def test_a_moving_average_too_large_for_its_input_is_refused_before_its_state_exists():
    average = MovingAverage(window=1_000_000)
    with pytest.raises(ValueError, match="window 1000000 x width 1000"):
        average.set_width(1000)
    assert average.inputs["u"] is None


def test_the_processes_the_tool_starts_import_nothing_from_their_working_folder():
    env = protect_children({"PYTHONPATH": ":/abs/one:relative:.::/abs/two", "HOME": "/h"})
    assert env == {"PYTHONPATH": "/abs/one:/abs/two", "PYTHONSAFEPATH": "1", "HOME": "/h"}
    assert "PYTHONPATH" not in protect_children({"PYTHONPATH": "::."})


def test_control_characters_are_shown_as_escapes_and_text_passes():
    assert escape_controls("a\x1b]2;t\x07\rb\tc\nd\u202eé\x9b") == "a\\x1b]2;t\\x07\\rb\tc\nd\\u202eé\\x9b"
