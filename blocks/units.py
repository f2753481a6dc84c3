"""Units, read by pint only: whether two units are one, and a unit in the SI base units.

Units are text (``"rad"``, ``"N m"``, ``"m/s^2"``, ``"1"``). This module owns the one pint
``UnitRegistry`` of the package (loaded when first needed: it takes a good half second).

``same_unit`` checks a connection whose ends both declare a unit. Two texts that are the
same product of the same factors (``"N m"``, ``"m*N"``, ``"N·m"``) are the same unit
without further ado; others are compared by pint: the same unit however written (``"N"``
and ``"kg m/s^2"``, ``"rad/s"`` and ``"radian / second"``) is the same, while units of one
dimension at different scales (``"mm"`` and ``"m"``) or of different dimensions are not,
since a connection converts nothing. A text pint cannot read is the same only as the same
text. An empty text is an unknown unit, like none.

``base_unit`` says a unit as an exported FMU's ``UnitDefinitions`` (and an SSD's
``ssd:Units``) declare it: its exponents of the SI base units and radian, a factor and an
offset (``"mm"``: m = 1, factor 0.001; ``"degC"``: K = 1, offset 273.15).
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass

_FACTORS = re.compile(r"[\s*·]+")

BASE_ATTRIBUTES = {"kilogram": "kg", "meter": "m", "second": "s", "ampere": "A", "kelvin": "K", "mole": "mol",
                   "candela": "cd", "radian": "rad"}
"""pint's base units (its ``mks`` system) by the attribute an FMI or SSP ``BaseUnit`` gives
each exponent in, in the order they list them."""


def factors(unit: str) -> tuple[str, ...]:
    """The factors of a product of units, in order of their text (``"m*N"`` -> ``("N", "m")``)."""
    return tuple(sorted(f for f in _FACTORS.split(unit.strip()) if f))


def same_unit(a: str, b: str) -> bool:
    """Whether units ``a`` and ``b`` are one unit (see the module's docstring)."""
    if factors(a) == factors(b):
        return True
    return _pint_same(a.strip(), b.strip())


def differs(a: str | None, b: str | None) -> bool:
    """Whether two declared units (None or ``""``: unknown) are known and not one unit."""
    return bool(a) and bool(b) and not same_unit(a, b)


@dataclass(frozen=True)
class BaseUnit:
    """A unit in the SI base units: a value ``v`` in it is ``factor * v + offset`` in the
    product of ``exponents`` (nonzero powers, by ``BASE_ATTRIBUTES``' names)."""

    exponents: tuple[tuple[str, int], ...]
    factor: float = 1.0
    offset: float = 0.0

    def attributes(self) -> dict[str, str]:
        """The attributes of an FMI or SSP ``BaseUnit`` element (factor and offset only
        where they are not 1 and 0)."""
        attrs = {name: str(power) for name, power in self.exponents}
        if self.factor != 1.0:
            attrs["factor"] = repr(self.factor)
        if self.offset != 0.0:
            attrs["offset"] = repr(self.offset)
        return attrs


@functools.cache
def base_unit(unit: str) -> BaseUnit | None:
    """``unit`` in the SI base units (``"deg/s"``: rad = 1, s = -1, factor pi/180), or None
    when pint cannot read it, or it is made of a base unit FMI has no exponent for (such
    as ``bit``) or of a power that is not whole."""
    registry = _registry()
    try:
        zero = registry.Quantity(0.0, unit)
        step = (registry.Quantity(1.0, unit) - zero).to_base_units()
        offset = float(zero.to_base_units().magnitude)
    except Exception:  # pint raises many kinds for a text it cannot read
        return None
    powers = dict(step.unit_items())
    if not set(powers) <= set(BASE_ATTRIBUTES) or not all(float(p).is_integer() for p in powers.values()):
        return None
    factor = float(step.magnitude)
    if not (math.isfinite(factor) and math.isfinite(offset)) or factor == 0.0:
        return None
    exponents = tuple((name, int(powers[base])) for base, name in BASE_ATTRIBUTES.items()
                      if int(powers.get(base, 0)))
    return BaseUnit(exponents, factor, offset)


@functools.cache
def seconds_in(unit: str) -> float | None:
    """The seconds in one ``unit`` (``"day"``: 86400.0), or None when pint cannot read it
    or it is not a unit of time (``"m"``, ``"s^2"``); finite and positive."""
    registry = _registry()
    try:
        quantity = registry.Quantity(1.0, unit)
        if quantity.dimensionality != registry.second.dimensionality:
            return None
        seconds = float(quantity.to(registry.second).magnitude)
    except Exception:  # pint raises many kinds for a text it cannot read
        return None
    return seconds if math.isfinite(seconds) and seconds > 0 else None


@functools.cache
def _pint_same(a: str, b: str) -> bool:
    registry = _registry()
    try:
        qa, qb = registry.Quantity(1.0, a), registry.Quantity(1.0, b)
        if qa.dimensionality != qb.dimensionality:
            return False
        return abs(qa.to(qb.units).magnitude - 1.0) < 1e-12
    except Exception:  # pint raises many kinds for a text it cannot read: then only the same text is the same
        return a == b


@functools.cache
def _registry():
    import pint

    return pint.UnitRegistry()
