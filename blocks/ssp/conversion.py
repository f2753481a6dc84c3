"""Units of an SSP being read: their definitions and the conversion from one to another.

SSP 1.0 defines a unit by its exponents of the SI base units, a factor and an offset
(``ssc:Unit`` / ``ssc:BaseUnit``, the attributes of an FMU's ``UnitDefinitions``): a
value ``v`` in it is ``factor * v + offset`` in the base units. The definitions an SSD,
an ``.ssv`` file or an FMU gives are read here; a unit none of them defines is read by
pint (``blocks.units.base_unit``), also in Modelica's notation (``kg.m2``, ``cm/s2``:
``.`` multiplies, a trailing integer is a power), which OMSimulator writes undefined.
Two units convert when their exponents are the same: ``conversion`` gives the factor
and offset, the standard's automatic unit conversion of connections and parameter values.
"""

from __future__ import annotations

import math
import re
from typing import Any

from ..units import BASE_ATTRIBUTES, BaseUnit, base_unit
from .xml import child, children, finite, shown, whole

Definitions = dict[str, BaseUnit]
"""Unit name -> its definition."""

_POWER = re.compile(r"^([^\W\d]+)(-?\d+)$")


class UnitError(ValueError):
    """A unit definition that cannot be read, or two units that do not convert: ``line``
    where, if known."""

    def __init__(self, message: str, line: int | None = None):
        super().__init__(message)
        self.line = line


class ZeroFactor(ValueError):
    """A unit definition whose factor is 0: no size in the base units."""


class UnknownUnit(UnitError):
    """A unit that neither a definition nor pint knows."""


def read_definitions(units: Any) -> Definitions:
    """The ``ssc:Unit`` definitions of an ``ssd:Units`` or ``ssv:Units`` element (None:
    none); UnitError for one whose ``ssc:BaseUnit`` attributes are not numbers."""
    found: Definitions = {}
    for unit in children(units, "ssc", "Unit"):
        base = child(unit, "ssc", "BaseUnit")
        name = unit.get("name")
        if base is None or not name:
            continue
        try:
            found[name] = from_attributes(base.attrib)
        except ZeroFactor:
            raise UnitError(f"ssc:Unit {shown(name)}: its factor is 0 (a unit's factor is its size in the SI base "
                            "units: 1000 for km)", base.sourceline) from None
        except ValueError:
            raise UnitError(f"ssc:Unit {shown(name)}: its ssc:BaseUnit attributes must be numbers: finite factor "
                            "and offset, whole exponents", base.sourceline) from None
    return found


def from_attributes(attributes: Any) -> BaseUnit:
    """A unit from the attributes of a ``BaseUnit`` (SSP's or an FMU's: ``kg``, ``m``, ...,
    ``factor``, ``offset``, each optional); ValueError for one that is not a number."""
    exponents = []
    for name in BASE_ATTRIBUTES.values():
        power = whole(str(attributes.get(name) or 0))
        if power:
            exponents.append((name, power))
    factor = finite(str(attributes.get("factor") or 1.0))
    offset = finite(str(attributes.get("offset") or 0.0))
    if factor == 0:
        raise ZeroFactor("its factor is 0")
    return BaseUnit(tuple(exponents), factor, offset)


def fmu_definitions(md: Any) -> Definitions:
    """The units an FMU's modelDescription (fmpy's) defines."""
    found: Definitions = {}
    for unit in getattr(md, "unitDefinitions", None) or []:
        base = getattr(unit, "baseUnit", None)
        if base is None or not unit.name:
            continue
        try:
            found[unit.name] = from_attributes({k: getattr(base, k, None) for k in
                                                (*BASE_ATTRIBUTES.values(), "factor", "offset")})
        except (TypeError, ValueError):
            continue
    return found


def definition(name: str, *tables: Definitions) -> BaseUnit | None:
    """The definition of unit ``name``: the first of ``tables`` that defines it, else
    pint's reading of it (as written, else in Modelica's notation); None if none knows it.
    A name in brackets (``[m]``, as some tools write a value's unit) is the unit inside."""
    for table in tables:
        if name in table:
            return table[name]
    found = base_unit(name) or base_unit(pint_text(name))
    if found is None and len(name) > 2 and name[0] == "[" and name[-1] == "]":
        return definition(name[1:-1], *tables)
    return found


def pint_text(name: str) -> str:
    """A unit in Modelica's notation as pint reads it: ``kg.m2`` -> ``kg*m**2``."""
    sides = []
    for side in name.split("/"):
        factors = []
        for factor in side.split("."):
            power = _POWER.match(factor.strip())
            factors.append(f"{power.group(1)}**{power.group(2)}" if power else factor.strip())
        sides.append("*".join(factors))
    return "/".join(sides)


def conversion(source: str, target: str, *tables: Definitions) -> tuple[float, float]:
    """(factor, offset) that take a value in unit ``source`` to unit ``target``
    (``target = factor * source + offset``); UnitError when either is unknown or they
    measure different quantities."""
    if source == target:
        return 1.0, 0.0
    a, b = definition(source, *tables), definition(target, *tables)
    unknown = [name for name, found in ((source, a), (target, b)) if found is None]
    if unknown:
        raise UnknownUnit(f"unit '{unknown[0]}' is defined nowhere (no ssc:Unit of that name, and pint does not "
                        "know it)")
    if a.exponents != b.exponents:
        raise UnitError(f"unit '{source}' does not convert to unit '{target}': they measure different quantities")
    factor, offset = a.factor / b.factor, (a.offset - b.offset) / b.factor
    if not (math.isfinite(factor) and math.isfinite(offset)) or factor == 0:
        raise UnitError(f"unit '{source}' to unit '{target}': their factors and offsets give no finite conversion")
    return factor, offset
