"""The FMU binaries the build links (blocks' and hierhand's, FMI 2 and FMI 3) load on any
Linux of the last decade: no RUNPATH or RPATH (the building machine's folders), and no
glibc symbol version newer than 2.17 (glibc 2.29 gave exp, log and pow new versions, 2.35
hypot: setup.py binds them to their oldest, blocks/csrc/glibc_compat.h). Read with binutils'
readelf from the binaries in the packages and from an exported FMU of each package."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import blocks
from blocks.fmu_export import export_fmu

REPO = Path(__file__).resolve().parents[1]
BINARIES = sorted(p for package in ("blocks", "hierhand") for p in (REPO / package / "fmu_binaries").glob("fmi*.so"))
OLDEST = (2, 17)

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc symbol versions: Linux only")


def readelf(*args: str) -> str:
    tool = shutil.which("readelf")
    if tool is None:
        pytest.skip("readelf (binutils) is not installed")
    return subprocess.run([tool, *args], capture_output=True, text=True, check=True).stdout


def glibc_versions(library: Path) -> set[tuple[int, ...]]:
    """The glibc versions the library's dynamic symbols ask for."""
    text = readelf("--dyn-syms", "--wide", str(library))
    return {tuple(int(n) for n in v.split(".")) for v in re.findall(r"@GLIBC_([0-9.]+)", text)}


def check_portable(library: Path) -> None:
    dynamic = readelf("-d", str(library))
    assert "RUNPATH" not in dynamic and "RPATH" not in dynamic, dynamic
    versions = glibc_versions(library)
    assert versions, "no glibc symbol read: the check would pass on anything"
    assert max(versions) <= OLDEST, f"{library.name} needs glibc {'.'.join(map(str, max(versions)))}"


@pytest.mark.parametrize("library", BINARIES, ids=lambda p: f"{p.parent.parent.name}-{p.name}")
def test_the_built_fmu_binaries_are_portable(library):
    check_portable(library)


def test_there_are_four_binaries():
    assert [f"{p.parent.parent.name}/{p.name}" for p in BINARIES] == [
        "blocks/fmi2.so", "blocks/fmi3.so", "hierhand/fmi2.so", "hierhand/fmi3.so"]


@pytest.mark.parametrize("fmi", [2, 3])
def test_an_exported_fmu_carries_a_portable_binary(tmp_path, fmi):
    path = export_fmu(blocks.load_diagram(REPO / "diagrams" / "toy.yaml"), tmp_path / "toy.fmu", fmi)
    with zipfile.ZipFile(path) as zf:
        member = next(n for n in zf.namelist() if n.startswith("binaries/") and n.endswith(".so"))
        zf.extract(member, tmp_path)
    check_portable(tmp_path / member)
