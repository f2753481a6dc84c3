"""The first-order test FMUs of the FMU tests (``sources/first_order_fmi*``), compiled once
per test module; without a C compiler the tests that use them are skipped."""

from __future__ import annotations

from pathlib import Path

import pytest

fmpy = pytest.importorskip("fmpy")

from .build import (  # noqa: E402
    MISBEHAVING,
    SOURCES,
    build_error,
    compile_library,
    interrupting_library,
    marker_library,
    misbehaving_library,
    zip_files,
)


class Fmus:
    """Builds FMU files in a folder from the compiled binaries and (edited) model descriptions."""

    def __init__(self, folder: Path, lib2: bytes, lib3: bytes, marker: bytes, markers: Path,
                 interrupting: dict[int, bytes]):
        self.folder = folder
        self.lib2, self.lib3 = lib2, lib3
        self.marker, self.markers = marker, markers
        self.interrupting = interrupting
        self.xml2 = (SOURCES / "first_order_fmi2.xml").read_text()
        self.xml3 = (SOURCES / "first_order_fmi3.xml").read_text()
        self.fmi2 = self.make("first_order.fmu")
        self.fmi3 = self.make("first_order3.fmu", version=3)

    def make(self, name: str, xml: str | None = None, version: int = 2, binary: bool = True) -> Path:
        ext = fmpy.sharedLibraryExtension
        if version == 2:
            files = {"modelDescription.xml": self.xml2 if xml is None else xml}
            if binary:
                files[f"binaries/{fmpy.platform}/FirstOrder{ext}"] = self.lib2
        else:
            files = {"modelDescription.xml": self.xml3 if xml is None else xml}
            if binary:
                files[f"binaries/{fmpy.platform_tuple}/FirstOrder3{ext}"] = self.lib3
        return zip_files(self.folder / name, files)

    def with_fixed_step(self, version: int, step: str, name: str) -> Path:
        """The first-order FMU declaring a fixed internal step: FMI 3's fixedInternalStepSize,
        for FMI 2 the same attribute in a vendor annotation."""
        if version == 3:
            xml = self.xml3.replace("<CoSimulation ", f'<CoSimulation fixedInternalStepSize="{step}" ')
        else:
            annotation = (f'<VendorAnnotations><Tool name="some tool"><CoSimulation fixedInternalStepSize="{step}"/>'
                          "</Tool></VendorAnnotations>\n  <ModelVariables>")
            xml = self.xml2.replace("<ModelVariables>", annotation)
        return self.make(name, xml, version=version)


@pytest.fixture(scope="module")
def fmus(tmp_path_factory) -> Fmus:
    why = build_error()
    if why:
        pytest.skip(why)
    build = tmp_path_factory.mktemp("fmu_build")
    markers = tmp_path_factory.mktemp("fmu_markers")
    lib2 = compile_library(build / ("fo2" + fmpy.sharedLibraryExtension), "first_order_fmi2.c",
                           "fmi2_unsupported.c")
    lib3 = compile_library(build / ("fo3" + fmpy.sharedLibraryExtension), "first_order_fmi3.c",
                           "fmi3_unsupported.c")
    interrupting = {status: interrupting_library(build, status) for status in (0, 4)}
    return Fmus(tmp_path_factory.mktemp("fmus"), lib2, lib3, marker_library(build, markers), markers,
                interrupting)


@pytest.fixture(scope="session")
def misbehaving(tmp_path_factory) -> dict[str, bytes]:
    """The libraries of the misbehaving test FMUs (``sources/misbehave.h``), by kind."""
    why = build_error()
    if why:
        pytest.skip(why)
    build = tmp_path_factory.mktemp("misbehaving")
    return {kind: misbehaving_library(build, kind) for kind in MISBEHAVING}
