"""Build the C code: the two Python extensions and the FMI 2 / FMI 3 binaries of exported FMUs.

Metadata lives in pyproject.toml; this file only declares what is compiled, because
setuptools' extension support is the build path every pip and every Python install
already has (no CMake, no code generator), and copies the shipped diagrams into the
package (``hierhand/diagrams/``), which package data cannot reach from outside it. The framework's extension ``blocks._native``
is the CPython host (``host.c``) of the op-table interpreter (``core.c``, plain C99 that
needs no Python), with the library's and the FMU block's kernels (``blocks/csrc``); the
hand's, ``hierhand._native``, binds its C core. Besides the extensions the build links
plain shared libraries that an FMU export copies into FMUs, so exporting needs no
compiler: ``blocks/fmu_binaries/fmi2.so`` and ``fmi3.so`` (the op-table core, the
library's kernels and an FMI wrapper: any diagram of library blocks) and
``hierhand/fmu_binaries/fmi2.so`` and ``fmi3.so`` (the same with the hand's kernels). They
link libc and libm only; their FMI headers come from fmpy (a build requirement), the
headers an importer builds against too. The file lists are ``blocks/engine/native_sources.py``
and ``hierhand/native_sources.py``, which the exporter reads for an FMU's ``sources/``.
"""

from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py

# after setuptools, which makes these its own copy of distutils (Python 3.12 has none)
from distutils.ccompiler import new_compiler  # noqa: E402
from distutils.command.build_scripts import build_scripts  # noqa: E402
from distutils.sysconfig import customize_compiler  # noqa: E402

ROOT = Path(__file__).resolve().parent


def _module(name: str, path: Path):
    """A source-list module read from its file, before any package is importable."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


framework = _module("blocks_native_sources", ROOT / "blocks" / "engine" / "native_sources.py")
hand = _module("hierhand_native_sources", ROOT / "hierhand" / "native_sources.py")

FMU_BINARIES = {
    package: {fmi: sources for fmi in framework.FMI_WRAPPERS
              for sources in [framework.fmu_sources(fmi) + [f"{framework.CSRC}/{framework.KERNEL_SET}"]
                              if package == "blocks" else hand.fmu_sources(framework.fmu_sources(fmi))]}
    for package in ("blocks", "hierhand")
}
"""Per package and FMI version, every file of its FMU binary (C files and headers)."""


class BuildNative(build_ext):
    """build_ext that also links the FMU binaries next to the extensions."""

    def run(self) -> None:
        super().run()
        for package, versions in FMU_BINARIES.items():
            for fmi, files in versions.items():
                self._link_fmu_binary(package, fmi, files)

    def _link_fmu_binary(self, package: str, fmi: int, files: list[str]) -> None:
        relative = Path(package, "fmu_binaries", f"fmi{fmi}.so")
        targets = [Path(self.build_lib) / relative]
        if self.inplace or getattr(self, "editable_mode", False):
            targets.append(ROOT / relative)
        objects = self.compiler.compile(
            [f for f in files if f.endswith(".c")],
            output_dir=os.path.join(self.build_temp, package, f"fmi{fmi}"),
            include_dirs=[framework.fmi_headers(), framework.CSRC, hand.CSRC],
            depends=[f for f in files if f.endswith(".h")],
            extra_postargs=framework.CFLAGS + ["-std=c99", "-g0"],  # no debug info in what FMUs carry
        )
        for target in targets:
            target.parent.mkdir(parents=True, exist_ok=True)
            self.compiler.link_shared_object(objects, str(target), libraries=["m"], extra_postargs=["-s"])

    def get_outputs(self) -> list[str]:
        outputs = super().get_outputs()
        for package, versions in FMU_BINARIES.items():
            for fmi in versions:
                outputs.append(str(Path(self.build_lib, package, "fmu_binaries", f"fmi{fmi}.so")))
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

COMMANDS = {"hierhand": "hierhand.start:main"}
"""Each command (an executable in bin/) and its entry function."""

LAUNCHER = f"{framework.CSRC}/{framework.LAUNCHER}"


class BuildCommands(build_scripts):
    """build_scripts that compiles each command of ``COMMANDS`` from the launcher, with the
    interpreter running this build as the one it falls back to. The distribution's scripts
    are the launcher's source, so that every install runs this command and puts what it
    builds into bin/."""

    def run(self) -> None:
        compiler = new_compiler()
        customize_compiler(compiler)
        build_temp = self.get_finalized_command("build").build_temp
        for program, entry in COMMANDS.items():
            macros = framework.launcher_macros(program, entry, sys.executable,
                                               hint=f"python3 -m {program} runs the same command")
            objects = compiler.compile([LAUNCHER], output_dir=os.path.join(build_temp, "commands", program),
                                       macros=macros,
                                       extra_postargs=framework.CFLAGS + ["-std=c99", "-Wextra", "-g0"])
            compiler.link_executable(objects, program, output_dir=self.build_dir, extra_postargs=["-s"])

    def get_source_files(self) -> list[str]:
        return [LAUNCHER]

    def get_outputs(self) -> list[str]:
        return [os.path.join(self.build_dir, program) for program in COMMANDS]


setup(
    ext_modules=[
        Extension(
            "blocks._native",
            sources=framework.EXTENSION_SOURCES,
            depends=framework.EXTENSION_DEPENDS,
            extra_compile_args=framework.CFLAGS + ["-std=c11"],
            libraries=["m"],
        ),
        Extension(
            "hierhand._native",
            sources=hand.EXTENSION_SOURCES,
            depends=hand.EXTENSION_DEPENDS,
            define_macros=[("HH_SOURCES_DIGEST", f'"{hand.sources_digest(ROOT)}"')],
            include_dirs=[framework.CSRC],
            extra_compile_args=framework.CFLAGS + ["-std=c11"],
            libraries=["m"],
        )
    ],
    scripts=[LAUNCHER],
    cmdclass={"build_ext": BuildNative, "build_py": BuildPy, "build_scripts": BuildCommands},
)
