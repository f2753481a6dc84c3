"""A diagram as an SSP: ``export_ssp`` writes ``SystemStructure.ssd`` and the FMUs under ``resources/``.

Each top-level block or subsystem becomes an ``ssd:Component``: an FMU block's FMU is
copied once per distinct file; any other block, and a subsystem, leaves as an FMU of its
own (``components``, exported by ``blocks.fmu_export``), stepped at the largest multiple
of its internal step that its partners' steps allow. Its connectors are the FMU's input
and output variables (element by element for a vector port, typed and with units as the
FMU declares them; ``ssd:Units`` from the FMUs' definitions), its start values an inline
``ssd:ParameterBindings``. The top level's connections become ``ssd:Connection``s between
those variables. The end time is the ``ssd:DefaultExperiment`` stopTime, whose libcosim
``osp:FixedStepAlgorithm`` baseStepSize and the system's OMSimulator ``FixedStepMaster``
stepSize are the greatest common divisor of the components' steps (every exported FMU
takes any step, holding its outputs between its hits). Where each component's own step
and feedthrough go is ``annotations`` (``ANNOTATIONS``): by default on the system, as
``blocks:Stepping`` entries (OMSimulator refuses annotations inside a component);
``components``: a libcosim ``osp:StepSizeHint`` and a ``blocks:Stepping`` in each component;
``none``: no tool annotations at all. What cannot become a component (a block or
subsystem the FMU exporter refuses, a block whose inherited hits are uneven, a delayed
connection, an offset, a port type SSP 1.0 has no connector type for) is one error
naming it. The SSD validates against the SSP schemas (the tests check it).
"""

from __future__ import annotations

import hashlib
import io
import math
import tempfile
import zipfile
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from blocks.results.atomic_file import write_atomically
from blocks.builder.diagram import Diagram
from ..issues import DiagramError, Issue
from ..timebase import format_duration
from .names import SSD_NAME
from .steps import (ANNOTATIONS, add_base_step, add_feedthrough, add_step_hint, add_system_step, add_system_stepping,
                    number)
from .units import add_units, unit_definitions
from .xml import PREFIXES, q
from blocks.builder.api_args import diagram_argument

CONNECTOR_TYPES = {"Float64": "Real", "Float32": "Real", "Int32": "Integer", "Int16": "Integer", "Int8": "Integer",
                   "UInt16": "Integer", "UInt8": "Integer", "Boolean": "Boolean"}
"""SSP 1.0 connector types of the FMU port types (``FMU.port_types``; FMI 2's Real is Float64)."""
VALUE_TYPES = {"Real": "Real", "Float64": "Real", "Float32": "Real", "Integer": "Integer", "Int32": "Integer",
               "Int16": "Integer", "Int8": "Integer", "UInt16": "Integer", "UInt8": "Integer", "Boolean": "Boolean",
               "String": "String"}
"""SSV 1.0 value types of the FMU variable types of start values."""


def export_ssp(diagram: Diagram, out: str | Path, annotations: str = "system") -> Path:
    """Write ``diagram`` as the SSP archive ``out`` (a ``.ssp`` file), its tool-specific
    annotations placed as ``annotations`` says (a key of ``ANNOTATIONS``); DiagramError
    naming each block or connection that SSP cannot carry."""
    diagram_argument(diagram)
    if annotations not in ANNOTATIONS:
        raise ValueError(f"annotations must be one of {', '.join(ANNOTATIONS)}, got {annotations!r}")
    with tempfile.TemporaryDirectory(prefix="blocks-ssp-") as scratch:
        problems: list[Issue] = []
        components = _components(diagram, Path(scratch), problems)
        wires = _connections(diagram, components, problems)
        if problems:
            raise DiagramError(problems)
        files: dict[str, bytes] = {}
        ssd = _description(diagram, components, wires, files, annotations)
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(SSD_NAME, ssd)
        for member, data in sorted(files.items()):
            zf.writestr(member, data)
    target = Path(out)
    target.parent.mkdir(parents=True, exist_ok=True)
    return write_atomically(target, buffer.getvalue())


def _description(diagram: Diagram, components: dict[str, "Component"], wires: list[tuple],
                 files: dict[str, bytes], annotations: str) -> bytes:
    """The SSD's text; ``files`` gets the FMUs it names, by member name."""
    from lxml import etree

    root = etree.Element(q("ssd", "SystemStructureDescription"), nsmap=PREFIXES)
    root.set("version", "1.0")
    root.set("name", diagram.name)
    system = etree.SubElement(root, q("ssd", "System"))
    system.set("name", diagram.name)
    if diagram.description:
        system.set("description", " ".join(str(diagram.description).split()))
    holder = etree.SubElement(system, q("ssd", "Elements"))
    names: dict[str, str] = {}
    units: dict[str, dict[str, float]] = {}
    for component in components.values():
        path = str(component.block.path)
        files.setdefault(_resource(path, names, component.name if component.exported else None),
                         Path(path).read_bytes())
        _component(holder, component, names[path], units, annotations == "components")
    if wires:
        connections = etree.SubElement(system, q("ssd", "Connections"))
        for src, dst in wires:
            c = etree.SubElement(connections, q("ssd", "Connection"))
            c.set("startElement", src[0])
            c.set("startConnector", src[1])
            c.set("endElement", dst[0])
            c.set("endConnector", dst[1])
    base = _gcd([c.period for c in components.values()])
    if annotations != "none":
        add_system_step(system, base)  # first: OMSimulator reads a system's first annotation only
    if annotations == "system":
        for component in components.values():
            add_system_stepping(system, component.name, component.period, component.feedthrough)
    if units:
        add_units(root, units)
    experiment = etree.SubElement(root, q("ssd", "DefaultExperiment"))
    experiment.set("startTime", "0")
    if diagram.t_end is not None:
        experiment.set("stopTime", number(diagram.t_end))
    if annotations != "none":
        add_base_step(experiment, base)
    return etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)


@dataclass
class Component:
    """An SSD component: its FMU (the FMU block of the diagram's, or of the FMU exported for
    a block or subsystem), where it is written, its communication step and whether the
    importer is to read its outputs with feedthrough, as the diagram's evaluation order does."""

    name: str
    block: Any
    at: Any
    period: Fraction | None = None
    exported: bool = False
    feedthrough: bool = False


def _components(diagram: Diagram, scratch: Path, problems: list[Issue]) -> dict[str, Component]:
    """Every top-level block and subsystem as a component, in the diagram's order."""
    from ..fmu import FMU

    found: dict[str, Component] = {}
    for name in dict.fromkeys(n.split(".")[0] for n in diagram.blocks):
        spec = diagram.blocks.get(name)
        if spec is not None and isinstance(spec.block, FMU):
            if spec.offset:
                problems.append(diagram.issue_at(spec, f"block '{name}': an offset ({format_duration(spec.offset)}) "
                                                 "has no place in an SSD", "SSP components start at t = 0"))
                continue
            found[name] = Component(name, spec.block, spec, _period(spec), feedthrough=bool(spec.block.feedthrough))
            continue
        component = _exported(diagram, name, scratch, problems)
        if component is not None:
            found[name] = component
    for component in found.values():
        for port, kind in component.block.port_types.items():
            if kind not in CONNECTOR_TYPES or component.block.element_variables(port) is None:
                problems.append(_issue(diagram, component.at, f"block '{component.name}': port '{port}' ({kind}) "
                                       "has no SSP 1.0 connector",
                                       "SSP 1.0 connectors are scalar Real, Integer or Boolean variables"))
    _communication_steps(found, _wires_between(diagram, found))
    return found


def _exported(diagram: Diagram, name: str, scratch: Path, problems: list[Issue]) -> Component | None:
    """Block or subsystem ``name`` exported as an FMU (``blocks.fmu_export``) into ``scratch``."""
    from ..fmu import FMU
    from ..fmu_export import FmuExportError, export_fmu
    from .components import component_diagram

    at = diagram.blocks.get(name) or diagram.subsystems[name]
    what = f"block '{name}' ({at.type_name})" if name in diagram.blocks else f"subsystem '{name}'"
    if name in diagram.blocks and at.offset:
        problems.append(diagram.issue_at(at, f"block '{name}': an offset ({format_duration(at.offset)}) has no "
                                         "place in an SSD", "SSP components start at t = 0"))
        return None
    period = None
    if name in diagram.blocks and at.period is None:
        period = _inherited_period(diagram, name)
        if period is None:
            problems.append(diagram.issue_at(at, f"block '{name}' ({at.type_name}) cannot become an SSP component: "
                                             "it fires when the blocks feeding it do, not at one period",
                                             f"give '{name}' a period"))
            return None
    try:
        path = export_fmu(component_diagram(diagram, name, period), scratch / f"{name}.fmu")
    except DiagramError as exc:
        problems.extend(Issue(i.file, i.line, f"{what} cannot become an SSP component: {i.message}", i.hint)
                        for i in exc.issues)
        return None
    except FmuExportError as exc:
        problems.append(_issue(diagram, at, f"{what} cannot become an SSP component: {exc}",
                               "its FMU is exported as 'fmu export' does"))
        return None
    block = FMU(path=str(path), feedthrough=True)
    return Component(name, block, at, exported=True, feedthrough=bool(block.feedthrough))


def _inherited_period(diagram: Diagram, name: str) -> Fraction | None:
    """The period at which block ``name``, which inherits its rate, fires in ``diagram``
    (its hits evenly spaced from t = 0; one that fires only at t = 0 holds its output, any
    period does: the hyperperiod); None when its hits are not evenly spaced."""
    from blocks.engine.schedule import build_schedule

    schedule = build_schedule(diagram, None)
    hits = np.flatnonzero(schedule.masks[name][:schedule.hyperperiod])
    if len(hits) <= 1:
        return schedule.hyperperiod * schedule.base_tick if len(hits) == 0 or hits[0] == 0 else None
    steps = set(np.diff(np.append(hits, hits[0] + schedule.hyperperiod)).tolist())
    if hits[0] != 0 or len(steps) != 1:
        return None
    return steps.pop() * schedule.base_tick


def _issue(diagram: Diagram, at: Any, message: str, hint: str) -> Issue:
    if hasattr(at, "including_file"):  # a subsystem: where its entry is written
        return Issue(at.including_file or diagram.file, at.line, message, hint)
    return diagram.issue_at(at, message, hint)


def _wires_between(diagram: Diagram, components: dict[str, Component]) -> list:
    """The top level's wires (a subsystem's by its ports) between components."""
    wires = diagram.root.wires if diagram.root is not None else diagram.connections
    return [w for w in wires if w.src_block in components and w.dst_block in components]


def _communication_steps(components: dict[str, Component], wires: list) -> None:
    """An exported component's step: the largest multiple of its FMU's internal step that
    divides the internal steps of every component it exchanges values with (so that it
    sees each of their outputs and they see each of its own as the diagram does), else
    its internal step."""
    partners: dict[str, set[str]] = {name: set() for name in components}
    for w in wires:
        if w.src_block != w.dst_block:
            partners[w.src_block].add(w.dst_block)
            partners[w.dst_block].add(w.src_block)
    grids = {name: c.block.default_step if c.exported else c.period for name, c in components.items()}
    for name, c in components.items():
        if not c.exported:
            continue
        own = grids[name]
        others = [grids[p] for p in partners[name] if grids[p] is not None]
        common = _gcd(others) if others else own
        c.period = common if (common / own).denominator == 1 else own


def _connections(diagram: Diagram, components: dict[str, Component], problems: list[Issue]) -> list[tuple]:
    wires = []
    for c in _wires_between(diagram, components):
        if c.delay:
            problems.append(diagram.issue_at(c, f"connection '{c}': a delay has no place in an SSD",
                                          "SSP connections hand values over without delay"))
            continue
        sources = components[c.src_block].block.element_variables(c.src_port)
        targets = components[c.dst_block].block.element_variables(c.dst_port)
        if sources is None or targets is None:
            continue  # the port's problem is reported
        picked_src = [sources[i] for i in c.src_elements] if c.src_elements is not None else sources
        picked_dst = [targets[i] for i in c.dst_elements] if c.dst_elements is not None else targets
        wires.extend(((c.src_block, a), (c.dst_block, b)) for a, b in zip(picked_src, picked_dst))
    return wires


def _component(holder: Any, component: Component, resource: str, units: dict[str, dict[str, float]],
               annotated: bool) -> None:
    """The component's ``ssd:Component`` (``annotated``: with its step and feedthrough
    annotations); ``units`` gets the definitions of its connectors' units."""
    from lxml import etree

    block, name = component.block, component.name
    element = etree.SubElement(holder, q("ssd", "Component"))
    element.set("name", name)
    element.set("type", "application/x-fmu-sharedlibrary")
    element.set("source", resource)
    if block.interface == "model exchange":
        element.set("implementation", "ModelExchange")
    defined = unit_definitions(block.path)
    connectors = etree.SubElement(element, q("ssd", "Connectors"))
    for kind, ports in (("input", block.inputs), ("output", block.outputs)):
        for port in ports:
            port_units = block.port_units(port)
            for i, variable in enumerate(block.element_variables(port)):
                connector = etree.SubElement(connectors, q("ssd", "Connector"))
                connector.set("name", variable)
                connector.set("kind", kind)
                typed = etree.SubElement(connector, q("ssc", CONNECTOR_TYPES[block.port_types[port]]))
                unit = port_units if isinstance(port_units, str) or port_units is None else port_units[i]
                if unit and typed.tag == q("ssc", "Real") and unit in defined:
                    typed.set("unit", unit)
                    units.setdefault(unit, defined[unit])
    values = block.assigned_values()
    if values:
        bindings = etree.SubElement(element, q("ssd", "ParameterBindings"))
        binding = etree.SubElement(bindings, q("ssd", "ParameterBinding"))
        inline = etree.SubElement(binding, q("ssd", "ParameterValues"))
        parameter_set = etree.SubElement(inline, q("ssv", "ParameterSet"))
        parameter_set.set("version", "1.0")
        parameter_set.set("name", f"{name}-start-values")
        parameters = etree.SubElement(parameter_set, q("ssv", "Parameters"))
        for variable, kind, given in values:
            parameter = etree.SubElement(parameters, q("ssv", "Parameter"))
            parameter.set("name", variable)
            typed = etree.SubElement(parameter, q("ssv", VALUE_TYPES.get(kind, "String")))
            typed.set("value", _text(given[0]))
    if annotated:
        add_step_hint(element, component.period)
        if component.feedthrough:
            add_feedthrough(element)


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def _period(spec: Any) -> Fraction:
    """An FMU block's communication step: its period, else its FMU's default step."""
    return spec.period if spec.period is not None else spec.block.period


def _gcd(periods: list[Fraction]) -> Fraction:
    lcm = math.lcm(*(p.denominator for p in periods))
    return Fraction(math.gcd(*(int(p * lcm) for p in periods)), lcm)


def _resource(path: Any, names: dict[str, str], component: str | None = None) -> str:
    """``resources/<file name>`` for the FMU at ``path`` (``<component>.fmu`` for one
    exported for a component), another name where two files share one."""
    key = str(path)
    if key not in names:
        stem = f"{component}.fmu" if component else Path(key).name
        member = f"resources/{stem}"
        if member in names.values():
            member = f"resources/{hashlib.sha256(key.encode()).hexdigest()[:8]}_{stem}"
        names[key] = member
    return names[key]
