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

pint reads a unit text as an arithmetic expression (``9**9**9**9`` would be computed), and
unit texts come from diagrams, SSPs and FMUs that may be someone else's: ``unit_problem``
checks a text against a grammar that cannot compute much before pint sees it (names,
bounded numbers, products, quotients, small whole powers, shallow parentheses), and pint
is never fed a text that fails it.
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass

_FACTORS = re.compile(r"[\s*·]+")

MAX_UNIT_CHARS = 100
"""Longest unit text (``"kg m^2 / (s^2 A)"`` has 16 characters)."""
MAX_UNIT_POWER = 12
"""Largest whole power a unit text may write (``m^3``, ``s^-2``, ``m**4``)."""
MAX_UNIT_NUMBER = 20
"""Longest number a unit text may write as a factor (``1e-3 m``, ``100 %``), in characters."""
MAX_UNIT_DEPTH = 4
"""Deepest nesting of parentheses in a unit text."""
_TOKEN = re.compile(r"\s+|(?P<name>(?:[^\W\d]|[°%])[\w°]*)|(?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)"
                    r"|(?P<power>\*\*|\^)\s*(?P<exp>[+-]?\d+)?|(?P<op>[*/·])|(?P<open>\()|(?P<close>\))")


def unit_problem(unit: str) -> str | None:
    """Why ``unit`` is not a unit text the grammar allows (see the module's docstring), or
    None: names (``rad``, ``degC``, ``%``, ``µm``), numbers of at most MAX_UNIT_NUMBER
    characters, ``*``, ``/``, ``·`` or juxtaposition, a whole power of at most
    MAX_UNIT_POWER (``^`` or ``**``) after a name or a group, and parentheses at most
    MAX_UNIT_DEPTH deep, of which a raised group holds no raised group of its own."""
    if len(unit) > MAX_UNIT_CHARS:
        return f"a unit has at most {MAX_UNIT_CHARS} characters, this one {len(unit)}"
    groups: list[bool] = []  # per open parenthesis: whether a raised group is inside it
    last, raised_group, pos = "", False, 0
    while pos < len(unit):
        m = _TOKEN.match(unit, pos)
        if m is None:
            return f"{unit[pos]!r} at character {pos + 1} is not part of a unit"
        pos, kind = m.end(), m.lastgroup
        if kind is None:
            continue
        if kind == "exp":
            if last not in ("name", "close"):
                return f"a power follows a unit name or a parenthesis, not {'a number' if last else 'nothing'}"
            if abs(int(m["exp"])) > MAX_UNIT_POWER:
                return f"a power is a whole number from -{MAX_UNIT_POWER} to {MAX_UNIT_POWER}, not {m['exp']}"
            if last == "close" and raised_group:
                return "a group raised to a power may not hold another raised group"
            if last == "close" and groups:
                groups[-1] = True
        elif kind == "power":
            return "a power is a whole number after '^' or '**'"
        elif kind == "number" and len(m["number"]) > MAX_UNIT_NUMBER:
            return f"a number in a unit has at most {MAX_UNIT_NUMBER} characters"
        elif kind == "open":
            groups.append(False)
            if len(groups) > MAX_UNIT_DEPTH:
                return f"parentheses nest at most {MAX_UNIT_DEPTH} deep in a unit"
        elif kind == "close":
            if not groups:
                return f"')' at character {pos} closes nothing"
            raised_group = groups.pop()
        last = kind
    return "a '(' is not closed" if groups else None

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
    as ``bit``) or of a power that is not whole, or the text is not one ``unit_problem``
    allows."""
    if unit_problem(unit):
        return None
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
    if unit_problem(a) or unit_problem(b):
        return a == b
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
