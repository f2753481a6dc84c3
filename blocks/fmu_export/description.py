"""modelDescription.xml and sources/buildDescription.xml of an exported diagram FMU.

Co-simulation only, FMI 2.0 or 3.0, every variable a Float64 (FMI 2 Real) scalar:
inputs (continuous, a start value), outputs (``initial="calculated"``; ``discrete`` where
a sampled block holds them between its hits), parameters (``variability="fixed"``,
settable until initialization ends; ``min``/``max`` where the block holds them to a range). Units are declared once in
``UnitDefinitions`` (with their SI base units where pint reads the unit: ``blocks.units``)
and named by every variable that has one. The step rules say what the binary does: the
internal step is the communication grid (``fixedInternalStepSize``, FMI 2: in a vendor
annotation), any communication step is taken (``canHandleVariableCommunicationStepSize``;
between grid points the outputs hold),
FMU states can be got, set and serialized.

A scheduled-execution FMU (FMI 3, ``clocks`` given) declares ``<ScheduledExecution>``, its
input clocks (constant, periodic, with their priorities, the interval and shift exact as
counters of a resolution) after the parameters, its inputs and outputs discrete with the
clock they belong to where they have one (``clocks=``), which their dependencies name too.
"""

from __future__ import annotations

import math
from fractions import Fraction
from xml.etree import ElementTree as ET

from ..units import base_unit
from .variables import VR_TIME, Variable, Variables


def _units(root: ET.Element, variables: list[Variable], extra: tuple[str, ...] = ()) -> None:
    names = sorted({v.unit for v in variables if v.unit} | set(extra))
    if not names:
        return
    block = ET.SubElement(root, "UnitDefinitions")
    for name in names:
        unit = ET.SubElement(block, "Unit", name=name)
        found = base_unit(name)
        if found is not None:
            ET.SubElement(unit, "BaseUnit", **found.attributes())


def model_description(fmi: int, identifier: str, token: str, model: str, description: str, variables: Variables,
                      grid: Fraction, step: Fraction, stop: Fraction | None, log_categories: dict[str, str],
                      generation_tool: str, source_files: list[str], *, clocks=None, base_tick: Fraction | None = None,
                      variable_clocks: dict[int, int] | None = None) -> bytes:
    """modelDescription.xml of an FMI ``fmi`` export; scheduled execution with ``clocks``
    (``partitions.Partitions``), the base tick and each clocked variable's clock."""
    common = {"modelName": model, "description": description, "generationTool": generation_tool,
              "variableNamingConvention": "structured"}
    internal = repr(float(grid))
    if fmi == 2:
        root = ET.Element("fmiModelDescription", fmiVersion="2.0", guid=token, numberOfEventIndicators="0", **common)
        cs = ET.SubElement(root, "CoSimulation", modelIdentifier=identifier,
                           canHandleVariableCommunicationStepSize="true", canGetAndSetFMUstate="true",
                           canSerializeFMUstate="true", canNotUseMemoryManagementFunctions="true")
        files = ET.SubElement(cs, "SourceFiles")
        for name in source_files:
            ET.SubElement(files, "File", name=name)
    elif clocks is not None:
        root = ET.Element("fmiModelDescription", fmiVersion="3.0", instantiationToken=token, **common)
        ET.SubElement(root, "ScheduledExecution", modelIdentifier=identifier, canGetAndSetFMUState="true",
                      canSerializeFMUState="true")
    else:
        root = ET.Element("fmiModelDescription", fmiVersion="3.0", instantiationToken=token, **common)
        ET.SubElement(root, "CoSimulation", modelIdentifier=identifier,
                      canHandleVariableCommunicationStepSize="true", canGetAndSetFMUState="true",
                      canSerializeFMUState="true", hasEventMode="false", providesIntermediateUpdate="false",
                      fixedInternalStepSize=internal)
    everything = [*variables.inputs, *variables.outputs, *variables.parameters]
    _units(root, everything, ("s",) if fmi == 3 else ())  # FMI 3's time is in seconds
    categories = ET.SubElement(root, "LogCategories")
    for name, text in log_categories.items():
        ET.SubElement(categories, "Category", name=name, description=text)
    experiment = {"startTime": "0", "stepSize": repr(float(step))}
    if stop is not None:
        experiment["stopTime"] = repr(float(stop))
    ET.SubElement(root, "DefaultExperiment", **experiment)
    if fmi == 2:  # FMI 2 has no fixedInternalStepSize: FMI 3's attribute as a vendor annotation
        tool = ET.SubElement(ET.SubElement(root, "VendorAnnotations"), "Tool", name=generation_tool.split()[0])
        ET.SubElement(tool, "CoSimulation", fixedInternalStepSize=internal)
    listed = ET.SubElement(root, "ModelVariables")
    _model_variables(listed, fmi, everything, variable_clocks)
    if clocks is not None:
        _clocks(listed, clocks, base_tick)
    _structure(ET.SubElement(root, "ModelStructure"), fmi, variables, variable_clocks)
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8") + b"\n"


def _clocks(parent: ET.Element, clocks, base_tick: Fraction) -> None:
    for c in clocks.clocks:
        interval, shift = c.seconds(base_tick)
        resolution = math.lcm(interval.denominator, shift.denominator)
        attrs = {"name": c.name, "valueReference": str(c.vr), "causality": "input",
                 "description": f"every {float(interval):g} s" + (f" from {float(shift):g} s on" if shift else ""),
                 "intervalVariability": "constant", "priority": str(c.priority),
                 "intervalDecimal": repr(float(interval)), "supportsFraction": "true",
                 "resolution": str(resolution), "intervalCounter": str(int(interval * resolution))}
        if shift:
            attrs.update(shiftDecimal=repr(float(shift)), shiftCounter=str(int(shift * resolution)))
        ET.SubElement(parent, "Clock", **attrs)


def _model_variables(parent: ET.Element, fmi: int, everything: list[Variable],
                     variable_clocks: dict[int, int] | None = None) -> None:
    if fmi == 3:
        ET.SubElement(parent, "Float64", name="time", valueReference=str(VR_TIME), causality="independent",
                      variability="continuous", description="simulation time", unit="s")
    for v in everything:
        attrs = {"name": v.name, "valueReference": str(v.vr), "causality": v.causality, "description": v.description}
        if v.causality == "parameter":
            attrs.update(variability="fixed", initial="exact")
        elif v.causality == "output":
            attrs.update(variability="discrete" if v.discrete else "continuous", initial="calculated")
        else:
            attrs.update(variability="continuous")
        if variable_clocks is not None and v.causality != "parameter":  # scheduled execution: discrete
            attrs["variability"] = "discrete"
            if v.vr in variable_clocks:
                attrs["clocks"] = str(variable_clocks[v.vr])
        typed = {}
        if v.unit:
            typed["unit"] = v.unit
        if v.start is not None:
            typed["start"] = repr(v.start)
        if v.minimum is not None:
            typed["min"] = repr(v.minimum)
        if v.maximum is not None:
            typed["max"] = repr(v.maximum)
        if fmi == 2:
            ET.SubElement(ET.SubElement(parent, "ScalarVariable", **attrs), "Real", **typed)
        else:
            ET.SubElement(parent, "Float64", **attrs, **typed)


def _structure(parent: ET.Element, fmi: int, variables: Variables,
               variable_clocks: dict[int, int] | None = None) -> None:
    """Outputs with the inputs they depend on; initial unknowns (the outputs) with the
    inputs that reach them at t = 0 and every parameter."""
    n_in = len(variables.inputs)
    parameters = variables.parameters
    if fmi == 2:  # 1-based indices among the ScalarVariables: inputs, outputs, parameters
        output_index = {id(o): n_in + k + 1 for k, o in enumerate(variables.outputs)}
        param_index = [n_in + len(variables.outputs) + k + 1 for k in range(len(parameters))]
        block = ET.SubElement(parent, "Outputs")
        for o in variables.outputs:
            ET.SubElement(block, "Unknown", index=str(output_index[id(o)]),
                          dependencies=" ".join(str(j + 1) for j in o.depends))
        block = ET.SubElement(parent, "InitialUnknowns")
        for o in variables.outputs:
            known = [j + 1 for j in o.initial_depends] + param_index
            ET.SubElement(block, "Unknown", index=str(output_index[id(o)]), dependencies=" ".join(map(str, known)))
    else:
        for o in variables.outputs:
            clock = [variable_clocks[o.vr]] if variable_clocks and o.vr in variable_clocks else []
            ET.SubElement(parent, "Output", valueReference=str(o.vr),
                          dependencies=" ".join(str(r) for r in [variables.inputs[j].vr for j in o.depends] + clock))
        for o in variables.outputs:
            if variable_clocks and o.vr in variable_clocks:
                continue  # a clocked output has no value before its clock ticks: no initial unknown
            known = [variables.inputs[j].vr for j in o.initial_depends] + [p.vr for p in parameters]
            ET.SubElement(parent, "InitialUnknown", valueReference=str(o.vr), dependencies=" ".join(map(str, known)))


def build_description(identifier: str, source_files: list[str]) -> bytes:
    """sources/buildDescription.xml (FMI 3): the C99 files to compile, libm to link."""
    root = ET.Element("fmiBuildDescription", fmiVersion="3.0")
    config = ET.SubElement(root, "BuildConfiguration", modelIdentifier=identifier)
    files = ET.SubElement(config, "SourceFileSet", language="C99")
    for name in source_files:
        ET.SubElement(files, "SourceFile", name=name)
    ET.SubElement(config, "Library", name="m", description="the C maths library (libm)")
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8") + b"\n"
