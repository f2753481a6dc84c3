"""An SSP as a diagram: its SystemStructure.ssd said to a ``DiagramBuilder``.

This is a front end, as the YAML loader is: it reads what only the SSD can get wrong
(its XML, the elements and attributes it uses, references to elements and connectors,
the files it names) and says the rest to the builder, each entry at the SSD line it is
written at, so that the diagram's checks (ports, widths, units, loops, periods) are the
builder's. The translation:

- ``ssd:Component`` (an FMU) -> an ``FMU`` block: ``path`` its ``source``, ``start_values``
  its parameter bindings, ``interface`` from ``implementation``, its period from the step
  annotations (``blocks.ssp.steps``): its ``osp:StepSizeHint`` (on libcosim's grid when an
  ``osp:FixedStepAlgorithm`` gives one), else its system's OMSimulator ``FixedStepMaster``,
  else the base step, else the step given to ``read_ssp`` (``--step``); none of them is
  an error naming the component;
- a nested ``ssd:System`` -> a subsystem of its components, whose ports are its
  connectors (inputs feed the inner connections that start at them, outputs are the one
  that ends at them);
- ``ssd:Connection`` -> a wire, an element connector (``q[3]``, an FMU's vector element)
  a connection by element (``plant.q[3]``); an ``ssc:LinearTransformation`` on it a
  ``Gain`` and/or ``Bias`` block between its ends, as is a unit conversion between two
  connectors whose units (``ssd:Units``) differ in factor or offset;
- parameter bindings of a system name their parameters ``element.parameter`` (through
  nested systems ``sub.element.parameter``) and win over the component's own;
- ``ssd:DefaultExperiment`` stopTime -> the end time; a connector's ``unit`` -> the port's
  unit, checked against the FMU's own and the other end's by the builder.

Every output is logged. What is not supported (signal dictionaries, array connectors
and indices, components that are not FMUs, other transformations, a start time other
than 0) is one error naming the element and its line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

from blocks.builder.context import known, suggest
from blocks.builder.diagram_builder import DiagramBuilder
from ..fmu.ports import port_name, port_of
from ..issues import DiagramError, Issue
from blocks.builder.records import Site
from blocks.builder.scopes import NAME
from ..timebase import DurationError, positive_duration
from .package import Package, PackageError, open_package
from .parameters import BindingError, binding_values, finite
from .steps import base_step, feedthrough, libcosim_period, step_hint, system_step
from .xml import XmlError, child, children, elements, exact, local, parse_file, q, shown

FMU_TYPE = "application/x-fmu-sharedlibrary"
IMPLEMENTATIONS = {"any": None, "CoSimulation": "co_simulation", "ModelExchange": "model_exchange"}
CONNECTION_PARTS = ("ConnectionGeometry", "Annotations")
STEP_HINT = ("add <ssd:Annotations><ssc:Annotation type='com.opensimulationplatform'><osp:StepSizeHint "
             "value='0.001'/>... to it, or pass --step (Python: read_ssp(..., step='1 ms'))")


@dataclass
class Connector:
    """A connector as the SSD declares it: its kind, unit and line."""

    name: str
    kind: str
    unit: str | None
    line: int | None


@dataclass
class Element:
    """An element of a system: a component (its ``start_values``) or a nested system."""

    kind: str
    connectors: dict[str, Connector]
    start_values: dict[str, Any] = field(default_factory=dict)
    system: "Element | None" = None
    elements: dict[str, "Element"] = field(default_factory=dict)


def read_ssp(path: str | Path, trust: bool = False, step: Any = None) -> DiagramBuilder:
    """The builder of the SSP ``path`` (a ``.ssp`` archive, a folder with SystemStructure.ssd,
    or that ``.ssd`` file), not built yet. ``step``: the communication step of components
    whose SSD gives none (a duration). DiagramError if it cannot be read as a diagram."""
    try:
        package = open_package(path)
    except PackageError as exc:
        message = str(exc).removeprefix(f"{path}: ")
        raise DiagramError([Issue(str(path), None, message, "an SSP is a zip archive (.ssp) or a folder with "
                                  "SystemStructure.ssd")]) from None
    return _Reader(package, trust, step).read()


class _Reader:
    def __init__(self, package: Package, trust: bool, step: Any):
        self.package = package
        self.trust = trust
        self.cli_step = step
        self.file = package.where(package.ssd)
        self.b: DiagramBuilder | None = None
        self.base: Fraction | None = None
        self.units: dict[str, tuple[tuple, float, float]] = {}
        self.texts: list[str] = []

    # -- reporting ---------------------------------------------------------------------

    def fail(self, line: int | None, message: str, hint: str = "", name: str | None = None,
             file: str | None = None) -> None:
        self.b.fail(Issue(file or self.file, line, message, hint), name)

    def site(self, element: Any) -> Site:
        return Site(self.file, element.sourceline if element is not None else None)

    def read_xml(self, path: Path) -> tuple[Any, str]:
        root, text = parse_file(path)
        self.texts.append(text)
        return root, text

    # -- the file ----------------------------------------------------------------------

    def read(self) -> DiagramBuilder:
        try:
            root, _ = self.read_xml(self.package.ssd)
        except XmlError as exc:
            raise DiagramError([Issue(self.file, exc.line, str(exc))]) from None
        if root.tag != q("ssd", "SystemStructureDescription"):
            raise DiagramError([Issue(self.file, root.sourceline, f"expected an ssd:SystemStructureDescription, "
                                      f"found <{local(root)}>", "is this an SSP's SystemStructure.ssd?")])
        system = child(root, "ssd", "System")
        b = self.b = DiagramBuilder(root.get("name") or Path(self.package.shown).stem,
                                    (system.get("description") if system is not None else None) or "",
                                    base_dir=self.package.ssd.parent, trust=self.trust, where=self.site(root))
        b.label = self.file
        if system is None:
            self.fail(root.sourceline, "the SSD has no ssd:System")
            return b
        self.experiment(child(root, "ssd", "DefaultExperiment"))
        self.read_units(child(root, "ssd", "Units"))
        self.system(system, b, None)
        b.log_all(where=self.site(system))
        b.texts.extend(self.texts)
        return b

    def experiment(self, experiment: Any) -> None:
        if experiment is None:
            return
        start = experiment.get("startTime")
        if start is not None and _number(start)[0] != 0:
            self.fail(experiment.sourceline, f"ssd:DefaultExperiment startTime {shown(start)} is not supported",
                      "runs start at t = 0: leave startTime out or make it 0")
        stop = experiment.get("stopTime")
        if stop is not None:
            value = self.step_value(stop, experiment.sourceline, "ssd:DefaultExperiment stopTime")
            if value is not None:
                self.b.t_end = value
                self.b.t_end_site = self.site(experiment)
        found = base_step(experiment)
        if found is not None:
            self.base = self.step_value(found[0], found[1], "osp:FixedStepAlgorithm baseStepSize")

    def read_units(self, units: Any) -> None:
        """``ssd:Units``: each unit's base-unit exponents, factor and offset."""
        for unit in children(units, "ssc", "Unit"):
            base = child(unit, "ssc", "BaseUnit")
            if base is None or not unit.get("name"):
                continue
            attrs = dict(base.attrib)
            try:
                factor, offset = finite(attrs.pop("factor", "1")), finite(attrs.pop("offset", "0"))
                exponents = tuple(sorted((k, int(v)) for k, v in attrs.items() if int(v) != 0))
            except ValueError:
                self.fail(base.sourceline, f"ssc:Unit {shown(unit.get('name'))}: its ssc:BaseUnit attributes must "
                          "be numbers: finite factor and offset, whole exponents")
                continue
            if factor == 0:
                self.fail(base.sourceline, f"ssc:Unit {shown(unit.get('name'))}: its factor is 0",
                          "a unit's factor is its size in the SI base units: 1000 for km")
                continue
            self.units[unit.get("name")] = (exponents, factor, offset)

    def step_value(self, text: str, line: int | None, what: str) -> Fraction | None:
        value, problem = _number(text)
        if value is None or value <= 0:
            self.fail(line, f"{what} {shown(text)} is not a positive number of seconds{problem}")
            return None
        return value

    # -- systems -----------------------------------------------------------------------

    def system(self, element: Any, b: DiagramBuilder, inherited: Fraction | None) -> Element:
        """Say the ``ssd:System`` ``element`` to ``b``; its elements, for the bindings."""
        oms = system_step(element)
        step = self.step_value(oms[0], oms[1], "oms:FixedStepMaster stepSize") if oms else inherited
        me = Element("system", self.connectors(element, system=True))
        for unsupported in ("SignalDictionaries",):
            found = child(element, "ssd", unsupported)
            if found is not None:
                self.fail(found.sourceline, f"ssd:{unsupported} are not supported", "connect the components' "
                          "connectors directly")
        for item in elements(child(element, "ssd", "Elements")):
            name, kind = item.get("name"), local(item)
            if kind not in ("Component", "System"):
                self.fail(item.sourceline, f"ssd:{kind} {shown(name)} is not supported",
                          "a system's elements here are FMU components and systems")
                continue
            if not isinstance(name, str) or not NAME.match(name):
                self.fail(item.sourceline, f"ssd:{kind} name {shown(name)} is not usable as a block name",
                          "names of letters, digits and '_', not starting with a digit")
                continue
            if name in me.elements:
                self.fail(item.sourceline, f"two elements are named '{name}'", "give each element its own name",
                          name=name)
                continue
            if kind == "System":
                sub = DiagramBuilder(name, item.get("description") or "", base_dir=b.base_dir, trust=self.trust,
                                     where=self.site(item))
                sub.label = f"system '{name}' ({self.file}:{item.sourceline})"
                found = self.system(item, sub, step)
                b.add_subsystem(name, sub, where=self.site(item))
            else:
                found = self.component(item, name, b, step)
            if found is not None:
                me.elements[name] = found
        self.connections(element, b, me)
        self.system_bindings(element, me)
        return me

    def connectors(self, element: Any, system: bool) -> dict[str, Connector]:
        found: dict[str, Connector] = {}
        for c in children(child(element, "ssd", "Connectors"), "ssd", "Connector"):
            name, kind = c.get("name"), c.get("kind")
            if not name or not kind:
                self.fail(c.sourceline, "ssd:Connector needs a name and a kind")
                continue
            typed = [e for e in elements(c) if local(e) not in ("ConnectorGeometry", "Annotations", "Clock")]
            if any(local(e) == "Dimension" for e in typed):
                self.fail(c.sourceline, f"connector {shown(name)}: array connectors (ssc:Dimension) are not "
                          "supported", "declare one connector per element: q[1], q[2], ...")
                continue
            unit = next((e.get("unit") for e in typed if e.get("unit")), None)
            if system and not NAME.match(port_name(name)):
                self.fail(c.sourceline, f"connector {shown(name)} is not usable as a port name")
                continue
            found[name] = Connector(name, kind, unit, c.sourceline)
        return found

    # -- components --------------------------------------------------------------------

    def component(self, item: Any, name: str, b: DiagramBuilder, system_step_: Fraction | None) -> Element | None:
        line = item.sourceline
        kind = item.get("type", FMU_TYPE)
        if kind != FMU_TYPE:
            self.fail(line, f"component '{name}' of type '{kind}' is not supported", f"components are FMUs "
                      f"(type {FMU_TYPE})", name=name)
            return None
        implementation = item.get("implementation", "any")
        if implementation not in IMPLEMENTATIONS:
            self.fail(line, f"component '{name}': implementation '{implementation}' is not supported",
                      f"one of {', '.join(IMPLEMENTATIONS)}", name=name)
            return None
        try:
            fmu = self.package.resolve(item.get("source") or "")
        except PackageError as exc:
            self.fail(line, f"component '{name}': source {exc}", "an FMU of the SSP, e.g. source='resources/"
                      "plant.fmu'", name=name)
            return None
        me = Element("component", self.connectors(item, system=False))
        try:
            values = binding_values(self.package, self.file, child(item, "ssd", "ParameterBindings"), self.read_xml)
        except BindingError as exc:
            self.fail(exc.line, f"component '{name}': {exc}", exc.hint, name=name, file=exc.file)
            return None
        for v in values:
            me.start_values[v.name] = v.value
        period = self.period(item, name, system_step_)
        params: dict[str, Any] = {"path": self.package.relative(fmu), "start_values": me.start_values}
        if IMPLEMENTATIONS[implementation]:
            params["interface"] = IMPLEMENTATIONS[implementation]
        if feedthrough(item):
            params["feedthrough"] = True
        b.add(name, "FMU", period=period, params=params, where=self.site(item))
        for port, (units, line) in _port_units(me.connectors.values()).items():
            b.annotate(f"{name}.{port}", units=units, where=Site(self.file, line))
        return me

    def period(self, item: Any, name: str, system_step_: Fraction | None) -> Fraction | None:
        hint = step_hint(item)
        if hint is not None:
            value = self.step_value(hint[0], hint[1], f"component '{name}': osp:StepSizeHint")
            if value is not None and self.base is not None:
                return libcosim_period(value, self.base)
            return value
        for given in (system_step_, self.base):
            if given is not None:
                return given
        if self.cli_step is not None:
            try:
                return positive_duration(self.cli_step, "the step given")
            except DurationError as exc:
                self.fail(item.sourceline, f"component '{name}': {exc}")
                return None
        self.fail(item.sourceline, f"component '{name}' has no step size: the SSD gives no osp:StepSizeHint, "
                  "oms:FixedStepMaster or osp:FixedStepAlgorithm", STEP_HINT, name=name)
        return None

    # -- connections -------------------------------------------------------------------

    def connections(self, element: Any, b: DiagramBuilder, me: Element) -> None:
        inputs: dict[str, list[str]] = {}
        outputs: dict[str, str] = {}
        count = 0
        for conn in children(child(element, "ssd", "Connections"), "ssd", "Connection"):
            line = conn.sourceline
            if conn.get("startIndices") is not None or conn.get("endIndices") is not None:
                self.fail(line, "ssd:Connection startIndices/endIndices (array connectors) are not supported",
                          "connect element connectors such as q[3] instead")
                continue
            src = self.end(me, conn.get("startElement"), conn.get("startConnector"), True, line)
            dst = self.end(me, conn.get("endElement"), conn.get("endConnector"), False, line)
            if src is None or dst is None:
                continue
            (src_text, src_unit), (dst_text, dst_unit) = src, dst
            factor, offset = 1.0, 0.0
            for part in elements(conn):
                what = local(part)
                if what in CONNECTION_PARTS:
                    continue
                if what != "LinearTransformation":
                    self.fail(part.sourceline, f"ssc:{what} on a connection is not supported",
                              "ssc:LinearTransformation is")
                    src = None
                    break
                try:
                    factor, offset = float(part.get("factor", "1")), float(part.get("offset", "0"))
                except ValueError:
                    self.fail(part.sourceline, "ssc:LinearTransformation: factor and offset must be numbers")
                    src = None
            if src is None:
                continue
            if conn.get("suppressUnitConversion") not in ("true", "1"):
                conversion = self.conversion(src_unit, dst_unit, line)
                if conversion is None:
                    continue
                factor, offset = factor * conversion[0], offset * conversion[0] + conversion[1]
            where = Site(self.file, line)
            if factor != 1.0 or offset != 0.0:
                count += 1
                stem = f"_lt{count}"
                while any(n in me.elements for n in (stem, f"{stem}_gain", f"{stem}_bias")):  # the user's names
                    stem = "_" + stem
                chain_in = chain_out = None
                if factor != 1.0:
                    b.add(f"{stem}_gain", "Gain", params={"k": factor}, where=where)
                    chain_in = chain_out = f"{stem}_gain"
                if offset != 0.0:
                    b.add(f"{stem}_bias", "Bias", params={"bias": offset}, where=where)
                    if chain_out is not None:
                        b.connect(f"{chain_out}.y", f"{stem}_bias.u", where=where)
                    chain_in = chain_in or f"{stem}_bias"
                    chain_out = f"{stem}_bias"
                self.wire(b, src_text, f"{chain_in}.u", inputs, outputs, where)
                self.wire(b, f"{chain_out}.y", dst_text, inputs, outputs, where)
            else:
                self.wire(b, src_text, dst_text, inputs, outputs, where)
        for name, targets in inputs.items():
            b.input(port_name(name), *targets, where=Site(self.file, me.connectors[name].line))
        for name, source in outputs.items():
            b.output(port_name(name), source, where=Site(self.file, me.connectors[name].line))

    def wire(self, b: DiagramBuilder, src: str, dst: str, inputs: dict, outputs: dict, where: Site) -> None:
        """A wire, or an end at the system's own connector (``("", name)``): an input fed,
        an output given."""
        if src.startswith(":"):
            inputs.setdefault(src[1:], []).append(dst)
        elif dst.startswith(":"):
            if dst[1:] in outputs:
                self.fail(where.line, f"the system's output connector '{dst[1:]}' is connected twice")
            outputs[dst[1:]] = src
        else:
            b.connect(src, dst, where=where)

    def end(self, me: Element, element: str | None, connector: str | None, start: bool,
            line: int | None) -> tuple[str, str | None] | None:
        """A connection's end as a wire end (``comp.q[3]``, ``sub.port``; ``:name`` for the
        system's own connector) and its declared unit; None (reported) if it names nothing."""
        which = "start" if start else "end"
        if not connector:
            self.fail(line, f"ssd:Connection needs a {which}Connector")
            return None
        if element is None:
            c = me.connectors.get(connector)
            if c is None:
                self.fail(line, f"ssd:Connection {which}Connector {shown(connector)}: the system has no connector "
                          "of that name", suggest(connector, list(me.connectors)) or
                          f"its connectors: {known(list(me.connectors))}")
                return None
            wanted = "input" if start else "output"
            if c.kind != wanted:
                self.fail(line, f"ssd:Connection {which}s at the system's connector '{connector}' of kind "
                          f"'{c.kind}'; a connection {which}s at a system's {wanted}")
                return None
            return f":{connector}", c.unit
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
        wanted = "output" if start else "input"
        if c.kind != wanted:
            self.fail(line, f"ssd:Connection {which}s at {element}.{connector} of kind '{c.kind}'; "
                      f"a connection {which}s at an {wanted}")
            return None
        if found.kind == "system":
            return f"{element}.{port_name(connector)}", c.unit
        port, label = port_of(connector)
        return (f"{element}.{port}" if label is None else f"{element}.{port}[{label}]"), c.unit

    def conversion(self, a: str | None, b: str | None, line: int | None) -> tuple[float, float] | None:
        """(factor, offset) from unit ``a`` to ``b`` as ``ssd:Units`` define them; (1, 0) when
        they are one or either is not given; None (reported) when they do not convert."""
        if a is None or b is None or a == b:
            return 1.0, 0.0
        ua, ub = self.units.get(a), self.units.get(b)
        if ua is None or ub is None:
            return 1.0, 0.0  # the builder compares units it knows
        if ua[0] != ub[0]:
            self.fail(line, f"ssd:Connection from unit '{a}' to unit '{b}': they measure different quantities",
                      "connect connectors of one quantity, or set suppressUnitConversion and convert with an "
                      "ssc:LinearTransformation")
            return None
        factor, offset = ua[1] / ub[1], (ua[2] - ub[2]) / ub[1]
        if not (math.isfinite(factor) and math.isfinite(offset)) or factor == 0:
            self.fail(line, f"ssd:Connection from unit {shown(a)} to unit {shown(b)}: their factors and offsets "
                      "give no finite conversion")
            return None
        return factor, offset

    # -- bindings of a system ----------------------------------------------------------

    def system_bindings(self, element: Any, me: Element) -> None:
        try:
            values = binding_values(self.package, self.file, child(element, "ssd", "ParameterBindings"),
                                    self.read_xml)
        except BindingError as exc:
            self.fail(exc.line, str(exc), exc.hint, file=exc.file)
            return
        for v in values:
            target, rest = me, v.name
            while True:
                head, dot, tail = rest.partition(".")
                found = target.elements.get(head) if dot else None
                if found is None:
                    names = list(target.elements)
                    self.fail(v.line, f"parameter '{v.name}': no element '{head}' to bind it to",
                              "a system's bindings name element.parameter; elements: " + known(names),
                              file=v.file)
                    break
                if found.kind == "component":
                    found.start_values[tail] = v.value
                    break
                target, rest = found, tail


def _port_units(connectors: Any) -> dict[str, tuple[str | list[str], int | None]]:
    """The units the connectors give their components' ports, and the line that gives
    each: a whole port's connector its unit; element connectors (``q[1]``, ``q[2]``, ...)
    one unit if they all say the same, else one per element when they are the port's
    elements 1 to n, each with a unit (other mixes give none: the FMU's own stand)."""
    whole: dict[str, tuple[str, int | None]] = {}
    by_element: dict[str, dict[str, tuple[str | None, int | None]]] = {}
    for c in connectors:
        port, label = port_of(c.name)
        if label is None:
            if c.unit is not None:
                whole[port] = (c.unit, c.line)
        else:
            by_element.setdefault(port, {})[label] = (c.unit, c.line)
    found: dict[str, tuple[str | list[str], int | None]] = dict(whole)
    for port, elements_ in by_element.items():
        if port in whole:
            continue
        units = [unit for unit, _ in elements_.values()]
        line = next(iter(elements_.values()))[1]
        if None in units:
            continue
        if len(set(units)) == 1:
            found[port] = (units[0], line)
        elif sorted(elements_) == sorted(str(i) for i in range(1, len(elements_) + 1)):
            found[port] = ([elements_[str(i)][0] for i in range(1, len(elements_) + 1)], line)
    return found


def _number(text: str) -> tuple[Fraction | None, str]:
    """A time's exact value, or None and why not (`` (...)``, for a message)."""
    try:
        return exact(text), ""
    except ValueError as exc:
        return None, f" ({exc})"
