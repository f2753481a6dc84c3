"""Export a diagram as a native FMI 2.0 or 3.0 co-simulation FMU, or an FMI 3.0
scheduled-execution FMU: ``export_fmu``.

Any diagram whose blocks all have compiled kernels with records (the library's, an
application's) leaves as an FMU whose binary is the op-table core (``blocks/csrc/core.c``)
with the FMI wrapper and the kernel types of its blocks, linked at install: no Python,
numpy or libpython at the importer, and no compiler at export. The FMU's resources hold
the op table and the blocks' records (``resources``); ``sources/`` the C files it was
built from (listed in the modelDescription for FMI 2, in ``buildDescription.xml`` for FMI
3), so an importer can build it for another platform.

The FMU's inputs and outputs are the diagram's own (``variables``); its parameters the
tunables of the blocks' records, checked by the kinds' constructors when the FMU is
initialised (an invalid value is a logged error status); a derived value follows what it
derives from as in a native run. Its internal step is the diagram's base tick (or the
period of the blocks the plan advances in one call); a communication step may be any
length, and one that ends between internal steps holds the last one's outputs (an
importer that steps every FMU at one step runs a multirate export); its samples are those
of a native run of the diagram, to the last bit.

With ``scheduled=True`` (FMI 3) the FMU declares ``<ScheduledExecution>`` instead: one
constant periodic input clock per rate, exact as ``intervalCounter / resolution``, and one
model partition per clock (``partitions``); activated on the tick grid in priority order,
the partitions compute the native run's samples, to the last bit.

Modules: ``kernel_sets`` (the binaries and the kinds they hold), ``plan`` (the op table
and the blocks' records), ``variables`` (the FMU's variables), ``resources`` (the binary
resource file), ``description`` (modelDescription.xml, buildDescription.xml),
``partitions`` (scheduled execution's clocks and partitions).
"""

from __future__ import annotations

import hashlib
import io
import platform
import re
import uuid
import zipfile
from dataclasses import replace
from fractions import Fraction
from pathlib import Path

from blocks.results.atomic_file import write_atomically
from blocks.engine.compiled import native
from blocks.builder.diagram import Diagram
from .description import build_description, model_description
from .kernel_sets import FmuExportError, KernelSet, installed_binary, kernel_sets, set_for
from .partitions import clocks_resource, partitions, variable_clocks
from .plan import Plan, plan_export
from .resources import resource_file
from .variables import Variables, fmu_variables, output_signals
from blocks.builder.api_args import diagram_argument

__all__ = ["FMI_VERSIONS", "FmuExportError", "KernelSet", "export_fmu", "installed_binary", "kernel_sets",
           "model_identifier"]

FMI_VERSIONS = (2, 3)

LOG_DESCRIPTIONS = (
    "instantiation, initialization and other events (when logging is on)",
    "warnings",
    "errors: invalid parameters, refused steps, a block's failure",
)


def export_fmu(diagram: Diagram, out: Path | str, fmi: int = 2, *, model: str | None = None,
               step=None, kernel_set: KernelSet | None = None, scheduled: bool = False) -> Path:
    """Write ``diagram`` as an FMU at ``out`` (a .fmu file) and return its path.

    ``model``: the model's name (default: the diagram's name); ``step``: the default
    communication step (a duration; default: the internal step); ``kernel_set``: the
    binary to use (default: the smallest installed one holding the diagram's kinds);
    ``scheduled``: FMI 3 scheduled execution (its clocks are the diagram's rates, ``step``
    does not apply).
    DiagramError for a diagram that cannot be exported (a block without a compiled
    kernel, a step that is no multiple of the internal step), FmuExportError when the FMU
    cannot be built.
    """
    diagram_argument(diagram)
    if fmi not in FMI_VERSIONS:
        raise ValueError(f"fmi must be 2 or 3, got {fmi!r}")
    if scheduled and (fmi != 3 or step is not None):
        raise ValueError("scheduled execution is FMI 3's, and takes no communication step")
    outputs = {signal.rsplit(".", 1)[0] for _, signal in output_signals(diagram)}
    plan = plan_export(diagram, outputs, step, advance=not scheduled)
    variables = fmu_variables(plan)
    clocks, clocks_file, extra = None, b"", {}
    if scheduled:
        clocks = partitions(plan, variables.vr_param + len(variables.parameters))
        plan = replace(plan, table=clocks.table, step=clocks.clocks[0].period * plan.schedule.base_tick)
        clocks_file = clocks_resource(clocks, plan.schedule.hyperperiod, *native().SCHEDULED_FORMAT)
        extra = {"clocks": clocks, "base_tick": plan.schedule.base_tick,
                 "variable_clocks": variable_clocks(clocks, plan.table, variables.inputs, variables.outputs)}
    chosen = kernel_set or set_for({b.record.kind for b in plan.blocks})
    grid = plan.grid * plan.schedule.base_tick
    model = model or diagram.name
    library = chosen.binary(fmi).read_bytes()
    sources = {path.name: path.read_bytes() for path in chosen.sources(fmi)}
    compiled = [name for name in sources if name.endswith(".c")]
    token_data = resource_file(plan, variables, "", model)
    identifier = model_identifier(model, fmi, token_data + clocks_file, library, sources)
    token = "{" + str(uuid.UUID(hashlib.sha256(identifier.encode()).hexdigest()[:32])) + "}"
    resources = resource_file(plan, variables, token, model)
    described = model_description(
        fmi, identifier, token, model, _description(diagram, grid, scheduled), variables, grid, plan.step,
        diagram.t_end, dict(zip(native().EXPORT_LOG_CATEGORIES, LOG_DESCRIPTIONS)), f"blocks {_version()}", compiled,
        **extra)
    files = {
        "modelDescription.xml": described,
        f"binaries/{_platform_folder(fmi)}/{identifier}.so": library,
        f"resources/{native().EXPORT_RESOURCE}": resources,
        **{f"sources/{name}": data for name, data in sources.items()},
    }
    if scheduled:
        files[f"resources/{native().SCHEDULED_RESOURCE}"] = clocks_file
    if fmi == 3:
        files["sources/buildDescription.xml"] = build_description(identifier, compiled)
    target = Path(out)
    target.parent.mkdir(parents=True, exist_ok=True)
    return write_atomically(target, _zip(files))


def model_identifier(model: str, fmi: int, resources: bytes, library: bytes, sources: dict[str, bytes]) -> str:
    """``<model>_<hash>``: differs whenever the FMU's diagram, parameters, code or FMI
    version do, so FMUs of different diagrams load side by side in one process."""
    h = hashlib.sha256()
    h.update(f"fmi {fmi}\0".encode() + hashlib.sha256(resources).digest() + hashlib.sha256(library).digest())
    for name in sorted(sources):
        h.update(name.encode() + b"\0" + hashlib.sha256(sources[name]).digest())
    stem = re.sub(r"[^A-Za-z0-9_]", "_", model) or "diagram"
    if not (stem[0].isalpha() or stem[0] == "_"):
        stem = "m_" + stem
    return f"{stem}_{h.hexdigest()[:12]}"


def _description(diagram: Diagram, grid: Fraction, scheduled: bool = False) -> str:
    text = diagram.description.strip() if diagram.description else f"the diagram '{diagram.name}'"
    if scheduled:
        return (f"{text} (exported by blocks for scheduled execution: one model partition per rate, activated "
                "on its clock's ticks, the clocks of an instant in priority order)")
    return (f"{text} (exported by blocks: internal step {float(grid):g} s, communication steps are multiples "
            "of it)")


def _version() -> str:
    from importlib import metadata

    for distribution in ("hierhand", "blocks"):
        try:
            return metadata.version(distribution)
        except metadata.PackageNotFoundError:
            continue
    return "unknown"


def _platform_folder(fmi: int) -> str:
    machine = platform.machine().lower()
    if machine in ("x86_64", "amd64"):
        return "linux64" if fmi == 2 else "x86_64-linux"
    if machine in ("aarch64", "arm64"):
        return "aarch64-linux"
    raise FmuExportError(f"no FMI platform name for a Linux {machine} binary")


def _zip(files: dict[str, bytes]) -> bytes:
    """The FMU archive: sorted entries with fixed timestamps, so equal exports are equal bytes."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for name in sorted(files):
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            archive.writestr(info, files[name])
    return buffer.getvalue()
