"""A unit in the SI base units, as an exported FMU's and an SSD's unit definitions say it
(``blocks.units.base_unit``, read by pint): exponents, factor and offset."""

from __future__ import annotations

import math

import pytest

from blocks.units import base_unit


def in_si(unit: str, value: float) -> float:
    """``value`` in ``unit`` converted to the SI base units as the definition says."""
    found = base_unit(unit)
    return found.factor * value + found.offset


@pytest.mark.parametrize("unit, exponents", [
    ("N m", {"kg": 1, "m": 2, "s": -2}),
    ("1/(N m)", {"kg": -1, "m": -2, "s": 2}),
    ("m/s^2", {"m": 1, "s": -2}),
    ("V", {"kg": 1, "m": 2, "s": -3, "A": -1}),
    ("deg/s", {"rad": 1, "s": -1}),
    ("degC", {"K": 1}),
    ("1", {}),
    ("%", {}),
])
def test_a_unit_is_its_powers_of_the_base_units(unit, exponents):
    assert dict(base_unit(unit).exponents) == exponents


@pytest.mark.parametrize("unit, value, si", [
    ("mm", 1500.0, 1.5),
    ("kN", 2.0, 2000.0),
    ("g", 250.0, 0.25),
    ("h", 1.0, 3600.0),
    ("deg", 180.0, math.pi),
    ("rpm", 60.0, 2 * math.pi),
    ("degC", 0.0, 273.15),
    ("degC", 100.0, 373.15),
    ("degF", 32.0, 273.15),
    ("degF", 212.0, 373.15),
    ("%", 50.0, 0.5),
])
def test_a_value_converts_to_si_by_the_factor_and_offset(unit, value, si):
    assert in_si(unit, value) == pytest.approx(si, rel=1e-12)


def test_a_unit_that_is_no_product_of_the_si_base_units_has_no_definition():
    assert base_unit("blorp") is None  # not a unit pint reads
    assert base_unit("bit") is None  # pint's, with no FMI exponent
    assert base_unit("m^0.5") is None  # FMI's exponents are whole


def test_the_definition_leaves_out_a_factor_of_one_and_an_offset_of_zero():
    assert base_unit("N m").attributes() == {"kg": "1", "m": "2", "s": "-2"}
    assert base_unit("mm").attributes() == {"m": "1", "factor": "0.001"}
    assert base_unit("degC").attributes() == {"K": "1", "offset": "273.15"}
