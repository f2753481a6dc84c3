"""The C sources of the hand core and what is built from them (read by setup.py too).

One list, so that the extension, the FMU libraries built at install and the ``sources/``
folder of an exported FMU always hold the same files. Paths are relative to the
repository root (``CSRC``); the exporter copies ``FMU_SOURCES`` flat into ``sources/``.
"""

from __future__ import annotations

import hashlib
import importlib.util
from pathlib import Path

CSRC = "hierhand/csrc"

CORE = ["hand_params.c", "contact.c", "plant.c"]
CORE_HEADERS = ["hand.h", "kinematics.h", "dynamics.h", "contact.h"]
CONTROL = ["reflex.c", "manipulation.c", "suppresser.c", "control_params.c", "kernels.c"]
CONTROL_HEADERS = ["control.h", "float_ops.h", "kernels.h"]
BINDING = ["python/module.c", "python/py_common.c", "python/py_model.c", "python/py_plant.c", "python/py_control.c",
           "python/py_kernels.c"]
FMU_COMMON = ["fmu_instance.c"]
FMU_HEADERS = ["fmu_instance.h"]
FMI_WRAPPERS = {2: "fmi2_functions.c", 3: "fmi3_functions.c"}

CFLAGS = ["-O2", "-fvisibility=hidden", "-fno-math-errno", "-ffp-contract=off", "-Wall"]
"""-ffp-contract=off: no fused multiply-adds, so every build rounds as the reference does."""


def _paths(names: list[str]) -> list[str]:
    return [f"{CSRC}/{name}" for name in names]


EXTENSION_SOURCES = _paths(CORE + CONTROL + BINDING)
EXTENSION_DEPENDS = _paths(CORE_HEADERS + CONTROL_HEADERS + FMU_HEADERS + ["python/py_common.h"]) + [
    "blocks/csrc/blocks_kernel.h"  # the calling convention of py_kernels.c
]
"""Headers whose change must rebuild the extension."""
FMI_LIBRARIES = {fmi: _paths(CORE + FMU_COMMON + [wrapper]) for fmi, wrapper in FMI_WRAPPERS.items()}
FMI_DEPENDS = _paths(CORE_HEADERS + FMU_HEADERS)


def fmu_source_files(fmi: int) -> list[str]:
    """File names (inside ``CSRC``) an FMU of this FMI version carries in ``sources/``."""
    return CORE + FMU_COMMON + [FMI_WRAPPERS[fmi]] + CORE_HEADERS + FMU_HEADERS


def fmu_compiled_files(fmi: int) -> list[str]:
    """The ``.c`` files among ``fmu_source_files``: what an importer compiles."""
    return [name for name in fmu_source_files(fmi) if name.endswith(".c")]


def fmi_headers() -> str:
    """The folder of the FMI 2 / 3 headers the libraries are built against (fmpy's copy)."""
    spec = importlib.util.find_spec("fmpy")
    if spec is None or not spec.submodule_search_locations:
        raise RuntimeError("building hierhand needs fmpy (for the FMI headers); pip installs it as a build requirement")
    folder = Path(list(spec.submodule_search_locations)[0]) / "c-code"
    if not (folder / "fmi2Functions.h").is_file() or not (folder / "fmi3Functions.h").is_file():
        raise RuntimeError(f"fmpy's FMI headers are missing from {folder}")
    return str(folder)


def sources_digest(root: Path) -> str:
    """The hash of every C source and header under ``root / CSRC``: the build stamps it into
    the extension, so that a checkout whose C sources changed since the build says so."""
    folder = Path(root) / CSRC
    h = hashlib.sha256()
    for path in sorted(folder.rglob("*")):
        if path.suffix in (".c", ".h"):
            h.update(path.relative_to(folder).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()
