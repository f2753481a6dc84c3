"""What an FMU declares, read safely and without running any of its code.

``read_description`` reads only the archive's member list and its ``modelDescription.xml``
(into memory, through ``archive.read_member``, with the archive limits): nothing is
extracted to disk and no binary is loaded. The FMU block reads its FMU this way when a
diagram is loaded (``hierhand validate`` and ``graph`` never run an FMU's code) and
extracts and loads the binary only when a run starts; ``hierhand fmu info`` prints
``describe_fmu``. ``open_fmu_file`` opens an FMU file and says what is wrong with a path
that is not one (missing, a folder, a FIFO or device, unreadable); ``step_of`` reads a step
attribute within the limits of a duration.
"""

from __future__ import annotations

import errno
import io
import math
import threading
import zipfile
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any
from xml.etree import ElementTree

from ..safepath import unusable_path
from ..timebase import DurationError, parse_duration
from .archive import ArchiveError, NotARegularFile, open_regular, read_member

MODEL_DESCRIPTION = "modelDescription.xml"
SHOWN_TEXT = 40
"""How many characters of an attribute's text messages quote (a 5000-digit step is shown cut)."""


class FMUInfoError(ValueError):
    """An FMU that cannot be read; the message names it."""


class FMUNotFound(FMUInfoError):
    """No file at an FMU's path."""


def open_fmu_file(path: str | Path, shown: str):
    """The FMU file ``path`` opened for binary reading (``shown`` names it in messages).
    FMUNotFound if nothing is there; FMUInfoError if it is a folder, a FIFO, a device or a
    socket (none of them is opened: a FIFO would wait for a writer, ``/dev/zero`` never
    ends) or cannot be read (permissions), each saying so."""
    try:
        return open_regular(path)
    except FileNotFoundError:
        raise FMUNotFound(f"FMU file not found: looked at {path}") from None
    except NotARegularFile as exc:
        if "folder" in str(exc):
            raise FMUInfoError(f"{shown} is a folder; give the path of the .fmu file") from None
        raise FMUInfoError(f"{shown} cannot be read as an FMU: {exc}; give the path of the .fmu file") from None
    except PermissionError:
        raise FMUInfoError(f"{shown} cannot be read: permission denied (check the permissions of the file "
                           "and of its folders)") from None
    except OSError as exc:
        if exc.errno == errno.ENOTDIR:
            raise FMUNotFound(f"FMU file not found: looked at {path} (a part of the path is a file, "
                              "not a folder)") from None
        raise FMUInfoError(f"{shown} cannot be read: {exc.strerror or exc}") from None
    except ValueError as exc:  # a NUL character in the path, or one the file names cannot hold
        raise FMUInfoError(f"{shown} cannot be read: {unusable_path(exc)}") from None


def shown_text(text: Any) -> str:
    """An attribute's text for a message: cut to SHOWN_TEXT characters."""
    text = str(text).strip()
    return text if len(text) <= SHOWN_TEXT else text[:SHOWN_TEXT] + "..."


def step_of(text: Any) -> Fraction:
    """A step attribute of a modelDescription (``stepSize``, ``fixedInternalStepSize``: an
    xs:double) as an exact duration: the decimal of the double it is, in the range of
    every duration (1e-12 s to 1e9 s, ``timebase.parse_duration``). ValueError says why
    not ("not a number", "out of range ..."), to follow the attribute's name and text. The exact decimal of the text itself could hold thousands of digits (or 1e999999999,
    whose Fraction would take forever), and a schedule of such a step would not end."""
    try:
        value = float(str(text).strip())
    except ValueError:
        raise ValueError("not a number") from None
    if not math.isfinite(value) or value <= 0:
        raise ValueError("not a positive finite number of seconds")
    try:
        return parse_duration(value)
    except DurationError:
        raise ValueError("out of range (1e-12 s to 1e9 s)") from None


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
        """The FMU's fixed internal step, if it declares a usable one (``fixed_step_text``
        read by ``step_of``; None for one out of range)."""
        text = self.fixed_step_text()
        try:
            return step_of(text) if text is not None else None
        except ValueError:
            return None

    def fixed_step_text(self) -> str | None:
        """The text of the fixed internal step, if the FMU gives one: FMI 3
        ``fixedInternalStepSize`` of ``<CoSimulation>``; FMI 2 has no such attribute, so
        there the same attribute is read from a ``<CoSimulation>`` element in any tool's
        ``<VendorAnnotations>``."""
        cs = self.md.coSimulation
        value = getattr(cs, "fixedInternalStepSize", None) if cs is not None else None
        if value is None and self.md.fmiVersion == "2.0":
            try:
                root = ElementTree.fromstring(self.xml)
            except ElementTree.ParseError:
                return None
            for element in root.iterfind("VendorAnnotations/Tool/CoSimulation"):
                value = element.get("fixedInternalStepSize") or value
        return None if value is None else str(value)


def variable_unit(v: Any) -> str | None:
    """The unit of a variable as its modelDescription declares it: the ``unit`` attribute of
    a Real (FMI 2) or Float32/Float64 (FMI 3) variable, else that of its declared type
    (FMI 2 ``<SimpleType><Real unit=...>``, FMI 3 ``<Float64Type unit=...>``); None when
    neither gives one (and for integer, Boolean and other variables, which have no unit)."""
    unit = getattr(v, "unit", None)
    if not unit and getattr(v, "declaredType", None) is not None:
        unit = getattr(v.declaredType, "unit", None)
    return str(unit) if unit else None


_reading = threading.Lock()
"""Held while fmpy reads a modelDescription: it validates with one lxml schema, which
threads cannot use at once (a spurious 'Internal error: xmlSchemaPValAttrNodeValue')."""


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
        with _reading:
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
    shown = f"FMU '{path}'"
    open_fmu_file(path, shown).close()
    description = read_description(path, shown, validate=False)
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
    step, text = description.fixed_step(), description.fixed_step_text()
    if step is not None:
        lines.append(f"  fixed internal step: {float(step):g} s (informative)")
    elif text is not None:
        lines.append(f"  fixed internal step: {_step_text(text)}")
    cs = md.coSimulation
    if cs is not None and not cs.canHandleVariableCommunicationStepSize:
        lines.append("  communication step: fixed (canHandleVariableCommunicationStepSize is false)")
    if md.modelExchange is not None:
        completed = "needs" if md.modelExchange.needsCompletedIntegratorStep else "does not need"
        lines.append(f"  model exchange: {md.numberOfContinuousStates} continuous states, "
                     f"{md.numberOfEventIndicators} event indicators; {completed} completedIntegratorStep")
    de = md.defaultExperiment
    if de is not None:
        parts = [f"{k} {_step_text(value) if k == 'step' else shown_text(value)}"
                 for k, value in (("start", de.startTime), ("stop", de.stopTime), ("step", de.stepSize),
                                  ("tolerance", de.tolerance)) if value is not None]
        lines.append(f"  default experiment: {', '.join(parts) or '-'}")
    else:
        lines.append("  default experiment: none")
    lines.append(f"  variables ({len(md.modelVariables)}):")
    width = max((len(v.name) for v in md.modelVariables), default=4)
    lines.append(f"    {'name':<{width}}  {'causality':<15} {'variability':<12} {'type':<8} start")
    for v in md.modelVariables:
        start = "" if v.start is None else shown_text(v.start)
        unit = f" {variable_unit(v)}" if variable_unit(v) else ""
        lines.append(f"    {v.name:<{width}}  {v.causality or '':<15} {v.variability or '':<12} "
                     f"{v.type:<8} {start}{unit}")
    return "\n".join(lines)


def _step_text(text: Any) -> str:
    """A step attribute as ``fmu info`` shows it: its text, or why ``step_of`` refuses it."""
    try:
        step_of(text)
    except ValueError as exc:
        return f"{shown_text(text)} (not usable: {exc})"
    return shown_text(text)
