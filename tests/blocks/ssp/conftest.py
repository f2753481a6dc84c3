"""SSPs written by hand for the SSP tests: the first-order test FMU (``tests/blocks/fmu``)
built once per session, SSD text wrapped in the standard's root element, packages as
folders or zip archives, and the SSP schemas (``schema/``, BSD-2, from the SSP standard's
repository) to validate SSDs against."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

from tests.blocks.fmu.build import SOURCES, build_error, compile_library, fmi2_files, zip_bytes

SCHEMA = Path(__file__).parent / "schema"
NAMESPACES = ('xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" '
              'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" '
              'xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" '
              'xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping" '
              'xmlns:osp="http://opensimulationplatform.com/SSP/OSPAnnotations" '
              'xmlns:oms="https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd"')


@pytest.fixture(scope="session")
def first_order_library(tmp_path_factory) -> bytes:
    """The shared library of the FMI 2 first-order test FMU."""
    why = build_error()
    if why:
        pytest.skip(why)
    build = tmp_path_factory.mktemp("ssp_fmu")
    return compile_library(build / "fo.so", "first_order_fmi2.c", "fmi2_unsupported.c")


@pytest.fixture(scope="session")
def first_order(first_order_library) -> bytes:
    """The bytes of the FMI 2 first-order test FMU (x[k+1] = a x[k] + b u[k], y = x,
    z = [scale x, t]; its DefaultExperiment step 0.1 s)."""
    return zip_bytes(fmi2_files(first_order_library))


def variant(library: bytes, *edits: tuple[str, str]) -> bytes:
    """The first-order FMU with its modelDescription edited (each (old, new) replaced once)."""
    xml = (SOURCES / "first_order_fmi2.xml").read_text()
    for old, new in edits:
        assert old in xml, old
        xml = xml.replace(old, new, 1)
    return zip_bytes(fmi2_files(library, xml))


NO_STEP = ('<DefaultExperiment startTime="0" stopTime="1" stepSize="0.1"/>', '<DefaultExperiment startTime="0" stopTime="1"/>')
"""The edit that leaves the FMU's DefaultExperiment without a step."""


def ssd(body: str, name: str = "system", experiment: str = '<ssd:DefaultExperiment startTime="0" stopTime="1"/>',
        version: str = "1.0") -> str:
    """An SSD: ``body`` (the top ssd:System's content) inside the root element."""
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n<ssd:SystemStructureDescription name="{name}" '
            f'version="{version}" {NAMESPACES}>\n<ssd:System name="root">\n{body}\n</ssd:System>\n{experiment}\n'
            "</ssd:SystemStructureDescription>\n")


def hint(step: str) -> str:
    """A component's libcosim step-size hint."""
    return (f'<ssd:Annotations><ssc:Annotation type="com.opensimulationplatform"><osp:StepSizeHint value="{step}"/>'
            "</ssc:Annotation></ssd:Annotations>")


def write_ssp(folder: Path, text: str, fmu: bytes, files: dict[str, str | bytes] | None = None,
              archive: bool = False) -> Path:
    """An SSP of the SSD ``text``, the FMU as resources/fo.fmu and ``files``: a folder, or
    (``archive``) a .ssp zip next to where the folder would be."""
    members = {"SystemStructure.ssd": text, "resources/fo.fmu": fmu, **(files or {})}
    if archive:
        path = folder.with_suffix(".ssp")
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
            for member, data in members.items():
                zf.writestr(member, data)
        return path
    for member, data in members.items():
        target = folder / member
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data if isinstance(data, bytes) else data.encode("utf-8"))
    return folder


def schema_errors(ssd_file: Path) -> list[str]:
    """Where the SSD breaks the SSP schema (none: valid)."""
    from lxml import etree

    schema = etree.XMLSchema(etree.parse(str(SCHEMA / "SystemStructureDescription.xsd")))
    document = etree.parse(str(ssd_file))
    schema.validate(document)
    return [f"{e.line}: {e.message}" for e in schema.error_log]
