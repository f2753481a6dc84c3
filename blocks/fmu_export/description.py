"""modelDescription.xml and sources/buildDescription.xml of an exported diagram FMU.

Co-simulation only, FMI 2.0 or 3.0, every variable a Float64 (FMI 2 Real) scalar:
inputs (continuous, a start value), outputs (``initial="calculated"``), parameters
(``variability="fixed"``, settable until initialization ends). Units are declared once in
``UnitDefinitions`` (with their SI base units where the unit is made of known symbols)
and named by every variable that has one. The step rules say what the binary does: the
internal step is the communication grid (``fixedInternalStepSize``, FMI 2: in a vendor
annotation), any whole multiple of it is taken (``canHandleVariableCommunicationStepSize``),
FMU states can be got, set and serialized.
"""

from __future__ import annotations

import re
from fractions import Fraction
from xml.etree import ElementTree as ET

from .variables import VR_TIME, Variable, Variables

BASE_UNITS = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")
_SYMBOLS: dict[str, dict[str, int]] = {
    "kg": {"kg": 1}, "g": {"kg": 1}, "m": {"m": 1}, "s": {"s": 1}, "A": {"A": 1}, "K": {"K": 1},
    "mol": {"mol": 1}, "cd": {"cd": 1}, "rad": {"rad": 1}, "N": {"kg": 1, "m": 1, "s": -2},
    "J": {"kg": 1, "m": 2, "s": -2}, "W": {"kg": 1, "m": 2, "s": -3}, "Pa": {"kg": 1, "m": -1, "s": -2},
    "Hz": {"s": -1}, "V": {"kg": 1, "m": 2, "s": -3, "A": -1},
}
_FACTORS = {"g": 1e-3}
_SCALED = {"deg": ("rad", 3.141592653589793 / 180.0), "min": ("s", 60.0), "h": ("s", 3600.0)}
"""Units that are a known symbol times a factor."""
_PREFIXES = {"n": 1e-9, "u": 1e-6, "µ": 1e-6, "m": 1e-3, "c": 1e-2, "k": 1e3, "M": 1e6, "G": 1e9}
_TOKEN = re.compile(r"^([A-Za-zµ]+)(?:\^?(-?\d+))?$")


def _symbol(token: str) -> tuple[dict[str, int], float] | None:
    """A unit symbol's base-unit exponents and factor: a known symbol, a scaled one
    (``deg``), or an SI prefix before a known symbol (``mm``, ``kN``, ``ms``)."""
    if token in _SYMBOLS:
        return _SYMBOLS[token], _FACTORS.get(token, 1.0)
    if token in _SCALED:
        symbol, factor = _SCALED[token]
        return _SYMBOLS[symbol], factor
    if len(token) > 1 and token[0] in _PREFIXES and token[1:] in _SYMBOLS:
        return _SYMBOLS[token[1:]], _PREFIXES[token[0]] * _FACTORS.get(token[1:], 1.0)
    return None


def base_units(unit: str) -> tuple[dict[str, int], float] | None:
    """The SI base-unit exponents and factor of ``unit`` ("N m", "m/s^2", "1/(N m)", "mm",
    "deg/s"), or None when it holds a symbol not known here ("1" is dimensionless: no
    exponents); such a unit is declared without a BaseUnit."""
    numerator, _, denominator = unit.partition("/")
    exponents: dict[str, int] = {}
    factor = 1.0
    for text, sign in ((numerator, 1), (denominator, -1)):
        for token in text.replace("(", " ").replace(")", " ").replace("*", " ").split():
            if token == "1":
                continue
            m = _TOKEN.match(token)
            known = None if m is None else _symbol(m.group(1))
            if known is None:
                return None
            power = sign * int(m.group(2) or 1)
            for base, e in known[0].items():
                exponents[base] = exponents.get(base, 0) + e * power
            factor *= known[1] ** power
    return {k: e for k, e in exponents.items() if e}, factor


def _units(root: ET.Element, variables: list[Variable], extra: tuple[str, ...] = ()) -> None:
    names = sorted({v.unit for v in variables if v.unit} | set(extra))
    if not names:
        return
    block = ET.SubElement(root, "UnitDefinitions")
    for name in names:
        unit = ET.SubElement(block, "Unit", name=name)
        found = base_units(name)
        if found is not None:
            exponents, factor = found
            attrs = {k: str(e) for k, e in exponents.items()}
            if factor != 1.0:
                attrs["factor"] = repr(factor)
            ET.SubElement(unit, "BaseUnit", **attrs)


def model_description(fmi: int, identifier: str, token: str, model: str, description: str, variables: Variables,
                      grid: Fraction, step: Fraction, stop: Fraction | None, log_categories: dict[str, str],
                      generation_tool: str, source_files: list[str]) -> bytes:
    """modelDescription.xml of an FMI ``fmi`` export."""
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
    _model_variables(ET.SubElement(root, "ModelVariables"), fmi, everything)
    _structure(ET.SubElement(root, "ModelStructure"), fmi, variables)
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8") + b"\n"


def _model_variables(parent: ET.Element, fmi: int, everything: list[Variable]) -> None:
    if fmi == 3:
        ET.SubElement(parent, "Float64", name="time", valueReference=str(VR_TIME), causality="independent",
                      variability="continuous", description="simulation time", unit="s")
    for v in everything:
        attrs = {"name": v.name, "valueReference": str(v.vr), "causality": v.causality, "description": v.description}
        if v.causality == "parameter":
            attrs.update(variability="fixed", initial="exact")
        elif v.causality == "output":
            attrs.update(variability="continuous", initial="calculated")
        else:
            attrs.update(variability="continuous")
        typed = {}
        if v.unit:
            typed["unit"] = v.unit
        if v.start is not None:
            typed["start"] = repr(v.start)
        if fmi == 2:
            ET.SubElement(ET.SubElement(parent, "ScalarVariable", **attrs), "Real", **typed)
        else:
            ET.SubElement(parent, "Float64", **attrs, **typed)


def _structure(parent: ET.Element, fmi: int, variables: Variables) -> None:
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
            ET.SubElement(parent, "Output", valueReference=str(o.vr),
                          dependencies=" ".join(str(variables.inputs[j].vr) for j in o.depends))
        for o in variables.outputs:
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
