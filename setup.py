"""Build the C code: the two Python extensions and the FMI 2 / FMI 3 binaries of exported FMUs.

Metadata lives in pyproject.toml; this file only declares what is compiled, because
setuptools' extension support is the build path every pip and every Python install
already has (no CMake, no code generator), and copies the shipped diagrams into the
package (``hierhand/diagrams/``), which package data cannot reach from outside it. The framework's extension ``blocks._native``
is the CPython module (``native_module.c``, ``native_run*.c``) of the op-table interpreter
(``core.c``, plain C99 that needs no Python), with the library's and the FMU block's kernels (``blocks/csrc``); the
hand's, ``hierhand._native``, binds its C core, with Python's stable ABI only (``Py_LIMITED_API``
3.11: one ``_native.abi3.so`` for every Python >= 3.11). ``blocks._native`` cannot be: its
run releases the GIL only while no other thread could take it, which it learns by walking the
interpreter's thread states (``PyInterpreterState_ThreadHead``, ``PyThreadState_Next``) and
``_PyOS_IsMainThread``, and it calls Python blocks by vectorcall (limited API from 3.12 only),
so the wheel keeps its version tag. Besides the extensions the build links
plain shared libraries that an FMU export copies into FMUs, so exporting needs no
compiler: ``blocks/fmu_binaries/fmi2.so`` and ``fmi3.so`` (the op-table core, the
library's kernels and an FMI wrapper: any diagram of library blocks) and
``hierhand/fmu_binaries/fmi2.so`` and ``fmi3.so`` (the same with the hand's kernels). They
link libc and libm only, with no RUNPATH and the maths symbols at the oldest glibc
versions (``blocks/csrc/glibc_compat.h``: portable across Linux distributions); their FMI
headers are the standard's, carried in ``blocks/csrc/fmi`` (BSD-2-Clause, see LICENSE). The
file lists are ``blocks/engine/native_sources.py``
and ``hierhand/native_sources.py``, which the exporter reads for an FMU's ``sources/``.

An editable install, and a wheel built from the tree (``pip wheel .``), build in fresh
temporary folders, where distutils' up-to-date check never finds a previous build, so every
reinstall (``pip install -e ".[test]"`` after ``pip install -e .``) and every wheel would
compile everything again; ``BuildNative`` therefore reuses the extensions and FMU binaries
that an editable or in-place build left in the tree when they are newer than every input of
the build (``BUILD_INPUTS``), and compiles otherwise (a source distribution carries no
builds, so a wheel built from one always compiles).
"""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py
from setuptools.modified import newer_group

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


BUILD_INPUTS = sorted(str(path) for folder in (framework.CSRC, hand.CSRC) for path in (ROOT / folder).rglob("*")
                      if path.suffix in (".c", ".h")) + [__file__, framework.__file__, hand.__file__]
"""Everything a compiled file of the build depends on: every C file and header of both C
trees, this file (flags, macros) and the source lists."""


class BuildNative(build_ext):
    """build_ext that also links the FMU binaries next to the extensions, and reuses what an
    earlier editable or in-place build left in the tree while it is current."""

    def run(self) -> None:
        super().run()
        if self._in_tree():
            self._remove_shadowing_builds()
        for package, versions in FMU_BINARIES.items():
            for fmi, files in versions.items():
                self._link_fmu_binary(package, fmi, files)

    def _remove_shadowing_builds(self) -> None:
        """Remove the tree's other builds of each extension (``_native.cpython-311-...so`` beside
        ``_native.abi3.so``): Python would import a version-specific one first, however old."""
        build_py = self.get_finalized_command("build_py")
        for ext in self.extensions:
            current = ROOT / self._get_inplace_equivalent(build_py, ext)[0]
            for other in current.parent.glob(ext.name.rpartition(".")[2] + ".*.so"):
                if other != current:
                    other.unlink()

    def get_ext_fullpath(self, ext_name: str) -> str:
        """distutils names the file by the extension's last name part only, which setuptools
        maps to the last extension of that short name (both are ``_native``, only one abi3):
        the file name here comes from the full name."""
        path = super().get_ext_fullpath(ext_name)
        return os.path.join(os.path.dirname(path), os.path.basename(self.get_ext_filename(self.get_ext_fullname(ext_name))))

    def _in_tree(self) -> bool:
        return self.inplace or getattr(self, "editable_mode", False)

    def _current(self, in_tree: Path) -> bool:
        """Whether ``in_tree``, left by an earlier editable or in-place build, is newer than
        every input of the build, so that copying it is the same as compiling it again."""
        return not self.force and in_tree.is_file() and not newer_group(BUILD_INPUTS, str(in_tree))

    def build_extension(self, ext: Extension) -> None:
        in_tree = ROOT / self._get_inplace_equivalent(self.get_finalized_command("build_py"), ext)[0]
        if not self._current(in_tree):
            super().build_extension(ext)
            return
        target = self.get_ext_fullpath(ext.name)
        self.mkpath(os.path.dirname(target))
        self.copy_file(str(in_tree), target)

    def _link_fmu_binary(self, package: str, fmi: int, files: list[str]) -> None:
        relative = Path(package, "fmu_binaries", f"fmi{fmi}.so")
        targets = [Path(self.build_lib) / relative]
        if self._current(ROOT / relative):
            self.mkpath(str(targets[0].parent))
            self.copy_file(str(ROOT / relative), str(targets[0]))
            return
        if self._in_tree():
            targets.append(ROOT / relative)
        objects = self.compiler.compile(
            [f for f in files if f.endswith(".c")],
            output_dir=os.path.join(self.build_temp, package, f"fmi{fmi}"),
            include_dirs=[framework.FMI_HEADERS, framework.CSRC, hand.CSRC],
            depends=[f for f in files if f.endswith(".h")],
            # no debug info in what FMUs carry; the maths bound to the oldest glibc that has it
            extra_postargs=framework.CFLAGS + ["-std=c99", "-g0", "-include", str(ROOT / framework.CSRC / "glibc_compat.h")],
        )
        linker = self.compiler.linker_so
        # no RUNPATH: Python's link flags name its own library folder, which an FMU neither
        # needs (it links libc and libm only) nor should carry to another machine
        self.compiler.linker_so = [a for a in linker if not a.startswith(("-Wl,-rpath", "-Wl,-R"))]
        try:
            for target in targets:
                target.parent.mkdir(parents=True, exist_ok=True)
                self.compiler.link_shared_object(objects, str(target), libraries=["m"], extra_postargs=["-s"])
        finally:
            self.compiler.linker_so = linker

    def get_outputs(self) -> list[str]:
        outputs = super().get_outputs()
        for package, versions in FMU_BINARIES.items():
            for fmi in versions:
                outputs.append(str(Path(self.build_lib, package, "fmu_binaries", f"fmi{fmi}.so")))
        return outputs


class BuildPy(build_py):
    """build_py that also puts the shipped diagrams (``diagrams/*.yaml``, with their schema) into the package,
    as ``hierhand/diagrams/``, so that an installed wheel runs ``hierhand reproduce``
    without the repository. An editable install reads the repository's folder itself."""

    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):
            return
        target = Path(self.build_lib) / SHIPPED_DIAGRAMS
        target.mkdir(parents=True, exist_ok=True)
        for diagram in shipped_files():
            self.copy_file(str(diagram), str(target / diagram.name))

    def get_outputs(self, include_bytecode: bool = True) -> list[str]:
        shipped = [str(Path(self.build_lib) / SHIPPED_DIAGRAMS / p.name) for p in shipped_files()]
        return super().get_outputs(include_bytecode) + shipped


SHIPPED_DIAGRAMS = Path("hierhand", "diagrams")


def shipped_files() -> list[Path]:
    """The shipped diagrams and the diagram file's JSON Schema that their first lines name."""
    return sorted([*(ROOT / "diagrams").glob("*.yaml"), ROOT / "diagrams" / "diagram.schema.json"])


setup(
    ext_modules=[
        Extension(
            "blocks._native",
            sources=framework.EXTENSION_SOURCES,
            depends=framework.EXTENSION_DEPENDS,
            extra_compile_args=framework.CFLAGS + ["-std=c11"],
            libraries=["m"],
        ),
        Extension(  # the stable ABI of Python 3.11 (hierhand/csrc/python/py_common.h): one build for every Python >= 3.11
            "hierhand._native",
            sources=hand.EXTENSION_SOURCES,
            depends=hand.EXTENSION_DEPENDS,
            py_limited_api=True,
            define_macros=[("Py_LIMITED_API", "0x030B0000"), ("HH_SOURCES_DIGEST", f'"{hand.sources_digest(ROOT)}"')],
            include_dirs=[framework.CSRC],
            extra_compile_args=framework.CFLAGS + ["-std=c11"],
            libraries=["m"],
        )
    ],
    cmdclass={"build_ext": BuildNative, "build_py": BuildPy},
)
