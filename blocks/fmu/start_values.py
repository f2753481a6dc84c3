"""Start values: which FMU variables a diagram may set, and their values checked and converted.

A block's ``start_values`` name variables (or vectors ``x`` for ``x[1]``, ``x[2]``, ...,
or FMI 3 arrays, which take a list). They are checked when the diagram is loaded, so a
typo or a value of the wrong type is a load error naming the variable (with a suggestion)
rather than a failure once the FMU runs: ``assignments`` checks that each variable is
settable and converts every value to the variable's type, in its range. A start value of
an input also passes through the input's float64 port when the input is unconnected, so
it must be one a float64 holds exactly. ``input_starts`` gives those unconnected inputs
their values: the start values over the modelDescription's, else 0.
"""

from __future__ import annotations

import difflib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .port_types import KINDS, float64_holds
from .model import Model, settable
from .ports import variable_width



@dataclass
class Assignment:
    """A start value to set: one variable (scalar or FMI 3 array) and its converted values."""

    name: str
    kind: str
    vr: int
    values: list


def assignments(model: Model, start_values: Mapping[str, Any]) -> list[Assignment]:
    """Start values checked and converted to the variables' types (ValueError naming the name)."""
    out: list[Assignment] = []
    for name, value in start_values.items():
        if not isinstance(name, str):
            raise ValueError(f"start_values keys must be variable names, got {name!r}")
        if name in model.variables:
            targets = [model.variables[name]]
        elif name in model.vectors:
            targets = model.vectors[name]
        else:
            raise ValueError(_unknown(model, name))
        for v in targets:
            why = settable(v)
            if why:
                raise ValueError(f"cannot set a start value for '{v.name}' of {model.shown}: {why}")
        widths = [variable_width(v) for v in targets]
        total = sum(widths)
        seq = isinstance(value, (list, tuple, np.ndarray))
        values = list(np.asarray(value, dtype=object).ravel()) if seq else [value] * total
        if len(values) != total:
            raise ValueError(f"start value of '{name}' must have {total} entries (one per element), "
                             f"got {len(values)}")
        pos = 0
        for v, w in zip(targets, widths):
            converted = [convert(v.type, x, v.name, model.major) for x in values[pos:pos + w]]
            pos += w
            if v.causality == "input" and v.type in KINDS[model.major]:
                _check_port_exact(v.name, converted)
            out.append(Assignment(v.name, v.type, v.valueReference, converted))
    return out


def input_starts(model: Model, assignments: list[Assignment]) -> dict[str, np.ndarray]:
    """The value each input port holds when unconnected: its start values (those of
    ``start_values`` over those of the modelDescription; 0 where there is none)."""
    given = {a.vr: a.values for a in assignments}
    by_vr = {v.valueReference: v for v in model.variables.values()
             if v.causality == "input" and v.alias is None}
    out = {}
    for port in model.inputs.values():
        values: list[float] = []
        for vr in port.vrs:
            v = by_vr[vr]
            width = variable_width(v)
            start = given.get(vr) or start_of(v) or [0.0]
            if len(start) not in (1, width):
                start = [0.0]
            values.extend(float(x) for x in (start if len(start) == width else start * width))
        out[port.name] = np.array(values, dtype=float)
    return out


def _unknown(model: Model, name: str) -> str:
    settable_names = [n for n, v in model.variables.items() if not settable(v)]
    settable_names += [b for b, vs in model.vectors.items() if all(not settable(v) for v in vs)]
    close = difflib.get_close_matches(name, settable_names, n=1) or difflib.get_close_matches(
        name, list(model.variables) + list(model.vectors), n=1)
    hint = f"did you mean '{close[0]}'? " if close else ""
    shown = ", ".join(sorted(settable_names)[:12]) + (", ..." if len(settable_names) > 12 else "")
    return (f"unknown variable '{name}' in start_values: {model.shown} has no such variable "
            f"({hint}settable variables: {shown or 'none'})")


def convert(kind: str, value: Any, name: str, major: int) -> Any:
    """One start value converted to the variable's type ``kind`` (as the FMU names it), or ValueError."""
    port_kind = KINDS[major].get(kind)
    if port_kind is not None and port_kind.is_float:
        if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
            raise ValueError(f"start value of '{name}' must be a number, got {value!r}")
        return float(value)
    if port_kind is not None and port_kind.low is not None:
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            value = int(value)
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise ValueError(f"start value of '{name}' must be an integer ({kind}), got {value!r}")
        if not port_kind.low <= int(value) <= port_kind.high:
            raise ValueError(f"start value of '{name}' is out of range for {kind}: {value!r}")
        return int(value)
    if kind == "Boolean":
        if isinstance(value, (bool, np.bool_)) or value in (0, 1):
            return bool(value)
        raise ValueError(f"start value of '{name}' must be true or false, got {value!r}")
    if kind == "String":
        if not isinstance(value, str):
            raise ValueError(f"start value of '{name}' must be text, got {value!r}")
        return value
    raise ValueError(f"start values of {kind} variables such as '{name}' are not supported")


def _check_port_exact(name: str, values: list) -> None:
    """ValueError if an input's start value would change on its way through a float64 port
    (the block writes its inputs' values, so an unconnected input passes its start through one)."""
    for x in values:
        if isinstance(x, int) and not isinstance(x, bool) and not float64_holds(x):
            raise ValueError(f"start value of '{name}' is {x}, which its float64 port cannot hold exactly "
                             "(integers are exact up to 2^53); use a value a float64 holds")


def start_of(v: Any) -> list | None:
    """A variable's modelDescription start, converted to its type (None if it has none,
    or one that does not read as its type)."""
    if v.start is None:
        return None
    text = str(v.start)
    if v.type == "String":
        return [text]
    try:
        if v.type == "Boolean":
            return [{"true": True, "false": False, "1": True, "0": False}[x] for x in text.split()]
        if v.type == "Integer" or v.type == "Enumeration" or "Int" in v.type:
            return [int(x) for x in text.split()]
        return [float(x) for x in text.split()]
    except (KeyError, ValueError):
        return None
