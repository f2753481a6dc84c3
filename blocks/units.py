"""Whether two units are the same unit: the check of a connection whose ends both declare one.

Units are text (``"rad"``, ``"N m"``, ``"m/s^2"``, ``"1"``). Two texts that are the same
product of the same factors (``"N m"``, ``"m*N"``, ``"N·m"``) are the same unit without
further ado; others are compared by pint, loaded only then (it takes a good half second):
the same unit however written (``"N"`` and ``"kg m/s^2"``, ``"rad/s"`` and ``"radian /
second"``) is the same, while units of one dimension at different scales (``"mm"`` and
``"m"``) or of different dimensions are not, since a connection converts nothing. A text
pint cannot read is the same only as the same text. An empty text is an unknown unit,
like none.
"""

from __future__ import annotations

import functools
import re

_FACTORS = re.compile(r"[\s*·]+")


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
