"""Builds the test FMUs of ``sources/`` at test time, for the FMU block tests and the
hostile-input corpus.

The shared libraries are compiled with the system C compiler against the FMI headers
that the repository carries (``blocks/csrc/fmi``); ``build_error()`` says why that cannot
be done here (no compiler, Windows, no headers), and the tests that need a library skip
with that reason.
"""

from __future__ import annotations

import hashlib
import io
import os
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import fmpy

from blocks.engine.native_sources import FMI_HEADERS

SOURCES = Path(__file__).parent / "sources"
HEADERS = Path(__file__).resolve().parents[3] / FMI_HEADERS
EXT = fmpy.sharedLibraryExtension


def compiler() -> str | None:
    """The C compiler to use ($CC, cc, gcc or clang), or None."""
    for name in (os.environ.get("CC"), "cc", "gcc", "clang"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


def build_error() -> str | None:
    """Why the test FMUs cannot be built here, or None if they can."""
    if sys.platform.startswith("win"):
        return "the test FMUs are built with a Unix C compiler"
    if compiler() is None:
        return "no C compiler (cc, gcc or clang) on PATH to build the test FMUs"
    if not (HEADERS / "fmi2Functions.h").is_file() or not (HEADERS / "fmi3Functions.h").is_file():
        return f"the FMI headers are missing (looked in {HEADERS})"
    return None


CACHE = Path(tempfile.gettempdir()) / f"hierhand-test-fmus-{os.getuid() if hasattr(os, 'getuid') else 0}"
"""Compiled test libraries by the hash of everything that makes them (``compile_library``):
the test modules and the suite's workers build the same few libraries many times."""


def compile_library(target: Path, *sources: str, defines: dict[str, str] | None = None) -> bytes:
    """Compile ``sources`` (names in ``sources/``) into the shared library ``target``;
    ``defines`` become ``-D`` options. Returns the library's bytes. A library compiled before
    from the same command, sources and headers (``CACHE``) is copied instead."""
    flags = [f"-D{k}={v}" for k, v in (defines or {}).items()]
    cmd = [compiler(), "-shared", "-fPIC", "-O1", f"-I{HEADERS}", *flags,
           *(str(SOURCES / s) for s in sources), "-o", str(target), "-lm"]
    key = hashlib.sha256("\0".join(cmd[:-3]).encode())
    for path in sorted([*SOURCES.iterdir(), *HEADERS.iterdir()]):
        key.update(path.name.encode() + b"\0" + path.read_bytes())
    cached = CACHE / f"{key.hexdigest()}{EXT}"
    if not cached.is_file():
        done = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            raise RuntimeError(f"compiling the test FMU failed:\n{' '.join(cmd)}\n{done.stderr}")
        CACHE.mkdir(exist_ok=True)
        partial = cached.with_name(f"{cached.name}.{os.getpid()}")
        shutil.copyfile(target, partial)
        os.replace(partial, cached)  # whole or absent for the other workers
        return target.read_bytes()
    shutil.copyfile(cached, target)
    return target.read_bytes()


def zip_files(path: Path, files: dict[str, bytes | str]) -> Path:
    """Write a zip archive of ``files`` (member name -> content)."""
    path.write_bytes(zip_bytes(files))
    return path


def zip_bytes(files: dict[str, bytes | str]) -> bytes:
    """A zip archive of ``files`` (member name -> content), in memory."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, data in files.items():
            zf.writestr(name, data)
    return buffer.getvalue()


def fmi2_files(library: bytes, xml: str | None = None, identifier: str = "FirstOrder") -> dict[str, bytes | str]:
    """The members of an FMI 2 first-order FMU: its modelDescription (by default the one of
    ``first_order_fmi2.xml``, under model identifier ``identifier``) and ``library``."""
    if xml is None:
        xml = (SOURCES / "first_order_fmi2.xml").read_text()
    xml = xml.replace('modelIdentifier="FirstOrder"', f'modelIdentifier="{identifier}"')
    return {"modelDescription.xml": xml, f"binaries/{fmpy.platform}/{identifier}{EXT}": library}


def marker_library(build: Path, markers: Path) -> bytes:
    """The FMI 2 first-order FMU's library with ``marker.c``: it leaves
    ``<library file>.loaded`` in ``markers`` when loaded and ``<library file>.instantiated``
    when fmi2Instantiate runs (see ``fmu_sources/marker.c``)."""
    return compile_library(build / f"marker{EXT}", "first_order_fmi2.c", "fmi2_unsupported.c", "marker.c",
                           defines={"TRACE_RUNS": "1", "MARKER_DIR": f'"{markers}"'})


def interrupting_library(build: Path, status: int, at: float = 0.2) -> bytes:
    """The FMI 2 first-order FMU's library whose doStep, from time ``at`` on, sends the
    process SIGINT (as Ctrl-C would), logs a message and returns ``status`` (0 ok, 3 error,
    4 fatal: what an FMU does whose memory callback Ctrl-C broke)."""
    return compile_library(build / f"interrupting{status}{EXT}", "first_order_fmi2.c", "fmi2_unsupported.c",
                           defines={"SIGINT_AT": repr(at), "SIGINT_STATUS": str(status)})


def typed_library(build: Path, fmi: int) -> bytes:
    """The library of the conformance FMU ``typed_fmi2.c`` / ``typed_fmi3.c``, built in ``build``."""
    return compile_library(build / f"Typed{fmi}{EXT}", f"typed_fmi{fmi}.c", f"fmi{fmi}_unsupported.c",
                           defines={"STEP_STATUS": "1"} if fmi == 2 else {"TYPED_ACCESSORS": "1", "MODEL_EXCHANGE": "1"})


def typed_fmu(build: Path, fmi: int, members: dict[str, bytes | str] | None = None,
              only: str | None = None) -> Path:
    """The conformance FMU of ``typed_fmi2.c`` / ``typed_fmi3.c`` (a port of every type of
    that FMI version, terminating at its parameter ``stop_at``), with extra ``members``.
    It offers co-simulation and model exchange, or only the interface ``only`` names
    (``CoSimulation`` or ``ModelExchange``)."""
    identifier = f"Typed{fmi}"
    library = typed_library(build, fmi)
    platform = fmpy.platform if fmi == 2 else fmpy.platform_tuple
    xml = (SOURCES / f"typed_fmi{fmi}.xml").read_text()
    if only is not None:
        other = {"CoSimulation": "ModelExchange", "ModelExchange": "CoSimulation"}[only]
        xml = re.sub(rf"\s*<{other} [^>]*/>", "", xml)
    files = {"modelDescription.xml": xml, f"binaries/{platform}/{identifier}{EXT}": library, **(members or {})}
    return zip_files(build / f"typed{fmi}{only or ''}.fmu", files)


ME_MODELS = ("linear", "bouncing", "stair")
"""The model-exchange test models of ``sources/`` (``me_model.h``), each an FMI 2 and an FMI 3 FMU."""


def me_fmu(build: Path, model: str, fmi: int, defines: dict[str, str] | None = None, name: str | None = None) -> Path:
    """The model-exchange FMU of the test model ``model`` (``linear``, ``bouncing``, ``stair``, ``sawtooth``)
    for FMI version ``fmi``: the model's source with the FMI wrapper ``me_fmi2.c`` / ``me_fmi3.c``
    (``defines`` become ``-D`` options), and its ``<model>_fmi<fmi>.xml``."""
    identifier = f"{model.capitalize()}{fmi}"
    wrapper = {"MODEL_EXCHANGE": "1", "NO_CO_SIMULATION": "1"} if fmi == 3 else {}
    library = compile_library(build / f"{name or identifier}{EXT}", f"{model}.c", f"me_fmi{fmi}.c",
                              f"fmi{fmi}_unsupported.c", defines={**wrapper, **(defines or {})})
    platform = fmpy.platform if fmi == 2 else fmpy.platform_tuple
    files = {"modelDescription.xml": (SOURCES / f"{model}_fmi{fmi}.xml").read_text(),
             f"binaries/{platform}/{identifier}{EXT}": library}
    return zip_files(build / f"{name or identifier}.fmu", files)


MISBEHAVING = {
    "cs2": (("first_order_fmi2.c", "fmi2_unsupported.c"), "first_order_fmi2.xml", "FirstOrder", 2),
    "cs3": (("first_order_fmi3.c", "fmi3_unsupported.c"), "first_order_fmi3.xml", "FirstOrder3", 3),
    "me2": (("linear.c", "me_fmi2.c", "fmi2_unsupported.c"), "linear_fmi2.xml", "Linear2", 2),
}
"""The test FMUs that can misbehave (``sources/misbehave.h``): FMI 2 and FMI 3 co-simulation
(the first-order FMUs) and FMI 2 model exchange (the linear oscillator)."""


def misbehaving_library(build: Path, kind: str) -> bytes:
    """The library of the misbehaving test FMU ``kind`` (a key of MISBEHAVING), built in ``build``."""
    sources, _, identifier, _ = MISBEHAVING[kind]
    return compile_library(build / f"misbehaving_{identifier}{EXT}", *sources, "misbehave.c",
                           defines={"MISBEHAVE": "1"})


def misbehaving_fmu(path: Path, kind: str, library: bytes, instructions: str = "") -> Path:
    """The misbehaving test FMU ``kind`` with ``library`` as its binary, at ``path``; it does
    what ``instructions`` say (a line of ``sources/misbehave.h``: "fmi2DoStep segv 0.3"),
    nothing unusual without them."""
    _, xml, identifier, fmi = MISBEHAVING[kind]
    platform = fmpy.platform if fmi == 2 else fmpy.platform_tuple
    files: dict[str, bytes | str] = {"modelDescription.xml": (SOURCES / xml).read_text(),
                                     f"binaries/{platform}/{identifier}{EXT}": library}
    if instructions:
        files["resources/misbehave.txt"] = instructions + "\n"
    return zip_files(path, files)
