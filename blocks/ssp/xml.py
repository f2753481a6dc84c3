"""The SSP's XML: its namespaces and prefixes, safe parsing with lines, numbers as exact text.

SSD, SSV and SSM files come from other tools, so they are parsed without DTDs, entities or
network access, and under a size limit. Every element keeps its source line
(``sourceline``), which the messages about it give. Names are written with the
prefixes the standard's examples use (``ssd:``, ``ssc:``, ``ssv:``, ``ssm:``), since some
readers (libcosim) match the prefixes rather than the namespaces.
"""

from __future__ import annotations

import math

import os
import re
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..timebase import DurationError, parse_duration

_DECIMAL = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
SSM = "http://ssp-standard.org/SSP1/SystemStructureParameterMapping"
SSB = "http://ssp-standard.org/SSP1/SystemStructureSignalDictionary"
OSP = "http://opensimulationplatform.com/SSP/OSPAnnotations"
OMS = "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd"
BLOCKS = "urn:hierhand:blocks:ssp"
PREFIXES = {"ssd": SSD, "ssc": SSC, "ssv": SSV, "ssm": SSM, "osp": OSP, "oms": OMS, "blocks": BLOCKS}

OSP_ANNOTATION = "com.opensimulationplatform"
"""The annotation type libcosim reads (step-size hints, the fixed-step algorithm)."""
OMS_ANNOTATION = "org.openmodelica"
"""The annotation type OMSimulator reads (its simulation information)."""

BLOCKS_ANNOTATION = "org.hierhand.blocks"
"""The annotation type this package reads and writes (how a component is stepped)."""

MAX_XML_BYTES = 16 * 1024 * 1024
"""Limit on the size of one SSD, SSV or SSM file."""


class XmlError(ValueError):
    """An XML file that cannot be read: ``line`` where, if known."""

    def __init__(self, message: str, line: int | None = None):
        super().__init__(message)
        self.line = line


def q(prefix: str, name: str) -> str:
    """The qualified (Clark) name ``{namespace}name`` of ``prefix:name``."""
    return f"{{{PREFIXES[prefix]}}}{name}"


def parse_file(path: Path) -> tuple[Any, str]:
    """The root element of the XML file ``path`` and its text; XmlError if it cannot be read."""
    from lxml import etree

    from ..fmu.archive import NotARegularFile, open_regular

    try:
        with open_regular(path) as fp:  # a FIFO or a device is refused unopened, not waited on or read
            size = os.fstat(fp.fileno()).st_size
            data = fp.read(MAX_XML_BYTES + 1) if size <= MAX_XML_BYTES else b""
        if size > MAX_XML_BYTES or len(data) > MAX_XML_BYTES:
            raise XmlError(f"the file is {max(size, len(data))} bytes or more, more than the limit of {MAX_XML_BYTES}")
    except NotARegularFile as exc:
        raise XmlError(f"cannot be read: {exc}") from None
    except OSError as exc:
        raise XmlError(f"cannot be read: {exc.strerror or exc}") from None
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False,
                             remove_comments=True, remove_pis=True)
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        raise XmlError(f"not well-formed XML: {exc.msg}", exc.lineno) from None
    return root, data.decode("utf-8", "replace")


def local(element: Any) -> str:
    """The element's name without its namespace."""
    tag = element.tag
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def namespace(element: Any) -> str:
    tag = element.tag
    return tag[1:].split("}", 1)[0] if isinstance(tag, str) and tag.startswith("{") else ""


def elements(parent: Any) -> list:
    """The child elements of ``parent`` (comments and text left out)."""
    return [c for c in parent if isinstance(c.tag, str)] if parent is not None else []


def child(parent: Any, prefix: str, name: str) -> Any:
    return parent.find(q(prefix, name)) if parent is not None else None


def children(parent: Any, prefix: str, name: str) -> list:
    return parent.findall(q(prefix, name)) if parent is not None else []


def annotations(element: Any, kind: str) -> list:
    """The contents (child elements) of ``element``'s ``ssd:Annotations`` of type ``kind``."""
    found = []
    for annotation in children(child(element, "ssd", "Annotations"), "ssc", "Annotation"):
        if annotation.get("type") == kind:
            found.extend(elements(annotation))
    return found


def exact(text: str) -> Fraction:
    """A time written in the XML (``xs:double``: ``0.001``, ``1e-4``) as the exact
    rational of its decimal text, read by ``timebase.parse_duration`` so that its range
    (0, or 1e-12 s to 1e9 s) is checked before any exact arithmetic (``1e999999999`` would
    be a number of a billion digits); ValueError (a DurationError) says why it is not one."""
    if not _DECIMAL.fullmatch(text.strip()):
        raise DurationError(f"{shown(text)} is not a decimal number")
    return parse_duration(text.strip())


def shown(text: Any) -> str:
    """An attribute's text for a message: at most 60 characters, quoted."""
    s = str(text)
    return repr(s if len(s) <= 60 else s[:57] + "...")


def whole(text: str) -> int:
    """A whole number of at most 24 characters (an Int64 has 20); ValueError otherwise."""
    if len(text.strip()) > 24:
        raise ValueError(text)
    return int(text.strip())


def finite(text: str) -> float:
    """A real number written in the XML; ValueError for one that is not finite (``INF``,
    ``NaN``, ``1e999``): no parameter, factor or offset is meant to be."""
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(text)
    return value
