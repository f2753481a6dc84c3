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
  else the base step, else the step given to ``read_ssp`` (``--step``), else the FMU's
  own ``DefaultExperiment`` stepSize (as a diagram's FMU block without a period); none of
  them is an error naming the component;
- a nested ``ssd:System`` -> a subsystem of its components, whose ports are its
  connectors (inputs feed the inner connections that start at them, outputs are the one
  that ends at them);
- ``ssd:Connection`` -> a wire, its direction the data flow its connectors' kinds give
  (start and end say nothing of it, SSP 1.0 5.3.2), an element connector (``q[3]``, an
  FMU's vector element) a connection by element (``plant.q[3]``); a unit conversion
  between connectors whose units differ in factor or offset (defined by ``ssd:Units``,
  else known to pint) and then the ``ssc:LinearTransformation`` on it (SSP 1.0 4.5.2.1:
  conversion first) a ``Gain`` and/or ``Bias`` block between its ends;
- parameter bindings of a system name their parameters ``element.parameter`` (through
  nested systems ``sub.element.parameter``) and win over the component's own; a value
  with a unit is converted into its parameter's unit (the FMU variable's, else its
  ``kind="parameter"`` connector's; ``blocks.ssp.parameters``);
- an input connector of the top-level system -> a ``Constant`` block of its name, holding
  the value a top-level binding gives it, else the start of the FMU inputs it feeds, else
  0 (``blocks.ssp.connections``): ``--set NAME.value=...`` sets it;
- ``ssd:DefaultExperiment`` stopTime -> the end time; an input or output connector's
  ``unit`` -> the port's unit, checked against the FMU's own and the other end's by the
  builder.

Every output is logged. What is not supported (signal dictionaries, array connectors
and indices, components that are not FMUs, other transformations, a start time other
than 0) is one error naming the element and its line.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from fractions import Fraction
from pathlib import Path
from typing import Any

from blocks.builder.context import known
from blocks.builder.diagram_builder import DiagramBuilder
from ..fmu.description import FMUInfoError, read_description, step_of, variable_unit
from ..fmu.ports import port_name, port_of
from ..issues import DiagramError, Issue
from blocks.builder.records import Site
from blocks.builder.scopes import NAME
from ..timebase import DurationError, positive_duration
from .connections import Wiring
from .conversion import Definitions, UnitError, fmu_definitions, read_definitions
from .package import Package, PackageError, open_package
from .parameters import BindingError, Value, binding_values
from .steps import base_step, feedthrough, libcosim_period, step_hint, system_step
from .xml import XmlError, child, children, elements, exact, local, parse_file, q, shown

FMU_TYPE = "application/x-fmu-sharedlibrary"
IMPLEMENTATIONS = {"any": None, "CoSimulation": "co_simulation", "ModelExchange": "model_exchange"}
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
    """An element of a system: a component (its FMU and ``start_values``) or a nested
    system (its ``values``: those its bindings give its own connectors)."""

    kind: str
    connectors: dict[str, Connector]
    start_values: dict[str, Any] = field(default_factory=dict)
    system: "Element | None" = None
    elements: dict[str, "Element"] = field(default_factory=dict)
    fmu: Path | None = None
    md: Any = None
    """The FMU's modelDescription (fmpy's), read when a value's unit needs it; False: unreadable."""
    values: dict[str, Value] = field(default_factory=dict)
    links: list[tuple[str, str, str, tuple[float, float], int | None]] = field(default_factory=list)
    """A system's parameter connections: (its connector, element, the element's parameter,
    (factor, offset), line), applied once every binding is read (``parameters``)."""


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
        self.units: Definitions = {}
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
        try:
            self.units = read_definitions(child(root, "ssd", "Units"))
        except UnitError as exc:
            self.fail(exc.line, str(exc))
        self.parameters(self.system(system, b, None, top=True))
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

    def step_value(self, text: str, line: int | None, what: str) -> Fraction | None:
        value, problem = _number(text)
        if value is None or value <= 0:
            self.fail(line, f"{what} {shown(text)} is not a positive number of seconds{problem}")
            return None
        return value

    # -- systems -----------------------------------------------------------------------

    def system(self, element: Any, b: DiagramBuilder, inherited: Fraction | None, top: bool = False) -> Element:
        """Say the ``ssd:System`` ``element`` to ``b`` (``top``: the SSD's own system); its
        elements, for the bindings."""
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
                if found.elements:  # a system of nothing but parameters (OMSimulator writes them) runs nothing
                    b.add_subsystem(name, sub, where=self.site(item))
            else:
                found = self.component(item, name, b, step)
            if found is not None:
                me.elements[name] = found
        self.system_bindings(element, me)
        self.connections(element, b, me, top)
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
        me = Element("component", self.connectors(item, system=False), fmu=fmu)
        try:
            values = binding_values(self.package, self.file, child(item, "ssd", "ParameterBindings"), self.read_xml)
        except BindingError as exc:
            self.fail(exc.line, f"component '{name}': {exc}", exc.hint, name=name, file=exc.file)
            return None
        for v in values:
            self.assign(me, v.name, v, name)
        period = self.period(item, name, system_step_, me)
        params: dict[str, Any] = {"path": self.package.relative(fmu), "start_values": me.start_values}
        if IMPLEMENTATIONS[implementation]:
            params["interface"] = IMPLEMENTATIONS[implementation]
        if feedthrough(item):
            params["feedthrough"] = True
        b.add(name, "FMU", period=period, params=params, where=self.site(item))
        ports = [c for c in me.connectors.values() if c.kind in ("input", "output")]
        for port, (units, line) in _port_units(ports).items():
            b.annotate(f"{name}.{port}", units=units, where=Site(self.file, line))
        return me

    def period(self, item: Any, name: str, system_step_: Fraction | None, me: Element) -> Fraction | None:
        """The component's period as the SSD, ``--step`` or its FMU gives it; None (and no
        error) for the FMU's DefaultExperiment step, which the FMU block takes itself."""
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
        md = self.description(me)
        if md is False or _default_step(md):
            return None  # the FMU block steps at its FMU's DefaultExperiment step (or says why it cannot be read)
        self.fail(item.sourceline, f"component '{name}' has no step size: the SSD gives no osp:StepSizeHint, "
                  "oms:FixedStepMaster or osp:FixedStepAlgorithm, and its FMU no DefaultExperiment stepSize",
                  STEP_HINT, name=name)
        return None

    def description(self, me: Element) -> Any:
        """The modelDescription of component ``me``'s FMU, read once; False if it cannot be
        read (the FMU block says why)."""
        if me.md is None:
            try:
                me.md = read_description(me.fmu, self.package.where(me.fmu)).md
            except FMUInfoError:
                me.md = False
        return me.md

    def assign(self, me: Element, name: str, v: Value, component: str) -> None:
        """Set parameter ``name`` of component ``me`` to the value ``v`` gives, converted into
        the parameter's unit (the FMU variable's, else its parameter connector's)."""
        unit, tables = None, (self.units,)
        if v.unit or v.enumeration:
            md = self.description(me)
            variable = next((x for x in md.modelVariables if x.name == name), None) if md else None
            if variable is None:  # an FMU that cannot be read, or no such variable: the FMU block says so
                me.start_values[name] = replace(v, unit=None).value_in(None)
                return
            if v.enumeration:
                me.start_values[name] = self.enumeration_item(v, variable, component)
                return
            connector = me.connectors.get(name)
            unit = variable_unit(variable) or (connector.unit if connector is not None else None)
            tables = (self.units, fmu_definitions(md))
        try:
            me.start_values[name] = v.value_in(unit, *tables)
        except BindingError as exc:
            self.fail(exc.line, f"component '{component}': {exc}", exc.hint, name=component, file=exc.file)

    # -- connections -------------------------------------------------------------------

    def connections(self, element: Any, b: DiagramBuilder, me: Element, top: bool) -> None:
        """Say the system's connections to ``b`` (``blocks.ssp.connections``)."""
        Wiring(self, b, me, top).connect_all(children(child(element, "ssd", "Connections"), "ssd", "Connection"))

    # -- bindings of a system ----------------------------------------------------------

    def system_bindings(self, element: Any, me: Element) -> None:
        """A system's bindings: ``element.parameter`` (``sub.element.parameter``) a component's
        parameter; a system's own input or parameter connector by its name (``sub.k``, ``k``)."""
        try:
            values = binding_values(self.package, self.file, child(element, "ssd", "ParameterBindings"),
                                    self.read_xml)
        except BindingError as exc:
            self.fail(exc.line, str(exc), exc.hint, file=exc.file)
            return
        for v in values:
            target, rest = me, v.name
            while True:
                if rest in target.connectors and target.connectors[rest].kind in ("input", "parameter"):
                    target.values[rest] = v  # a value of a system's own connector (top-level inputs, parameters)
                    break
                head, dot, tail = rest.partition(".")
                found = target.elements.get(head) if dot else None
                if found is None:
                    self.fail(v.line, f"parameter '{v.name}': no element '{head}' to bind it to",
                              "a system's bindings name element.parameter or one of its input or parameter "
                              f"connectors; elements: {known(list(target.elements))}", file=v.file)
                    break
                if found.kind == "component":
                    self.assign(found, tail, v, head)
                    break
                target, rest = found, tail

    def start_of(self, me: Element, name: str) -> float | None:
        """The start value the FMU of component ``me`` declares for its Real variable
        ``name``; None for a system, an FMU that cannot be read, a variable without one."""
        md = self.description(me) if me.kind == "component" else False
        variable = next((x for x in md.modelVariables if x.name == name), None) if md else None
        try:
            return float(variable.start) if variable is not None and variable.start is not None else None
        except (TypeError, ValueError):
            return None

    def enumeration_item(self, v: Value, variable: Any, component: str) -> Any:
        """The number of the item ``v`` names in its FMU variable's enumeration type (the name
        as it is, reported, where the variable's type has no such item)."""
        items = getattr(getattr(variable, "declaredType", None), "items", None) or []
        for item in items:
            if item.name == v.value:
                return int(item.value)
        names = [item.name for item in items]
        self.fail(v.line, f"component '{component}': parameter '{v.name}' = '{v.value}' is no item of the FMU's "
                  f"enumeration type of '{variable.name}'", f"its items: {known(names)}" if names else
                  f"'{variable.name}' is not an Enumeration variable", name=component, file=v.file)
        return v.value

    def parameters(self, me: Element) -> None:
        """Pass the values of system ``me``'s parameter connectors on along its parameter
        connections, then those of its nested systems (a higher level's first: it wins)."""
        for connector, name, parameter, (factor, offset), line in me.links:
            v = me.values.get(connector)
            target = me.elements[name]
            if v is None:
                continue  # an unbound system parameter leaves the element's own value
            try:
                value = v.value_in(me.connectors[connector].unit, self.units)
            except BindingError as exc:
                self.fail(exc.line, str(exc), exc.hint, file=exc.file)
                continue
            if (factor, offset) != (1.0, 0.0):
                if not isinstance(value, float):
                    self.fail(line, f"ssd:Connection from the system's parameter '{connector}': a unit conversion or "
                              "linear transformation maps only Real values")
                    continue
                value = factor * value + offset
            if target.kind == "component":
                target.start_values[parameter] = value
            else:
                target.values[parameter] = Value(parameter, value, v.file, v.line, target.connectors[parameter].unit)
        for element in me.elements.values():
            if element.kind == "system":
                self.parameters(element)


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


def _default_step(md: Any) -> bool:
    """Whether a modelDescription declares a usable DefaultExperiment stepSize."""
    step = getattr(md.defaultExperiment, "stepSize", None) if md.defaultExperiment is not None else None
    try:
        return step is not None and step_of(step) > 0
    except ValueError:
        return False


def _number(text: str) -> tuple[Fraction | None, str]:
    """A time's exact value, or None and why not (`` (...)``, for a message)."""
    try:
        return exact(text), ""
    except ValueError as exc:
        return None, f" ({exc})"
