"""An SSD system's connections said to a ``DiagramBuilder``: wires, conversions, held inputs.

SSP 1.0 (5.3.2): a connection's start and end say nothing of its direction; the data
flows from the end whose connector is a source (an element's output, a system's input)
to the other (an element's input, a system's output), whichever is written first. On a
connection, the automatic unit conversion between its connectors' units comes first and
its ``ssc:LinearTransformation`` after it, on the converted value (4.5.2.1:
``target = factor * converted + offset``; with ``suppressUnitConversion`` the
transformation alone); both become a ``Gain`` and/or a ``Bias`` block between the ends.
Units convert as ``ssd:Units`` define them, else as pint knows them; an unknown unit is
left to the builder, which compares the units it knows.

A connection at a nested system's own connector is one of the subsystem's inputs or
outputs. A connection from a system's ``kind="parameter"`` connector to an element's
parameter (a component's, or a nested system's parameter connector) passes the value the
system's bindings give its connector on to that parameter, converted and transformed as a
signal is, after every binding of the file is read (``Element.links``; OMSimulator exports
system parameters so), and wins over the element's own bindings. A system or element
named ``""`` is the system itself, as OMSimulator writes it. An input connector of the top-level system has nothing outside to feed it, so it
becomes a ``Constant`` block of its name, holding the value a binding of the top-level
system gives the connector (converted into its unit), else the start value of the FMU
inputs it feeds (through the conversions on the way; SSP 2.0: an unconnected input keeps
its default), else 0: ``--set NAME.value=...`` sets it, as OMSimulator's ``setReal`` sets
a top-level input.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from blocks.builder.context import known, suggest
from blocks.builder.diagram_builder import DiagramBuilder
from blocks.builder.records import Site

from ..fmu.ports import port_name, port_of
from .conversion import UnitError, UnknownUnit, conversion
from .parameters import BindingError
from .xml import elements, finite, local, shown

CONNECTION_PARTS = ("ConnectionGeometry", "Annotations")
SOURCES = {True: ("input", "parameter"), False: ("output", "calculatedParameter")}
"""The kinds of connector data flows out of: of a system (True), of an element (False)."""
SIGNALS = ("input", "output")
"""The kinds of connector a wire joins (parameters are set by bindings)."""


@dataclass(frozen=True)
class End:
    """One end of a connection: as a wire end (``comp.q[3]``, ``sub.port``; ``:name`` for
    the system's own connector), its connector's kind and unit, and how messages name it."""

    text: str
    kind: str
    unit: str | None
    system: bool
    shown: str
    element: str | None = None
    connector: str = ""

    @property
    def source(self) -> bool:
        return self.kind in SOURCES[self.system]


class Wiring:
    """The connections of one system (``me``, an ``Element``) said to its builder ``b``;
    ``reader`` reports (its ``fail``, ``file`` and ``units``). ``top``: the SSD's own system."""

    def __init__(self, reader: Any, b: DiagramBuilder, me: Any, top: bool):
        self.reader, self.b, self.me, self.top = reader, b, me, top
        self.inputs: dict[str, list[str]] = {}
        self.outputs: dict[str, str] = {}
        self.fed: dict[str, list[tuple[End, float, float]]] = {}
        """The element ends each of the system's input connectors feeds, with the (factor,
        offset) on the way: where a top-level input's start value comes from."""
        self.count = 0

    def fail(self, line: int | None, message: str, hint: str = "") -> None:
        self.reader.fail(line, message, hint)

    def connect_all(self, connections: list) -> None:
        for conn in connections:
            self.connection(conn)
        me, file = self.me, self.reader.file
        for name, targets in self.inputs.items():
            where = Site(file, me.connectors[name].line)
            if self.top:
                self.held_input(name, targets, where)
            else:
                self.b.input(port_name(name), *targets, where=where)
        for name, source in self.outputs.items():
            self.b.output(port_name(name), source, where=Site(file, me.connectors[name].line))

    def connection(self, conn: Any) -> None:
        line = conn.sourceline
        if conn.get("startIndices") is not None or conn.get("endIndices") is not None:
            self.fail(line, "ssd:Connection startIndices/endIndices (array connectors) are not supported",
                      "connect element connectors such as q[3] instead")
            return
        ends = [self.end(conn.get(f"{which}Element"), conn.get(f"{which}Connector"), which, line)
                for which in ("start", "end")]
        if None in ends:
            return
        flow = self.flow(ends[0], ends[1], line)
        transform = self.transformation(conn)
        if flow is None or transform is None:
            return
        (src, dst), (factor, offset) = flow, transform
        if conn.get("suppressUnitConversion") not in ("true", "1"):
            converted = self.conversion(src.unit, dst.unit, line)
            if converted is None:
                return
            factor, offset = factor * converted[0], factor * converted[1] + offset
        if src.kind == "parameter":
            self.me.links.append((src.connector, dst.element, dst.connector, (factor, offset), line))
            return
        if src.system:
            self.fed.setdefault(src.connector, []).append((dst, factor, offset))
        where = Site(self.reader.file, line)
        if factor == 1.0 and offset == 0.0:
            self.wire(src.text, dst.text, where)
            return
        self.count += 1
        stem = f"_lt{self.count}"
        while any(n in self.me.elements for n in (stem, f"{stem}_gain", f"{stem}_bias")):  # the user's names
            stem = "_" + stem
        chain: list[str] = []
        if factor != 1.0:
            self.b.add(f"{stem}_gain", "Gain", params={"k": factor}, where=where)
            chain.append(f"{stem}_gain")
        if offset != 0.0:
            self.b.add(f"{stem}_bias", "Bias", params={"bias": offset}, where=where)
            chain.append(f"{stem}_bias")
        if len(chain) == 2:
            self.b.connect(f"{chain[0]}.y", f"{chain[1]}.u", where=where)
        self.wire(src.text, f"{chain[0]}.u", where)
        self.wire(f"{chain[-1]}.y", dst.text, where)

    def transformation(self, conn: Any) -> tuple[float, float] | None:
        """The (factor, offset) of the connection's ``ssc:LinearTransformation`` ((1, 0):
        none); None (reported) for another transformation or one that is not numbers."""
        factor, offset = 1.0, 0.0
        for part in elements(conn):
            what = local(part)
            if what in CONNECTION_PARTS:
                continue
            if what != "LinearTransformation":
                self.fail(part.sourceline, f"ssc:{what} on a connection is not supported", "ssc:LinearTransformation is")
                return None
            try:
                factor, offset = finite(part.get("factor", "1")), finite(part.get("offset", "0"))
            except ValueError:
                self.fail(part.sourceline, "ssc:LinearTransformation: factor and offset must be finite numbers")
                return None
        return factor, offset

    def flow(self, a: End, b: End, line: int | None) -> tuple[End, End] | None:
        """The connection's ends as (source, destination), by their kinds; None (reported)
        for two sources, two destinations, or a parameter connector."""
        for end in (a, b):
            if end.kind not in (*SOURCES[True], *SOURCES[False]):
                self.fail(line, f"ssd:Connection at {end.shown} of kind '{end.kind}' is not supported",
                          "connectors of FMU components and systems are inputs, outputs and parameters")
                return None
        if a.source == b.source:
            which = "sources" if a.source else "destinations"
            self.fail(line, f"ssd:Connection joins {a.shown} of kind '{a.kind}' and {b.shown} of kind '{b.kind}': "
                      f"both are {which} of data", "a connection joins an element's output (or a system's input) "
                      "to an element's input (or a system's output)")
            return None
        src, dst = (a, b) if a.source else (b, a)
        if src.system and src.kind == "parameter" and not dst.system and dst.kind == "parameter":
            return src, dst
        for end in (src, dst):
            if end.kind not in SIGNALS:
                self.fail(line, f"ssd:Connection at {end.shown} of kind '{end.kind}' is not supported",
                          "set a parameter with a parameter binding (ssd:ParameterBindings) instead")
                return None
        return src, dst

    def end(self, element: str | None, connector: str | None, which: str, line: int | None) -> End | None:
        """A connection's end; None (reported) if it names nothing."""
        me = self.me
        if not connector:
            self.fail(line, f"ssd:Connection needs a {which}Connector")
            return None
        if not element:
            c = me.connectors.get(connector)
            if c is None:
                self.fail(line, f"ssd:Connection {which}Connector {shown(connector)}: the system has no connector "
                          "of that name", suggest(connector, list(me.connectors)) or
                          f"its connectors: {known(list(me.connectors))}")
                return None
            return End(f":{connector}", c.kind, c.unit, True, f"the system's connector '{connector}'", None, connector)
        found = me.elements.get(element)
        if found is None:
            names = list(me.elements)
            self.fail(line, f"ssd:Connection {which}Element {shown(element)}: no element of that name in the system",
                      suggest(element, names) or f"its elements: {known(names)}")
            return None
        c = found.connectors.get(connector)
        if c is None:
            names = list(found.connectors)
            self.fail(line, f"ssd:Connection {which}Connector {shown(connector)}: element '{element}' declares no "
                      "connector of that name", suggest(connector, names) or f"its connectors: {known(names)}")
            return None
        if found.kind == "system":
            if not found.elements and c.kind in SIGNALS:
                self.fail(line, f"ssd:Connection at {element}.{connector}: the system '{element}' has no elements",
                          "connect to a system of components")
                return None
            text = f"{element}.{port_name(connector)}"
        else:
            port, label = port_of(connector)
            text = f"{element}.{port}" if label is None else f"{element}.{port}[{label}]"
        return End(text, c.kind, c.unit, False, f"{element}.{connector}", element, connector)

    def conversion(self, a: str | None, b: str | None, line: int | None) -> tuple[float, float] | None:
        """(factor, offset) from unit ``a`` to ``b``; (1, 0) when either is not given or
        not known; None (reported) when they do not convert."""
        if a is None or b is None:
            return 1.0, 0.0
        try:
            return conversion(a, b, self.reader.units)
        except UnknownUnit:
            return 1.0, 0.0  # the builder compares the units it knows
        except UnitError:
            self.fail(line, f"ssd:Connection from unit '{a}' to unit '{b}': they measure different quantities",
                      "connect connectors of one quantity, or set suppressUnitConversion and convert with an "
                      "ssc:LinearTransformation")
            return None

    def wire(self, src: str, dst: str, where: Site) -> None:
        """A wire, or an end at the system's own connector (``:name``): an input fed, an output given."""
        if src.startswith(":"):
            self.inputs.setdefault(src[1:], []).append(dst)
        elif dst.startswith(":"):
            if dst[1:] in self.outputs:
                self.fail(where.line, f"the system's output connector '{dst[1:]}' is connected twice")
            self.outputs[dst[1:]] = src
        else:
            self.b.connect(src, dst, where=where)

    def held_input(self, name: str, targets: list[str], where: Site) -> None:
        """A top-level input connector: a ``Constant`` of its name feeding ``targets``, at
        the value a binding gives the connector, else the start value of the FMU inputs it
        feeds (SSP 2.0, 5.3.1: an unconnected input keeps its default value), else 0."""
        me = self.me
        block = port_name(name)
        while block in me.elements:
            block = "_" + block
        connector, bound = me.connectors[name], me.values.get(name)
        if bound is not None:
            try:
                value = bound.value_in(connector.unit, self.reader.units)
            except BindingError as exc:
                self.reader.fail(exc.line, str(exc), exc.hint, file=exc.file)
                return
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                self.reader.fail(bound.line, f"the system's input connector '{name}' is bound to {value!r}, not a "
                                 "number", file=bound.file)
                return
        else:
            value = self.start_value(name)
        self.b.add(block, "Constant", params={"value": float(value)}, where=where)
        if connector.unit:
            self.b.annotate(f"{block}.y", units=connector.unit, where=where)
        for target in targets:
            self.b.connect(f"{block}.y", target, where=where)

    def start_value(self, name: str) -> float:
        """The value of the system's input ``name`` that gives the FMU inputs it feeds their
        start values (through the conversions on the way), where they all declare one and
        agree; else 0."""
        found = set()
        for end, factor, offset in self.fed.get(name, []):
            start = self.reader.start_of(self.me.elements[end.element], end.connector)
            if start is None or factor == 0.0:
                return 0.0
            found.add((start - offset) / factor)
        return found.pop() if len(found) == 1 else 0.0
