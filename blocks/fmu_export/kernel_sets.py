"""The binaries an export can use: sets of kernel types, each built at install for FMI 2 and 3.

An exported FMU's binary is the op-table core, the FMI wrapper and the kernel types of the
diagram's blocks (``blocks/csrc/export_instance.h``). A ``KernelSet`` is one such build:
the kinds it holds, its binary per FMI version (linked when the package was installed, so
exporting needs no compiler) and the C files it was built from, which the FMU carries in
``sources/``. The framework's set holds the library; an application registers its own
(its kernel types beside the library's) under the entry-point group
``blocks.fmu_kernel_sets``. An export takes the smallest set that holds every kind its
diagram needs.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from blocks.engine import native_sources
from ..plugins import load_group

GROUP = "blocks.fmu_kernel_sets"


class FmuExportError(RuntimeError):
    """The FMU cannot be built (the install has no FMU binary, a diagram's kinds are in none)."""


@dataclass(frozen=True)
class KernelSet:
    """One FMU binary build: ``kinds`` (kernel type names), ``binary(fmi)`` (the library
    built at install), ``sources(fmi)`` (the files it was built from: C files, then
    headers, copied flat into an FMU's ``sources/``)."""

    name: str
    kinds: frozenset[str]
    binary: Callable[[int], Path]
    sources: Callable[[int], list[Path]]


def installed_binary(package_dir: Path, fmi: int, package: str) -> Path:
    """``package_dir/fmu_binaries/fmi<N>.so``, or FmuExportError saying how to get it."""
    path = package_dir / "fmu_binaries" / f"fmi{fmi}.so"
    if not path.is_file():
        raise FmuExportError(f"{path} is missing: {package} was installed without its FMU binaries "
                             "(hint: reinstall with 'pip install .' or 'pip install -e .' and a C compiler)")
    return path


_ROOT = Path(__file__).resolve().parents[2]
"""The folder holding the packages (the repository, or site-packages): native_sources'
paths are relative to it."""


def library_set() -> KernelSet:
    """The framework's set: every library kernel."""
    from ..library._kernels import functions

    kinds = frozenset(name.rsplit("_", 1)[0] for name in functions())
    files = lambda fmi: [_ROOT / p for p in native_sources.fmu_sources(fmi)  # noqa: E731 - short and local
                         + [f"{native_sources.CSRC}/{native_sources.KERNEL_SET}"]]
    return KernelSet("blocks", kinds, lambda fmi: installed_binary(_ROOT / "blocks", fmi, "blocks"), files)


def kernel_sets() -> list[KernelSet]:
    """Every set: the library's and those registered by installed packages, smallest first."""
    found, _ = load_group(GROUP, lambda obj: None if callable(obj) else "is not callable")
    sets = [library_set()]
    for make in found.values():
        made = make()
        if isinstance(made, KernelSet):
            sets.append(made)
    return sorted(sets, key=lambda k: len(k.kinds))


def set_for(kinds: set[str]) -> KernelSet:
    """The smallest set holding every kind in ``kinds``; FmuExportError naming those no set holds."""
    sets = kernel_sets()
    for candidate in sets:
        if kinds <= candidate.kinds:
            return candidate
    everything = set().union(*(k.kinds for k in sets))
    missing = sorted(kinds - everything) or sorted(kinds)
    raise FmuExportError(f"no installed FMU binary holds the kernel type(s) {', '.join(missing)} "
                         f"(sets: {', '.join(k.name for k in sets)})")
