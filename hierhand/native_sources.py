"""The C sources of the hand core and what is built from them (read by setup.py too).

One rule, so that the extension, the FMU binaries built at install and the ``sources/``
folder of an exported FMU always hold the same files: every C file directly in
``hierhand/csrc`` is the hand's C code (the plant core, the controllers' laws and every
kernel type, ``layouts.h`` listing the types), which the extension and the FMU binaries
both compile; ``python/`` holds the extension's binding, and the kernel-set file
``fmu_kernel_set.c`` only the FMU binaries'. A new block type's C file is therefore
built without being listed. Paths are relative to the repository root (``CSRC``); an
export copies its files flat into ``sources/``. Like ``blocks.engine.native_sources``
this module imports nothing of the packages, so that setup.py can read it before anything
is built.

hierhand's FMU binary is the framework's (``blocks.engine.native_sources.fmu_sources``)
with the hand's kernel types beside the library's, so any diagram of library and hand
blocks leaves as an FMU.
"""

from __future__ import annotations

import os
import zlib

CSRC = "hierhand/csrc"
KERNEL_SET = "fmu_kernel_set.c"

_FOLDER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "csrc")


def _names(pattern: str) -> list[str]:
    """The files of ``hierhand/csrc`` matching ``pattern`` (``*.c``, ``python/*.c``), sorted,
    relative to it (os.path, not pathlib: this module is read on every import of hierhand)."""
    folder, _, suffix = pattern.rpartition("/")
    here = os.path.join(_FOLDER, folder)
    return sorted(f"{folder}/{name}" if folder else name for name in os.listdir(here)
                  if name.endswith(suffix.lstrip("*")) and os.path.isfile(os.path.join(here, name)))


HAND_SOURCES = [name for name in _names("*.c") if name != KERNEL_SET]
"""The hand's C code, which the extension and the FMU binaries compile alike."""
HAND_HEADERS = _names("*.h")
BINDING = _names("python/*.c")


def _paths(names: list[str]) -> list[str]:
    return [f"{CSRC}/{name}" for name in names]


EXTENSION_SOURCES = _paths(HAND_SOURCES + BINDING)
EXTENSION_DEPENDS = _paths(HAND_HEADERS + _names("python/*.h")) + [
    "blocks/csrc/blocks_kernel.h"  # the calling convention of the kernel types
]
"""Headers whose change must rebuild the extension."""


def fmu_sources(framework: list[str]) -> list[str]:
    """Every file (repository paths) of hierhand's FMU binary of one FMI version: the
    framework's (``framework``, from ``blocks.engine.native_sources.fmu_sources``), the hand's
    kernels and its kernel-set file; C files first, then headers."""
    c_files = [p for p in framework if p.endswith(".c")] + _paths(HAND_SOURCES + [KERNEL_SET])
    return c_files + [p for p in framework if not p.endswith(".c")] + _paths(HAND_HEADERS)


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
