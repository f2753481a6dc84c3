"""The C sources of the hand core and what is built from them (read by setup.py too).

One list, so that the extension, the FMU binaries built at install and the ``sources/``
folder of an exported FMU always hold the same files. Paths are relative to the
repository root (``CSRC``); an export copies its files flat into ``sources/``. Like
``blocks.engine.native_sources`` this module imports nothing of the packages, so that setup.py
can read it before anything is built.

hierhand's FMU binary is the framework's (``blocks.engine.native_sources.fmu_sources``) with the
hand's kernel types: the plant core and the controllers' laws, their kernels
(``kernels.c``) and the kernel-set file ``fmu_kernels.c`` that lists them beside the
library's, so any diagram of library and hand blocks leaves as an FMU.
"""

from __future__ import annotations

import os
import zlib

CSRC = "hierhand/csrc"

CORE = ["hand_params.c", "contact.c", "plant.c"]
CORE_HEADERS = ["hand.h", "kinematics.h", "dynamics.h", "contact.h"]
CONTROL = ["reflex.c", "manipulation.c", "suppresser.c", "control_params.c", "kernels.c"]
CONTROL_HEADERS = ["control.h", "float_ops.h", "kernels.h"]
BINDING = ["python/module.c", "python/py_common.c", "python/py_model.c", "python/py_plant.c", "python/py_control.c",
           "python/py_kernels.c"]
KERNEL_SET = "fmu_kernels.c"


def _paths(names: list[str]) -> list[str]:
    return [f"{CSRC}/{name}" for name in names]


EXTENSION_SOURCES = _paths(CORE + CONTROL + BINDING)
EXTENSION_DEPENDS = _paths(CORE_HEADERS + CONTROL_HEADERS + ["python/py_common.h"]) + [
    "blocks/csrc/blocks_kernel.h"  # the calling convention of kernels.c
]
"""Headers whose change must rebuild the extension."""


def fmu_sources(framework: list[str]) -> list[str]:
    """Every file (repository paths) of hierhand's FMU binary of one FMI version: the
    framework's (``framework``, from ``blocks.engine.native_sources.fmu_sources``), the hand's
    kernels and its kernel-set file; C files first, then headers."""
    c_files = [p for p in framework if p.endswith(".c")] + _paths(CORE + CONTROL + [KERNEL_SET])
    return c_files + [p for p in framework if not p.endswith(".c")] + _paths(CORE_HEADERS + CONTROL_HEADERS)


def sources_digest(root: str | os.PathLike) -> str:
    """A checksum of every C source and header under ``root / CSRC``: the build stamps it
    into the extension, so that a checkout whose C sources changed since the build says so.
    CRC-32 and Adler-32 of the names and contents (zlib, not hashlib, and os.path, not
    pathlib: this runs on every import of hierhand, before the command can handle Ctrl-C,
    and OpenSSL and pathlib take milliseconds to load; it detects edits, it is not a seal
    against tampering). Files are taken in the order of their relative paths' parts."""
    folder = os.path.join(root, CSRC)
    names = [tuple(os.path.relpath(os.path.join(here, name), folder).split(os.sep))
             for here, _, files in os.walk(folder) for name in files if name.endswith((".c", ".h"))]
    crc, adler, size = 0, 1, 0
    for parts in sorted(names):
        with open(os.path.join(folder, *parts), "rb") as source:
            data = "/".join(parts).encode() + b"\0" + source.read() + b"\0"
        crc, adler, size = zlib.crc32(data, crc), zlib.adler32(data, adler), size + len(data)
    return f"{crc:08x}{adler:08x}{size:x}"
