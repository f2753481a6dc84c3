"""Export the hand plant (``HandPlant``) as a native FMI 2.0 or 3.0 co-simulation FMU.

The FMU's binary is the plant's C core (``hierhand/csrc``, the code ``HandPlant`` runs)
with an FMI wrapper, linked when hierhand was installed (``hierhand/fmu_binaries``): an
importer needs neither Python nor a compiler on Linux x86-64, and exporting needs no
compiler either. The FMU also carries the C sources, listed in its modelDescription
(FMI 2 ``<SourceFiles>``) and in ``sources/buildDescription.xml`` (FMI 3), so a tool can
build it for another platform.

- Inputs ``tau[1]``..``tau[9]``, ``f_ext[1]``..``f_ext[3]`` (start 0), held over a step.
- Outputs: every element of every plant output port (``q[1]``, ..., ``normal[6]``),
  ``initial="calculated"`` and independent of the inputs (no direct feedthrough, and
  at initialisation they depend on the parameters only).
- Parameters (``variability="fixed"``): every number of the hand file, named as the C
  core names them (``object.mass``, ``fingers[2].links[3].com[1]``, 1-based), start values
  from ``hand``; the FMU reads them from ``resources/hand_parameters.txt`` when
  instantiated, so one compiled library serves every exported hand.
- The plant steps at ``INTERNAL_STEP`` inside; a communication step that is not a whole
  multiple of it is refused with an error status and a logged message. The step is declared
  as ``fixedInternalStepSize`` (FMI 3: of ``<CoSimulation>``; FMI 2, which lacks it: in a
  ``<VendorAnnotations>`` tool entry), so the FMU block refuses such a period at load time.

The model identifier is ``HandPlant_<hash>`` over the hand, the FMI version, the binary
and the sources, so FMUs of different hands load side by side in one process.
"""

from __future__ import annotations

import hashlib
import io
import json
import platform
import struct
import uuid
import zipfile
from fractions import Fraction
from pathlib import Path
from typing import Any
from xml.etree import ElementTree as ET

import hierhand
from blocks.atomic_file import write_atomically
from hierhand import _native, native_sources

FMU_DIR = Path("fmu")
"""Where exports go by default: ``fmu/`` under the current folder, like ``runs/`` for results."""

INTERNAL_STEP = Fraction(1, 10000)
DEFAULT_COMMUNICATION_STEP = 1e-3
FMI_VERSIONS = (2, 3)
RESOURCE_FILE: str = _native.FMU_RESOURCE_FILE

# value references, defined in fmu_instance.h
VR_TIME: int = _native.LAYOUT["VR_TIME"]
VR_INPUT: int = _native.LAYOUT["VR_TAU"]  # tau, then f_ext
VR_OUTPUT: int = _native.LAYOUT["VR_OUTPUT"]
VR_PARAM: int = _native.LAYOUT["VR_PARAM"]

PACKAGE_DIR = Path(hierhand.__file__).resolve().parent
SOURCE_DIR = PACKAGE_DIR / "csrc"
BINARY_DIR = PACKAGE_DIR / "fmu_binaries"

LOG_CATEGORIES = dict(zip(_native.FMU_LOG_CATEGORIES, (
    "instantiation, initialization and other events (when logging is on)",
    "warnings",
    "errors: invalid parameters, rejected steps, numerical failure",
)))
"""The categories fmu_instance.h logs under (events, warnings, errors), described."""

PORT_DOCS = {
    "tau": "joint torques [N m]: thumb joints 1-3, fore 1-3, middle 1-3 (proximal to distal)",
    "f_ext": "external load on the object: fx, fy [N], torque [N m]",
    "q": "joint angles [rad]: thumb 1-3, fore 1-3, middle 1-3 (relative angles)",
    "qd": "joint rates [rad/s]: thumb 1-3, fore 1-3, middle 1-3",
    "tip": "per finger (thumb, fore, middle) the tip centre x, y [m] and the link-3 angle [rad]",
    "fn": "per finger the summed normal contact force [N]",
    "ft": "per finger the summed tangential contact force on the object [N] (counter-clockwise tangent)",
    "ratio": "per finger |ft| / fn (0 without contact)",
    "contact": "per finger 1 while its normal force is positive, else 0",
    "obj": "object pose: x, y [m], theta [rad]",
    "obj_vel": "object velocity: vx, vy [m/s], omega [rad/s]",
    "normal": "per finger the unit vector x, y from the tip centre to its contact point (0 without contact)",
}


class FmuExportError(RuntimeError):
    """The FMU cannot be built (for instance the install has no FMU library)."""


def export_plant_fmu(out: Path | None = None, fmi: int = 2, hand: Path | None = None) -> Path:
    """Write the hand plant FMU and return its path.

    ``out``: a ``.fmu`` file, or a folder to put ``HandPlant_fmi<N>.fmu`` in (default
    ``fmu/HandPlant_fmi<N>.fmu`` under the current folder); ``fmi``: 2 or 3; ``hand``: a
    hand file whose values become the parameters' start values (default: the shipped
    hand). Raises ``HandFileError`` for an invalid hand file and ``FmuExportError`` when
    the FMU cannot be built.
    """
    if fmi not in FMI_VERSIONS:
        raise ValueError(f"fmi must be 2 or 3, got {fmi!r}")
    from hierhand.model import load_hand

    loaded = load_hand(hand if hand is not None else {})
    library = fmu_library(fmi).read_bytes()
    sources = {name: (SOURCE_DIR / name).read_bytes() for name in native_sources.fmu_source_files(fmi)}
    identifier = _identifier(fmi, loaded.vector, library, sources)
    token = "{" + str(uuid.UUID(hashlib.sha256(identifier.encode()).hexdigest()[:32])) + "}"
    files = {
        "modelDescription.xml": model_description(fmi, identifier, token, loaded),
        f"binaries/{_platform_folder(fmi)}/{identifier}.so": library,
        f"resources/{RESOURCE_FILE}": resource_file(token, loaded).encode(),
        **{f"sources/{name}": data for name, data in sources.items()},
    }
    if fmi == 3:
        files["sources/buildDescription.xml"] = build_description(identifier)
    target = _output_path(out, fmi)
    target.parent.mkdir(parents=True, exist_ok=True)
    return write_atomically(target, _zip(files))


def fmu_library(fmi: int) -> Path:
    """The FMI ``fmi`` plant library built at install."""
    path = BINARY_DIR / f"fmi{fmi}.so"
    if not path.is_file():
        raise FmuExportError(f"{path} is missing: hierhand was installed without its FMU libraries "
                             "(hint: reinstall with 'pip install .' or 'pip install -e .' and a C compiler)")
    return path


# -- naming ---------------------------------------------------------------------------------


def default_output_path(fmi: int) -> Path:
    return FMU_DIR / f"HandPlant_fmi{fmi}.fmu"


def _output_path(out: Path | None, fmi: int) -> Path:
    if out is None:
        return default_output_path(fmi)
    out = Path(out)
    if out.suffix.lower() == ".fmu":
        return out
    return out / default_output_path(fmi).name


def _hierhand_version() -> str:
    from importlib import metadata

    try:
        return metadata.version("hierhand")
    except metadata.PackageNotFoundError:
        return "unknown"


def _identifier(fmi: int, vector, library: bytes, sources: dict[str, bytes]) -> str:
    """``HandPlant_<hash>``: differs whenever the FMU's parameters, code or FMI version do."""
    h = hashlib.sha256()
    h.update(json.dumps({"fmi": fmi, "hand": [_hex(x) for x in vector], "dt": str(INTERNAL_STEP),
                         "hierhand": _hierhand_version()}, sort_keys=True).encode())
    h.update(hashlib.sha256(library).digest())
    for name in sorted(sources):
        h.update(name.encode() + b"\0" + hashlib.sha256(sources[name]).digest())
    return "HandPlant_" + h.hexdigest()[:12]


def _platform_folder(fmi: int) -> str:
    machine = platform.machine().lower()
    if machine in ("x86_64", "amd64"):
        return "linux64" if fmi == 2 else "x86_64-linux"
    if machine in ("aarch64", "arm64"):
        return "aarch64-linux"
    raise FmuExportError(f"no FMI platform name for a Linux {machine} binary")


# -- files ----------------------------------------------------------------------------------


def _hex(x: float) -> str:
    """The 16 hex digits of a double's IEEE 754 bits: exact, and read the same in every locale."""
    return struct.pack(">d", float(x)).hex()


def resource_file(token: str, hand) -> str:
    """``resources/hand_parameters.txt``: the token, the internal step, the finger names
    and every parameter's default, in the C core's order."""
    from hierhand.model.hand_vector import parameter_names

    lines = [
        "# hierhand HandPlant FMU: default parameters, read when the FMU is instantiated.",
        "# Each value is the 16 hex digits of an IEEE 754 double (exact, locale-free); the",
        "# comment after it is the decimal value. The parameter order is fixed by the binary.",
        f"token {token}",
        f"dt {_hex(float(INTERNAL_STEP))}  # {float(INTERNAL_STEP)!r} s",
        "finger_names " + " ".join(name.replace(" ", "_") for name in hand.names),
    ]
    lines += [f"{name} {_hex(x)}  # {float(x)!r}" for name, x in zip(parameter_names(), hand.vector)]
    return "\n".join(lines) + "\n"


def _variables(hand) -> list[dict[str, Any]]:
    """Every FMU variable in modelDescription order: inputs, outputs, parameters."""
    from hierhand.model.hand_vector import hand_file_path, parameter_docs, parameter_names
    from hierhand.model.layout import OUTPUT_PORTS

    variables = []
    vr = VR_INPUT
    for port, width in (("tau", 9), ("f_ext", 3)):
        for i in range(width):
            variables.append({"name": f"{port}[{i + 1}]", "vr": vr, "causality": "input",
                              "description": PORT_DOCS[port], "start": 0.0})
            vr += 1
    vr = VR_OUTPUT
    for port, width in OUTPUT_PORTS:
        for i in range(width):
            variables.append({"name": f"{port}[{i + 1}]", "vr": vr, "causality": "output",
                              "description": PORT_DOCS[port]})
            vr += 1
    for k, (name, doc, value) in enumerate(zip(parameter_names(), parameter_docs(), hand.vector)):
        field = hand_file_path(name)
        if name.startswith("fingers["):
            doc = f"{hand.names[int(name[8]) - 1]} {doc}"
        variables.append({"name": name, "vr": VR_PARAM + k, "causality": "parameter",
                          "description": f"hand file {field}: {doc}", "start": float(value)})
    return variables


def model_description(fmi: int, identifier: str, token: str, hand) -> bytes:
    """modelDescription.xml of an FMI ``fmi`` export."""
    description = ("hierhand HandPlant: three-fingered planar hand grasping a square object, penalty contact; "
                   f"internal step {float(INTERNAL_STEP) * 1e3:g} ms, communication steps must be multiples of it")
    common = {"modelName": "HandPlant", "description": description,
              "generationTool": f"hierhand {_hierhand_version()}", "variableNamingConvention": "structured"}
    if fmi == 2:
        root = ET.Element("fmiModelDescription", fmiVersion="2.0", guid=token, numberOfEventIndicators="0",
                          **common)
        cs = ET.SubElement(root, "CoSimulation", modelIdentifier=identifier,
                           canHandleVariableCommunicationStepSize="true", canGetAndSetFMUstate="true",
                           canSerializeFMUstate="true", canNotUseMemoryManagementFunctions="true")
        files = ET.SubElement(cs, "SourceFiles")
        for name in native_sources.fmu_compiled_files(fmi):
            ET.SubElement(files, "File", name=name)
    else:
        root = ET.Element("fmiModelDescription", fmiVersion="3.0", instantiationToken=token, **common)
        ET.SubElement(root, "CoSimulation", modelIdentifier=identifier,
                      canHandleVariableCommunicationStepSize="true", canGetAndSetFMUState="true",
                      canSerializeFMUState="true", hasEventMode="false", providesIntermediateUpdate="false",
                      fixedInternalStepSize=repr(float(INTERNAL_STEP)))
    categories = ET.SubElement(root, "LogCategories")
    for name, text in LOG_CATEGORIES.items():
        ET.SubElement(categories, "Category", name=name, description=text)
    ET.SubElement(root, "DefaultExperiment", startTime="0", stopTime="1", stepSize=repr(DEFAULT_COMMUNICATION_STEP))
    if fmi == 2:  # FMI 2 has no fixedInternalStepSize: FMI 3's attribute as a vendor annotation
        tool = ET.SubElement(ET.SubElement(root, "VendorAnnotations"), "Tool", name="hierhand")
        ET.SubElement(tool, "CoSimulation", fixedInternalStepSize=repr(float(INTERNAL_STEP)))
    variables = ET.SubElement(root, "ModelVariables")
    if fmi == 3:
        ET.SubElement(variables, "Float64", name="time", valueReference=str(VR_TIME), causality="independent",
                      variability="continuous", description="simulation time [s]")
    entries = _variables(hand)
    for v in entries:
        attrs = {"name": v["name"], "valueReference": str(v["vr"]), "causality": v["causality"],
                 "description": v["description"]}
        if v["causality"] == "parameter":
            attrs.update(variability="fixed", initial="exact")
        elif v["causality"] == "output":
            attrs.update(variability="continuous", initial="calculated")
        else:
            attrs.update(variability="continuous")
        if fmi == 2:
            scalar = ET.SubElement(variables, "ScalarVariable", **attrs)
            real = ET.SubElement(scalar, "Real")
            if "start" in v:
                real.set("start", repr(v["start"]))
        else:
            if "start" in v:
                attrs["start"] = repr(v["start"])
            ET.SubElement(variables, "Float64", **attrs)
    structure = ET.SubElement(root, "ModelStructure")
    outputs = [(k + 1, v) for k, v in enumerate(entries) if v["causality"] == "output"]  # FMI 2: 1-based index
    # initial outputs depend on the parameters only, never on the inputs: importers need
    # not compute the inputs before initialising the FMU
    parameters = [(k + 1, v) for k, v in enumerate(entries) if v["causality"] == "parameter"]
    if fmi == 2:
        block = ET.SubElement(structure, "Outputs")
        for index, _ in outputs:
            ET.SubElement(block, "Unknown", index=str(index), dependencies="")
        block = ET.SubElement(structure, "InitialUnknowns")
        known = " ".join(str(index) for index, _ in parameters)
        for index, _ in outputs:
            ET.SubElement(block, "Unknown", index=str(index), dependencies=known)
    else:
        for _, v in outputs:
            ET.SubElement(structure, "Output", valueReference=str(v["vr"]), dependencies="")
        known = " ".join(str(v["vr"]) for _, v in parameters)
        for _, v in outputs:
            ET.SubElement(structure, "InitialUnknown", valueReference=str(v["vr"]), dependencies=known)
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8") + b"\n"


def build_description(identifier: str) -> bytes:
    """sources/buildDescription.xml (FMI 3): the C99 files to compile, libm to link."""
    root = ET.Element("fmiBuildDescription", fmiVersion="3.0")
    config = ET.SubElement(root, "BuildConfiguration", modelIdentifier=identifier)
    files = ET.SubElement(config, "SourceFileSet", language="C99")
    for name in native_sources.fmu_compiled_files(3):
        ET.SubElement(files, "SourceFile", name=name)
    ET.SubElement(config, "Library", name="m", description="the C maths library (libm)")
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8") + b"\n"


def _zip(files: dict[str, bytes]) -> bytes:
    """The FMU archive: sorted entries with fixed timestamps, so equal exports are equal bytes."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for name in sorted(files):
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            archive.writestr(info, files[name])
    return buffer.getvalue()
