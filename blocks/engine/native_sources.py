"""The framework's C sources and what is built from them (read by setup.py too).

One list, so that the extension ``blocks._native``, the FMU binaries built at install
and the ``sources/`` folder of an exported diagram FMU always hold the same files. Paths
are relative to the repository root (``CSRC``). This module imports nothing of the
package, so that setup.py can read it before anything is built.

An exported FMU's binary is the op-table core, the library's kernels, the FMU instance
and one FMI wrapper, plus a kernel-set file that lists the kernel types the binary holds
(``library_kernel_set.c`` for the library alone; an application lists its own beside it).
"""

from __future__ import annotations

CSRC = "blocks/csrc"

CORE = ["core.c"]
CORE_HEADERS = ["core.h", "blocks_kernel.h"]
LIBRARY = ["library.c", "lib_math.c", "lib_dynamic.c", "lib_sources.c"]
LIBRARY_HEADERS = ["library.h", "lib_common.h"]
EXTENSION = ["native_module.c", "native_run.c", "native_run_bind.c", "native_run_hooks.c", "native_python_blocks.c",
             "native_kernel_call.c", "layout_names.c", "fmu_block_step.c", "fmu_me_integration.c", "fmu_channel.c"]
"""The extension's own files: the module, its Run type and single kernel calls, and the
FMU block's compiled step, model-exchange loops and channel to an isolated FMU."""
EXTENSION_HEADERS = ["native_run.h", "native_kernel_call.h", "layout_names.h", "fmu_block_step.h",
                     "fmu_me_integration.h", "fmu_channel.h", "fmu_step_table.h", "fmi_step_calls.h"]
EXPORT = ["export_log.c", "export_resources.c", "export_step.c", "export_build.c", "export_lifecycle.c",
          "export_variables.c", "export_snapshot.c", "export_scheduled.c"]
"""An exported FMU's instance, one concern a file (export_internal.h lists them)."""
EXPORT_HEADERS = ["export_instance.h", "export_internal.h", "export_scheduled.h"]
FMI_WRAPPERS = {2: "export_fmi2.c", 3: "export_fmi3.c"}
KERNEL_SET = "library_kernel_set.c"
"""The kernel-set file of a binary holding the library's kernel types only."""

FMI_HEADERS = f"{CSRC}/fmi"
"""The FMI 2.0 and 3.0 standard's headers, unmodified (BSD-2-Clause, see LICENSE), which the FMU
binaries and the tests' FMUs and C hosts are built against."""

CFLAGS = ["-O2", "-fvisibility=hidden", "-fno-math-errno", "-ffp-contract=off", "-Wall"]
"""-ffp-contract=off: no fused multiply-adds, so every build rounds as the reference does."""


def paths(names: list[str], folder: str = CSRC) -> list[str]:
    return [f"{folder}/{name}" for name in names]


EXTENSION_SOURCES = paths(EXTENSION + CORE + LIBRARY)
EXTENSION_DEPENDS = paths(CORE_HEADERS + LIBRARY_HEADERS + EXTENSION_HEADERS + EXPORT_HEADERS)


def fmu_sources(fmi: int) -> list[str]:
    """The framework's files (repository paths) in every exported FMU of FMI ``fmi``, its
    kernel-set file excepted: C files first, then headers."""
    return paths(CORE + LIBRARY + EXPORT + [FMI_WRAPPERS[fmi]] + CORE_HEADERS + LIBRARY_HEADERS + EXPORT_HEADERS)
