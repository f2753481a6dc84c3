"""Build the hand's C core: the Python extension and the FMI 2 / FMI 3 plant libraries.

Metadata lives in pyproject.toml; this file only declares what is compiled, because
setuptools' extension support is the build path every pip and every Python install
already has (no CMake, no code generator), and copies the shipped diagrams into the
package (``hierhand/diagrams/``), which package data cannot reach from outside it. The framework's extension ``blocks._native``
is the CPython host (``host.c``) of the op-table interpreter (``core.c``, plain C99 that
needs no Python), with the library's and the FMU block's kernels (``blocks/csrc``). Besides
the extension ``hierhand._native``
the build links two plain shared libraries from the same C sources,
``hierhand/fmu_binaries/fmi2.so`` and ``fmi3.so``, that ``hierhand fmu export`` copies
into FMUs, so exporting needs no compiler. They link libc and libm only; their FMI
headers come from fmpy (a build requirement), the headers an importer builds against too.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
sys.path.insert(0, str(ROOT / "hierhand"))
from native_sources import (  # noqa: E402 - the source lists live in the package, for the exporter
    CFLAGS,
    EXTENSION_DEPENDS,
    EXTENSION_SOURCES,
    FMI_DEPENDS,
    FMI_LIBRARIES,
    fmi_headers,
    sources_digest,
)

sys.path.pop(0)


class BuildNative(build_ext):
    """build_ext that also links the FMU libraries next to the extension."""

    def run(self) -> None:
        super().run()
        for fmi, sources in FMI_LIBRARIES.items():
            self._link_fmi_library(fmi, sources)

    def _link_fmi_library(self, fmi: int, sources: list[str]) -> None:
        relative = Path("hierhand", "fmu_binaries", f"fmi{fmi}.so")
        targets = [Path(self.build_lib) / relative]
        if self.inplace or getattr(self, "editable_mode", False):
            targets.append(ROOT / relative)
        objects = self.compiler.compile(
            sources,
            output_dir=os.path.join(self.build_temp, f"fmi{fmi}"),
            include_dirs=[fmi_headers()],
            depends=FMI_DEPENDS,
            extra_postargs=CFLAGS + ["-std=c99", "-g0"],  # no debug info in what FMUs carry
        )
        for target in targets:
            target.parent.mkdir(parents=True, exist_ok=True)
            self.compiler.link_shared_object(objects, str(target), libraries=["m"], extra_postargs=["-s"])

    def get_outputs(self) -> list[str]:
        outputs = super().get_outputs()
        for fmi in FMI_LIBRARIES:
            outputs.append(str(Path(self.build_lib, "hierhand", "fmu_binaries", f"fmi{fmi}.so")))
        return outputs


class BuildPy(build_py):
    """build_py that also puts the shipped diagrams (``diagrams/*.yaml``) into the package,
    as ``hierhand/diagrams/``, so that an installed wheel runs ``hierhand reproduce``
    without the repository. An editable install reads the repository's folder itself."""

    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):
            return
        target = Path(self.build_lib) / SHIPPED_DIAGRAMS
        target.mkdir(parents=True, exist_ok=True)
        for diagram in sorted((ROOT / "diagrams").glob("*.yaml")):
            self.copy_file(str(diagram), str(target / diagram.name))

    def get_outputs(self, include_bytecode: bool = True) -> list[str]:
        shipped = [str(Path(self.build_lib) / SHIPPED_DIAGRAMS / p.name) for p in (ROOT / "diagrams").glob("*.yaml")]
        return super().get_outputs(include_bytecode) + shipped


SHIPPED_DIAGRAMS = Path("hierhand", "diagrams")
BLOCKS_CSRC = "blocks/csrc"

setup(
    ext_modules=[
        Extension(
            "blocks._native",
            sources=[f"{BLOCKS_CSRC}/{name}.c"
                     for name in ("host", "core", "library", "lib_math", "lib_dynamic", "lib_sources", "fmu", "fmu_me",
                                  "fmu_host")],
            depends=[f"{BLOCKS_CSRC}/{name}.h" for name in ("blocks_kernel", "core", "library", "lib_common", "fmu",
                                                             "fmu_me", "fmu_calls", "fmu_host")],
            extra_compile_args=CFLAGS + ["-std=c11"],
            libraries=["m"],
        ),
        Extension(
            "hierhand._native",
            sources=EXTENSION_SOURCES,
            depends=EXTENSION_DEPENDS,
            define_macros=[("HH_SOURCES_DIGEST", f'"{sources_digest(ROOT)}"')],
            include_dirs=[BLOCKS_CSRC],
            extra_compile_args=CFLAGS + ["-std=c11"],
            libraries=["m"],
        )
    ],
    cmdclass={"build_ext": BuildNative, "build_py": BuildPy},
)
