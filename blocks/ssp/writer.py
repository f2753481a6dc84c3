"""A diagram as an SSP: ``export_ssp`` writes ``SystemStructure.ssd`` and the FMUs under ``resources/``.

Each top-level block becomes an ``ssd:Component`` whose FMU is the one its FMU block
names (copied once per distinct file); its connectors are the FMU's input and output
variables (element by element for a vector port, typed as the FMU declares them), its
start values an inline ``ssd:ParameterBindings``, its period a libcosim
``osp:StepSizeHint``. The connections become ``ssd:Connection``s between those variables.
The end time is the ``ssd:DefaultExperiment`` stopTime, whose libcosim
``osp:FixedStepAlgorithm`` baseStepSize and the system's OMSimulator ``FixedStepMaster``
stepSize are the greatest common divisor of the components' periods (OMSimulator steps
every component of a system at one step). A block that cannot become a component (not
an FMU block, a block inside a subsystem, a delayed connection, an offset, a port type
SSP 1.0 has no connector type for) is one error naming it. The SSD validates against the
SSP schemas (the tests check it).
"""

from __future__ import annotations

import hashlib
import io
import math
import zipfile
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..atomic_file import write_atomically
from ..diagram import Diagram
from ..issues import DiagramError, Issue
from ..timebase import format_duration
from .package import SSD_NAME
from .steps import add_base_step, add_step_hint, add_system_step, number
from .xml import PREFIXES, q

CONNECTOR_TYPES = {"Float64": "Real", "Float32": "Real", "Int32": "Integer", "Int16": "Integer", "Int8": "Integer",
                   "UInt16": "Integer", "UInt8": "Integer", "Boolean": "Boolean"}
"""SSP 1.0 connector types of the FMU port types (``FMU.port_types``; FMI 2's Real is Float64)."""
VALUE_TYPES = {"Real": "Real", "Float64": "Real", "Float32": "Real", "Integer": "Integer", "Int32": "Integer",
               "Int16": "Integer", "Int8": "Integer", "UInt16": "Integer", "UInt8": "Integer", "Boolean": "Boolean",
               "String": "String"}
"""SSV 1.0 value types of the FMU variable types of start values."""


def export_ssp(diagram: Diagram, out: str | Path) -> Path:
    """Write ``diagram`` as the SSP archive ``out`` (a ``.ssp`` file); DiagramError naming
    each block or connection that SSP cannot carry."""
    from lxml import etree

    problems: list[Issue] = []
    components = _components(diagram, problems)
    wires = _connections(diagram, components, problems)
    if problems:
        raise DiagramError(problems)
    root = etree.Element(q("ssd", "SystemStructureDescription"), nsmap=PREFIXES)
    root.set("version", "1.0")
    root.set("name", diagram.name)
    system = etree.SubElement(root, q("ssd", "System"))
    system.set("name", diagram.name)
    if diagram.description:
        system.set("description", " ".join(str(diagram.description).split()))
    holder = etree.SubElement(system, q("ssd", "Elements"))
    files: dict[str, bytes] = {}
    names: dict[str, str] = {}
    for name, spec in components.items():
        files.setdefault(_resource(spec.block.path, names), Path(spec.block.path).read_bytes())
        _component(holder, name, spec, names[str(spec.block.path)])
    if wires:
        connections = etree.SubElement(system, q("ssd", "Connections"))
        for src, dst in wires:
            c = etree.SubElement(connections, q("ssd", "Connection"))
            c.set("startElement", src[0])
            c.set("startConnector", src[1])
            c.set("endElement", dst[0])
            c.set("endConnector", dst[1])
    base = _gcd([_period(spec) for spec in components.values()])
    add_system_step(system, base)
    experiment = etree.SubElement(root, q("ssd", "DefaultExperiment"))
    experiment.set("startTime", "0")
    if diagram.t_end is not None:
        experiment.set("stopTime", number(diagram.t_end))
    add_base_step(experiment, base)
    ssd = etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(SSD_NAME, ssd)
        for member, data in sorted(files.items()):
            zf.writestr(member, data)
    target = Path(out)
    target.parent.mkdir(parents=True, exist_ok=True)
    return write_atomically(target, buffer.getvalue())


def _components(diagram: Diagram, problems: list[Issue]) -> dict[str, Any]:
    from ..fmu import FMU

    found = {}
    for name, spec in diagram.blocks.items():
        if "." in name:
            top = name.split(".")[0]
            if not any(i.message.startswith(f"subsystem '{top}'") for i in problems):
                problems.append(diagram.issue_at(spec, f"subsystem '{top}' cannot become an SSP component: only FMU "
                                      "blocks can, until a subsystem can be exported as an FMU",
                                      f"replace '{top}' by an FMU block of it"))
            continue
        if not isinstance(spec.block, FMU):
            problems.append(diagram.issue_at(spec, f"block '{name}' ({spec.type_name}) cannot become an SSP component: "
                                  "only FMU blocks can", f"replace '{name}' by an FMU of it (type: FMU)"))
            continue
        if spec.offset:
            problems.append(diagram.issue_at(spec, f"block '{name}': an offset ({format_duration(spec.offset)}) has no "
                                  "place in an SSD", "SSP components start at t = 0"))
            continue
        for port, kind in spec.block.port_types.items():
            if kind not in CONNECTOR_TYPES or spec.block.element_variables(port) is None:
                problems.append(diagram.issue_at(spec, f"block '{name}': port '{port}' ({kind}) has no SSP 1.0 connector",
                                      "SSP 1.0 connectors are scalar Real, Integer or Boolean variables"))
        found[name] = spec
    return found


def _connections(diagram: Diagram, components: dict, problems: list[Issue]) -> list[tuple]:
    wires = []
    for c in diagram.connections:
        if c.src_block not in components or c.dst_block not in components:
            continue
        if c.delay:
            problems.append(diagram.issue_at(c, f"connection '{c}': a delay has no place in an SSD",
                                          "SSP connections hand values over without delay"))
            continue
        sources = components[c.src_block].block.element_variables(c.src_port)
        targets = components[c.dst_block].block.element_variables(c.dst_port)
        picked_src = [sources[i] for i in c.src_elements] if c.src_elements is not None else sources
        picked_dst = [targets[i] for i in c.dst_elements] if c.dst_elements is not None else targets
        wires.extend(((c.src_block, a), (c.dst_block, b)) for a, b in zip(picked_src, picked_dst))
    return wires


def _component(holder: Any, name: str, spec: Any, resource: str) -> None:
    from lxml import etree

    block = spec.block
    element = etree.SubElement(holder, q("ssd", "Component"))
    element.set("name", name)
    element.set("type", "application/x-fmu-sharedlibrary")
    element.set("source", resource)
    if block.interface == "model exchange":
        element.set("implementation", "ModelExchange")
    connectors = etree.SubElement(element, q("ssd", "Connectors"))
    for kind, ports in (("input", block.inputs), ("output", block.outputs)):
        for port in ports:
            for variable in block.element_variables(port):
                connector = etree.SubElement(connectors, q("ssd", "Connector"))
                connector.set("name", variable)
                connector.set("kind", kind)
                etree.SubElement(connector, q("ssc", CONNECTOR_TYPES[block.port_types[port]]))
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
    add_step_hint(element, _period(spec))


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def _period(spec: Any) -> Fraction:
    return spec.period if spec.period is not None else spec.block.period


def _gcd(periods: list[Fraction]) -> Fraction:
    lcm = math.lcm(*(p.denominator for p in periods))
    return Fraction(math.gcd(*(int(p * lcm) for p in periods)), lcm)


def _resource(path: Any, names: dict[str, str]) -> str:
    """``resources/<file name>`` for the FMU at ``path``, another name where two files share one."""
    key = str(path)
    if key not in names:
        stem = Path(key).name
        member = f"resources/{stem}"
        if member in names.values():
            member = f"resources/{hashlib.sha256(key.encode()).hexdigest()[:8]}_{stem}"
        names[key] = member
    return names[key]
