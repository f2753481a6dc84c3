"""Fixtures that several of the hand's test modules share: the native re-grasp run and a
C host of FMI 2 FMUs compiled without Python."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from blocks.engine.native_sources import FMI_HEADERS

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def native_regrasp():
    """diagrams/regrasp.yaml run natively."""
    import blocks

    return blocks.simulate(blocks.load_diagram(REPO / "diagrams" / "regrasp.yaml"))


@pytest.fixture(scope="session")
def c_host(tmp_path_factory):
    """tests/hierhand/fmu_host/fmi2_host.c compiled: dlopen and the FMI 2 API, no Python."""
    compiler = shutil.which("gcc") or shutil.which("cc")
    if compiler is None:
        pytest.skip("no C compiler")
    exe = tmp_path_factory.mktemp("host") / "fmi2_host"
    subprocess.run([compiler, "-std=c99", "-O1", "-I", str(REPO / FMI_HEADERS), "-o", str(exe),
                    str(Path(__file__).with_name("fmu_host") / "fmi2_host.c"), "-ldl"], check=True)
    return exe
