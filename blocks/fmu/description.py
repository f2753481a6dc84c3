"""What an FMU declares, read safely and without running any of its code.

``read_description`` reads only the archive's member list and its ``modelDescription.xml``
(into memory, through ``archive.read_member``, with the archive limits): nothing is
extracted to disk and no binary is loaded. The FMU block reads its FMU this way when a
diagram is loaded (``hierhand validate`` and ``graph`` never run an FMU's code) and
extracts and loads the binary only when a run starts; ``hierhand fmu info`` prints
``describe_fmu``.
"""

from __future__ import annotations

import io
import zipfile
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any
from xml.etree import ElementTree

from .archive import ArchiveError, read_member

MODEL_DESCRIPTION = "modelDescription.xml"


class FMUInfoError(ValueError):
    """An FMU that cannot be read; the message names it."""


@dataclass
class FMUDescription:
    """An FMU's modelDescription (fmpy's ``ModelDescription``), its XML text and the
    names of the files in its archive (``/``-separated)."""

    md: Any
    xml: bytes
    files: list[str]

    def platforms(self) -> list[str]:
        """The platform folders under ``binaries/`` that hold files."""
        return sorted({f.split("/")[1] for f in self.files if f.startswith("binaries/") and f.count("/") >= 2})

    def fixed_step(self) -> Fraction | None:
        """The FMU's fixed internal step, if it declares one: FMI 3 ``fixedInternalStepSize``
        of ``<CoSimulation>``; FMI 2 has no such attribute, so there the same attribute is
        read from a ``<CoSimulation>`` element in any tool's ``<VendorAnnotations>``."""
        cs = self.md.coSimulation
        value = getattr(cs, "fixedInternalStepSize", None) if cs is not None else None
        if value is None and self.md.fmiVersion == "2.0":
            try:
                root = ElementTree.fromstring(self.xml)
            except ElementTree.ParseError:
                return None
            for element in root.iterfind("VendorAnnotations/Tool/CoSimulation"):
                value = element.get("fixedInternalStepSize") or value
        try:
            step = Fraction(str(value).strip()) if value is not None else None
        except (ValueError, ZeroDivisionError):
            return None
        return step if step is not None and step > 0 else None


def variable_unit(v: Any) -> str | None:
    """The unit of a variable as its modelDescription declares it: the ``unit`` attribute of
    a Real (FMI 2) or Float32/Float64 (FMI 3) variable, else that of its declared type
    (FMI 2 ``<SimpleType><Real unit=...>``, FMI 3 ``<Float64Type unit=...>``); None when
    neither gives one (and for integer, Boolean and other variables, which have no unit)."""
    unit = getattr(v, "unit", None)
    if not unit and getattr(v, "declaredType", None) is not None:
        unit = getattr(v.declaredType, "unit", None)
    return str(unit) if unit else None


def read_description(path: str | Path, shown: str, validate: bool = True) -> FMUDescription:
    """The modelDescription of the FMU archive ``path`` (``shown`` names it in messages),
    checked against the FMI schema if ``validate``; FMUInfoError if it cannot be read."""
    from fmpy.model_description import read_model_description

    try:
        xml, files = read_member(path, MODEL_DESCRIPTION)
    except ArchiveError as exc:
        raise FMUInfoError(f"unsafe FMU archive, not extracted: {exc}") from None
    except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, NotImplementedError) as exc:
        raise FMUInfoError(f"{shown} is not an FMU: not a readable zip archive ({exc})") from None
    except OSError as exc:
        raise FMUInfoError(f"{shown} cannot be read: {exc.strerror or exc}") from None
    if xml is None:
        raise FMUInfoError(f"{shown} is not an FMU: the archive has no {MODEL_DESCRIPTION}")
    alone = io.BytesIO()
    with zipfile.ZipFile(alone, "w") as zf:  # fmpy reads the description from a zip file
        zf.writestr(MODEL_DESCRIPTION, xml)
    alone.seek(0)
    try:
        md = read_model_description(alone, validate=validate)
    except Exception as exc:
        problems = getattr(exc, "problems", None)
        text = "; ".join(str(p) for p in problems[:3]) + ("; ..." if len(problems) > 3 else "") \
            if problems else (str(exc).strip().splitlines() or [type(exc).__name__])[0]
        raise FMUInfoError(f"{shown} has a broken {MODEL_DESCRIPTION}: {text}") from None
    return FMUDescription(md, xml, files)


def describe_fmu(path: str | Path) -> str:
    """Text listing an FMU's FMI version, interfaces, default experiment and variables."""
    path = Path(path)
    if not path.is_file():
        raise FMUInfoError(f"{path}: FMU file not found")
    description = read_description(path, f"FMU '{path}'", validate=False)
    md = description.md
    lines = [f"{path}", f"  model: {md.modelName}  (FMI {md.fmiVersion}, generated by "
                        f"{md.generationTool or 'unknown tool'})"]
    if md.description:
        lines.append(f"  description: {md.description}")
    interfaces = [(name, getattr(md, attr)) for name, attr in
                  (("co-simulation", "coSimulation"), ("model exchange", "modelExchange"),
                   ("scheduled execution", "scheduledExecution")) if getattr(md, attr, None) is not None]
    lines.append("  interfaces: " + (", ".join(f"{n} (model identifier {i.modelIdentifier})"
                                               for n, i in interfaces) or "none"))
    lines.append(f"  platforms: {', '.join(description.platforms()) or 'none (no binaries)'}")
    step = description.fixed_step()
    if step is not None:
        lines.append(f"  fixed internal step: {float(step):g} s (informative)")
    cs = md.coSimulation
    if cs is not None and not cs.canHandleVariableCommunicationStepSize:
        lines.append("  communication step: fixed (canHandleVariableCommunicationStepSize is false)")
    if md.modelExchange is not None:
        completed = "needs" if md.modelExchange.needsCompletedIntegratorStep else "does not need"
        lines.append(f"  model exchange: {md.numberOfContinuousStates} continuous states, "
                     f"{md.numberOfEventIndicators} event indicators; {completed} completedIntegratorStep")
    de = md.defaultExperiment
    if de is not None:
        parts = [f"{k} {getattr(de, a)}" for k, a in (("start", "startTime"), ("stop", "stopTime"),
                                                      ("step", "stepSize"), ("tolerance", "tolerance"))
                 if getattr(de, a, None) is not None]
        lines.append(f"  default experiment: {', '.join(parts) or '-'}")
    else:
        lines.append("  default experiment: none")
    lines.append(f"  variables ({len(md.modelVariables)}):")
    width = max((len(v.name) for v in md.modelVariables), default=4)
    lines.append(f"    {'name':<{width}}  {'causality':<15} {'variability':<12} {'type':<8} start")
    for v in md.modelVariables:
        start = "" if v.start is None else str(v.start)
        unit = f" {variable_unit(v)}" if variable_unit(v) else ""
        lines.append(f"    {v.name:<{width}}  {v.causality or '':<15} {v.variability or '':<12} "
                     f"{v.type:<8} {start}{unit}")
    return "\n".join(lines)
