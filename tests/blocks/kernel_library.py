"""The test kernels of ``kernel_sources/leak.c``, compiled with the calling convention's
header (blocks/csrc/blocks_kernel.h), and the addresses of their functions."""

from __future__ import annotations

import ctypes
import subprocess
from pathlib import Path

from .fmu.build import compiler

SOURCES = Path(__file__).parent / "kernel_sources"
HEADERS = Path(__file__).resolve().parents[2] / "blocks" / "csrc"


def build(target: Path) -> ctypes.CDLL | None:
    """leak.c built into the shared library ``target``; None without a C compiler."""
    if compiler() is None:
        return None
    cmd = [compiler(), "-shared", "-fPIC", "-O2", "-ffp-contract=off", f"-I{HEADERS}", str(SOURCES / "leak.c"),
           "-o", str(target), "-lm"]
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    return ctypes.CDLL(str(target))


def function(lib: ctypes.CDLL, name: str) -> int:
    """The address of a function of the library, for a Kernel."""
    return ctypes.cast(getattr(lib, name), ctypes.c_void_p).value
