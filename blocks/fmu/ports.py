"""How an FMU's input and output variables become the block's ports.

Scalars named ``x[1]``, ``x[2]``, ... (and ``A[1,1]``, ``A[1,2]``, ... row-major) form one
vector port ``x``, an FMI 3 array variable is one port of its flattened size, and port
names are the variable names made identifiers (``body.v[2]`` -> ``body_v``); the rules
for users are in the package docstring. ``group_variables`` builds the ports and refuses
what cannot be one port (gaps in the indices, mixed types, two names mapping to one port
name), ``Port.labels`` keeps the FMU's own element indices for the CSV columns, and
``groups`` lays the ports of one FMI type out for a single get or set call, which is what
an instance preallocates. ``initial_reads`` turns the modelDescription's InitialUnknowns
into the block's ``initial_feedthrough``.
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from .description import variable_unit
from .port_types import KINDS, PortKind

_INDEXED = re.compile(r"^(?P<base>.*[^\s])\[(?P<index>\s*\d+\s*(?:,\s*\d+\s*)*)\]$")
_NOT_IDENT = re.compile(r"[^A-Za-z0-9_]")


@dataclass
class Port:
    """One port: the FMU variables (value references) behind it, in port order."""

    name: str
    kind: PortKind
    vrs: list[int]
    width: int
    source: str               # the variable or vector name in the FMU, for messages
    labels: list[str] | None = None   # the FMU's own element indices ("1", "1,2"), if a vector
    units: str | list[str] | None = None  # the variables' units (one per element where they differ)


@dataclass
class Group:
    """Ports of one FMI type read or written with one call: values laid out port by port."""

    kind: PortKind
    vrs: list[int]
    count: int
    slices: list[tuple[str, int, int]] = field(default_factory=list)


def port_name(base: str) -> str:
    """The port name of a variable (or vector) name: an identifier."""
    name = _NOT_IDENT.sub("_", base)
    return "_" + name if not name or name[0].isdigit() else name


def variable_width(v: Any) -> int:
    """How many values a variable holds: 1, or an FMI 3 array's flattened size."""
    shape = getattr(v, "shape", None) or ()
    return int(math.prod(shape)) if v.dimensions else 1


def element_of(v: Any) -> tuple[str, tuple[int, ...]] | None:
    """``("x", (1, 2))`` for a scalar named ``x[1,2]``, None for any other variable."""
    return None if v.dimensions else indexed_name(v.name)


def indexed_name(name: str) -> tuple[str, tuple[int, ...]] | None:
    """``("x", (1, 2))`` for the name ``x[1,2]``, None for a name without indices."""
    m = _INDEXED.match(name)
    return (m.group("base"), tuple(int(i) for i in m.group("index").split(","))) if m else None


def port_of(name: str) -> tuple[str, str | None]:
    """The port a scalar variable named ``name`` is (part of) and its element label there:
    ``("p_e", "2")`` for ``p.e[2]``, ``("k", None)`` for ``k`` (a whole port)."""
    element = indexed_name(name)
    if element is None:
        return port_name(name), None
    return port_name(element[0]), ",".join(map(str, element[1]))


def group_variables(variables: list, what: str, fmu: str, major: int) -> dict[str, Port]:
    """Ports from variables: ``x[i]`` (and ``x[i,j]``) scalars become one vector per base name."""
    bases: dict[str, list[tuple[tuple[int, ...] | None, Any]]] = {}
    for v in variables:
        element = element_of(v)
        if element:
            bases.setdefault(element[0], []).append((element[1], v))
        else:
            bases.setdefault(v.name, []).append((None, v))
    ports: dict[str, Port] = {}
    origin: dict[str, str] = {}
    for base, items in bases.items():
        if len(items) == 1 and items[0][0] is None:
            v = items[0][1]
            width = variable_width(v)
            if width < 1:
                raise ValueError(f"{what} '{v.name}' of {fmu} is an array of size 0")
            port = Port(port_name(base), KINDS[major][v.type], [v.valueReference], width, v.name,
                        _array_labels(v) if width > 1 else None, variable_unit(v))
        else:
            port = _vector_port(base, items, what, fmu, major)
        if port.name in ports:
            raise ValueError(f"{what}s of {fmu}: '{origin[port.name]}' and '{port.source}' both map to "
                             f"the port name '{port.name}'")
        ports[port.name] = port
        origin[port.name] = port.source
    return ports


def _vector_port(base: str, items: list[tuple[tuple[int, ...] | None, Any]], what: str, fmu: str,
                 major: int) -> Port:
    """The vector port of the scalars ``base[i]`` (``base[i,j]``), which must number 1..n."""
    if any(index is None for index, _ in items):
        raise ValueError(f"{what}s of {fmu}: '{base}' is both a variable and the vector "
                         f"{base}[...]; cannot make one port of them")
    ranks = {len(index) for index, _ in items}
    if len(ranks) > 1:
        raise ValueError(f"{what}s of {fmu}: '{base}[...]' mixes indices of different "
                         "dimensions")
    items.sort(key=lambda item: item[0])
    indices = [index for index, _ in items]
    dups = [i for i, j in itertools.pairwise(indices) if i == j]
    if dups:
        raise ValueError(f"{what}s of {fmu}: '{base}[{','.join(map(str, dups[0]))}]' "
                         "occurs twice")
    shape = tuple(max(index[d] for index in indices) for d in range(len(indices[0])))
    expected = list(itertools.product(*(range(1, n + 1) for n in shape)))
    if indices != expected:
        missing = sorted(set(expected) - set(indices))
        found = ", ".join(f"{base}[{','.join(map(str, i))}]" for i in indices[:6])
        more = ", ..." if len(indices) > 6 else ""
        if missing:
            detail = f"{base}[{','.join(map(str, missing[0]))}] is missing"
        else:
            detail = "indices must start at 1"
        raise ValueError(f"{what}s of {fmu}: the elements of vector '{base}' must be numbered "
                         f"1..n without gaps, but {detail} (found {found}{more})")
    kinds = {v.type for _, v in items}
    if len(kinds) > 1:
        raise ValueError(f"{what}s of {fmu}: vector '{base}' mixes the types "
                         f"{', '.join(sorted(kinds))}")
    units = [variable_unit(v) for _, v in items]
    return Port(port_name(base), KINDS[major][items[0][1].type], [v.valueReference for _, v in items],
                len(items), f"{base}[...]", [",".join(map(str, i)) for i in indices], _port_units(units))


def _port_units(units: list[str | None]) -> str | list[str] | None:
    """The units of a vector port's scalars: one string if they share it, None if none has
    one, else one string per element ("" where a scalar has none)."""
    if all(u == units[0] for u in units):
        return units[0]
    return [u or "" for u in units]


def _array_labels(v: Any) -> list[str]:
    """Element indices of an FMI 3 array variable, counted from 1 as FMI does, row-major."""
    shape = [int(n) for n in (getattr(v, "shape", None) or ())]
    return [",".join(map(str, i)) for i in itertools.product(*(range(1, n + 1) for n in shape))]


def vectors(variables: list, names: Mapping[str, Any]) -> dict[str, list]:
    """The scalars ``x[1]``, ``x[2]``, ... of every vector ``x`` that is not itself a variable
    in ``names``, in index order: what a start value given for ``x`` sets."""
    indexed: dict[str, list[tuple[tuple[int, ...], Any]]] = {}
    for v in variables:
        element = element_of(v)
        if element and element[0] not in names:
            indexed.setdefault(element[0], []).append((element[1], v))
    return {b: [v for _, v in sorted(items, key=lambda i: i[0])] for b, items in indexed.items()}


def groups(ports: dict[str, Port]) -> list[Group]:
    """The ports laid out by FMI type, one group (one get or set call) per type."""
    out: dict[str, Group] = {}
    for port in ports.values():
        g = out.setdefault(port.kind.name, Group(port.kind, [], 0))
        g.vrs.extend(port.vrs)
        g.slices.append((port.name, g.count, g.count + port.width))
        g.count += port.width
    return list(out.values())


def initial_reads(md: Any, inputs: dict[str, Port], outputs: dict[str, Port]) -> dict[str, frozenset[str]]:
    """For each output port, the input ports its value at initialisation depends on.

    The modelDescription's InitialUnknowns say which inputs each output depends on
    (all of them when the list is absent; none for an output not listed, whose start
    is exact). An FMU is initialised once, as a whole, at its first output, so every
    output waits for the union of those inputs.
    """
    port_of_vr = {vr: p.name for p in inputs.values() for vr in p.vrs}
    reads: set[str] = set()
    for u in md.initialUnknowns:
        if u.variable is None or u.variable.causality != "output":
            continue
        if u.dependencies is None:
            reads = set(inputs)
            break
        reads |= {port_of_vr[d.valueReference] for d in u.dependencies if d.valueReference in port_of_vr}
    return {name: frozenset(reads) for name in outputs}


def direct_reads(md: Any, inputs: dict[str, Port], outputs: dict[str, Port]) -> dict[str, frozenset[str]]:
    """For each output port, the input ports its value depends on at a communication point
    (the modelDescription's ModelStructure Outputs: all inputs where an output's list is
    absent, none where it is empty), for the FMU block's ``feedthrough``."""
    port_of_vr = {vr: p.name for p in inputs.values() for vr in p.vrs}
    port_of_output = {vr: p.name for p in outputs.values() for vr in p.vrs}
    reads: dict[str, set[str]] = {name: set() for name in outputs}
    for u in md.outputs:
        port = port_of_output.get(getattr(u.variable, "valueReference", None))
        if port is None:
            continue
        if u.dependencies is None:
            reads[port] |= set(inputs)
        else:
            reads[port] |= {port_of_vr[d.valueReference] for d in u.dependencies if d.valueReference in port_of_vr}
    return {name: frozenset(found) for name, found in reads.items()}
