"""The FMI variable types that become ports, and how their values travel as float64.

Ports carry float64 vectors whatever the FMU's variable types are. ``PortKind`` says, for
one FMI type, which get/set functions move it, in which C and numpy type, and the rule a
value keeps on its way (``input_rule`` / ``output_rule``; ``hierhand validate`` lists them
for connections between different types). ``KINDS`` is the table of the types that become
ports, by FMI major version and the type name the FMU uses; ``NOT_PORTS`` says why the
other types do not.
"""

from __future__ import annotations

from dataclasses import dataclass

EXACT_INTEGERS = 2**53
"""Integers up to this magnitude are exact in a float64 port; a 64-bit output beyond it
stops the run rather than change its value."""


def float64_holds(value: int) -> bool:
    """Whether the integer ``value`` survives the trip through a float64 port unchanged."""
    return int(float(value)) == value


@dataclass(frozen=True)
class PortKind:
    """How values of one FMI variable type travel as float64 port values.

    ``name`` is the type in FMI 3 spelling (FMI 2's Real is Float64, its Integer Int32),
    ``function`` the suffix of the FMI get/set functions that move it, ``ctype`` and
    ``dtype`` its C and numpy types. Integer types have a range ``[low, high]``.
    """

    name: str
    function: str
    ctype: str
    dtype: str
    low: int | None = None
    high: int | None = None

    @property
    def is_float(self) -> bool:
        return self.low is None and self.name != "Boolean"

    @property
    def exceeds_float64(self) -> bool:
        """Whether some values of this type are integers a float64 cannot hold exactly."""
        return self.low is not None and max(-self.low, self.high) > EXACT_INTEGERS

    def input_rule(self) -> str:
        """What a float64 value must be to reach a variable of this type."""
        if self.name == "Float64":
            return "any number"
        if self.name == "Float32":
            return "any number, rounded to the nearest Float32"
        if self.name == "Boolean":
            return "0 (false) or 1 (true); any other value stops the run"
        return f"whole numbers from {self.low} to {self.high}; any other value stops the run"

    def output_rule(self) -> str:
        """How a value of this type becomes a float64."""
        if self.name == "Boolean":
            return "false -> 0, true -> 1"
        if self.exceeds_float64:
            return "exact up to 2^53 in magnitude; a larger value stops the run"
        return "exact"


def _ints(name: str, bits: int, signed: bool, function: str | None = None) -> PortKind:
    low, high = (-2**(bits - 1), 2**(bits - 1) - 1) if signed else (0, 2**bits - 1)
    ctype = f"c_{'' if signed else 'u'}int{bits}"
    return PortKind(name, function or name, ctype, f"{'' if signed else 'u'}int{bits}", low, high)


KINDS: dict[int, dict[str, PortKind]] = {
    2: {"Real": PortKind("Float64", "Real", "c_double", "float64"),
        "Integer": _ints("Int32", 32, True, "Integer"),
        "Enumeration": _ints("Enumeration", 32, True, "Integer"),
        "Boolean": PortKind("Boolean", "Boolean", "c_int", "int32")},
    3: {"Float64": PortKind("Float64", "Float64", "c_double", "float64"),
        "Float32": PortKind("Float32", "Float32", "c_float", "float32"),
        **{f"{u}Int{b}": _ints(f"{u}Int{b}", b, not u) for u in ("", "U") for b in (8, 16, 32, 64)},
        "Enumeration": _ints("Enumeration", 64, True, "Int64"),
        "Boolean": PortKind("Boolean", "Boolean", "c_bool", "bool")},
}
"""The variable types that become ports, by FMI major version and the FMU's type name."""

NOT_PORTS = {
    "String": "a String variable, which cannot be a port (ports carry numbers)",
    "Binary": "a Binary variable, which cannot be a port (ports carry numbers)",
    "Clock": ("a Clock, which is not a port (the block activates the periodic input clocks of a "
              "scheduled-execution FMU on their ticks; co-simulation and model exchange run without clocks)"),
}
"""Why the other variable types are not ports, by type name."""
