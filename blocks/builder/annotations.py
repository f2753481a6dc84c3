"""The units and element names a diagram gives ports, and the units of connected ports.

A diagram may say what the values of a port of a generic block are (``units: {plant.y:
rad}``, ``elements: {plant.y: [x, y, theta]}``, or by port on the block entry), where the
block itself does not know: a unit (one text, or one per element) and one name per
element, checked against the port's width once it is known. A block that names its own
units or elements keeps them: the diagram may repeat them, not change them. What is
given is kept on the block's spec (``BlockSpec.units``, ``BlockSpec.labels``), which run.json,
CSV columns, plots, ``validate`` and connections by label read through
``BlockSpec.port_units`` and ``BlockSpec.element_labels``. Then every connection whose two
ends both declare units is checked element by element: one unit however written
(``blocks.units``), else a load error, since a connection converts nothing.
"""

from __future__ import annotations

from typing import Any, Callable, Sequence

from blocks.block import checked_units
from blocks.builder.context import known, suggest
from blocks.builder.diagram import BlockSpec, Connection
from blocks.builder.elements import parse_endpoint
from blocks.units import differs, unit_problem

Report = Callable[[str | None, int | None, str, str], None]
"""``report(file, line, message, hint)``."""


def annotate(levels, specs: dict[str, BlockSpec], failed: set[str], report: Report) -> None:
    """Check every level's annotations and keep what they give on the blocks' specs."""
    for level in levels:
        given: set[tuple[str, str, str]] = set()
        for a in level.builder.annotations:
            site = a.site
            ep = parse_endpoint(a.signal)
            if ep is None:
                report(site.file, site.line, f"units and element names are given to a port 'block.port', not "
                       f"{a.signal!r}", "units: {plant.y: rad}")
                continue
            name, port = ep
            flat = level.flat(name)
            if name in level.failed or flat in failed:
                continue
            if name in level.subsystems:
                report(site.file, site.line, f"'{flat}' is a subsystem: give the units and element names of a "
                       "port of a block inside it, in its own file", f"units: {{<block>.{port}: ...}} there")
                continue
            spec = specs.get(flat)
            if spec is None:
                names = level.names()
                report(site.file, site.line, f"units of '{flat}.{port}': no block named '{flat}'",
                       suggest(flat, names) or f"blocks are: {known(names)}")
                continue
            block = spec.block
            width = block.outputs.get(port, block.inputs.get(port))
            if port not in block.outputs and port not in block.inputs:
                ports = [*block.inputs, *block.outputs]
                report(site.file, site.line, f"block '{flat}' ({spec.type_name}) has no port '{port}'",
                       suggest(port, ports) or f"its ports: {known(ports)}")
                continue
            for key, value in (("units", a.units), ("elements", a.elements)):
                if value is None:
                    continue
                if (flat, port, key) in given:
                    report(site.file, site.line, f"the {key} of {flat}.{port} are given twice", "give them once")
                    continue
                given.add((flat, port, key))
                problem = _keep(spec, port, width, key, value)
                if problem:
                    report(site.file, site.line, f"{key} of {flat}.{port}: {problem[0]}", problem[1])


def _keep(spec: BlockSpec, port: str, width: int | None, key: str, value: Any) -> tuple[str, str] | None:
    """Keep ``value`` as the port's units or element names; the problem with it, or None."""
    block = spec.block
    if key == "units":
        try:
            units = checked_units(value, width, port)
        except ValueError as exc:
            return str(exc), "one unit ('rad', 'N m', '1'), or a list of one per element"
        problem = next((f"{u[:40]!r} is not a unit: {unit_problem(u)}" for u in element_units(units, 1)
                        if unit_problem(u)), None)
        if problem:  # read by the unit grammar here, where the diagram gives it, never computed by pint
            return problem, "units of names, numbers, '*', '/' and whole powers ('m/s^2', 'kg m^2')"
        own = checked_units(block.port_units(port), width, port)
        if own is not None and own != units:
            return (f"block '{spec.name}' ({spec.type_name}) gives it {own!r}, the diagram {units!r}",
                    "a block's own units stand: leave them out or repeat them")
        spec.units[port] = units
        return None
    if (not isinstance(value, (list, tuple)) or not all(isinstance(x, str) and x for x in value)
            or len(set(value)) != len(value)):
        return f"must be a list of distinct names, got {value!r}", "elements: {y: [x, y, theta]}"
    if width is not None and len(value) != width:
        return f"{len(value)} names for the {width} elements of '{port}'", "one name per element"
    own = block.element_labels(port)
    if own is not None and [str(x) for x in own] != list(value):
        return (f"block '{spec.name}' ({spec.type_name}) names them {', '.join(map(str, own))}",
                "a block's own element names stand: leave them out or repeat them")
    spec.labels[port] = tuple(value)
    return None


def element_units(units: str | list[str] | None, width: int) -> list[str]:
    """A port's units, one per element (``""``: unknown)."""
    if units is None:
        return [""] * width
    return [units] * width if isinstance(units, str) else list(units)


def check_connected_units(connections: Sequence[Connection], written: dict[int, Connection],
                          specs: dict[str, BlockSpec], report: Report) -> None:
    """A connection whose two ends declare different units for an element is reported at
    its line, with the first such element."""
    for c in connections:
        src, dst = specs[c.src_block], specs[c.dst_block]
        ws, wd = src.block.outputs[c.src_port], dst.block.inputs[c.dst_port]
        try:
            su = element_units(checked_units(src.port_units(c.src_port), ws, c.src_port), ws)
            du = element_units(checked_units(dst.port_units(c.dst_port), wd, c.dst_port), wd)
        except ValueError:
            continue  # a block's own bad units fail its run, where they are read
        pairs = list(zip(c.src_elements if c.src_elements is not None else range(ws),
                         c.dst_elements if c.dst_elements is not None else range(wd)))
        bad = next(((i, j) for i, j in pairs if differs(su[i], du[j])), None)
        if bad is None:
            continue
        wire = written.get(id(c), c)
        i, j = bad
        a = wire.src if ws == 1 else f"{wire.src}[{i}]"
        b = wire.dst if wd == 1 else f"{wire.dst}[{j}]"
        report(c.file, c.line, f"connection '{wire}': units differ: {a} is in {su[i]!r}, {b} in {du[j]!r}",
               "a connection converts nothing: insert a Gain of the factor between them, or give both ends "
               "one unit")

