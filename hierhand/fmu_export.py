"""Export hand diagrams as native FMUs: any diagram of library and hand blocks, or the plant alone.

The framework's exporter (``blocks.fmu_export``) packages a diagram whose blocks all have
compiled kernels; hierhand contributes the binary that holds the hand's kernel types
beside the library's (``kernel_set``, registered under the entry-point group
``blocks.fmu_kernel_sets``), linked when hierhand was installed, so the hierarchical
controller, the plant or the whole closed loop leave as FMUs that run without Python.

The plant-only export (``export_plant_fmu``, ``hierhand fmu export --hand ...``) is the
same path for a diagram of one ``HandPlant`` at 0.1 ms: its inputs ``tau`` and ``f_ext``,
its outputs every plant output port, its parameters the hand file's numbers under their
own names (``object.mass``, ``fingers[2].links[1].length``), the object's inertia
following its mass and size as in a diagram unless the hand file gives it.
"""

from __future__ import annotations

from pathlib import Path

import hierhand
from blocks import Diagram, DiagramBuilder
from blocks.engine import native_sources as framework_sources
from blocks.fmu_export import FmuExportError, KernelSet, export_fmu, installed_binary

from . import _native, native_sources

FMU_DIR = Path("fmu")
"""Where exports go by default: ``fmu/`` under the current folder, like ``runs/`` for results."""

PLANT_PERIOD = "0.1 ms"
PLANT_STEP = "1 ms"
"""The plant-only export's internal step and default communication step."""

FMI_VERSIONS = (2, 3)
PACKAGE_DIR = Path(hierhand.__file__).resolve().parent
ROOT = PACKAGE_DIR.parent
"""The folder holding the packages: the source lists' paths are relative to it."""

__all__ = ["FmuExportError", "default_output_path", "export_diagram_fmu", "export_plant_fmu", "kernel_set",
           "plant_diagram"]


def kernel_set() -> KernelSet:
    """hierhand's FMU binary: the library's kernel types and the hand's (kernel_types.h)."""
    from blocks.fmu_export.kernel_sets import library_set

    hand = frozenset(name.split(".", 1)[0] for name in _native.kernels())
    return KernelSet("hierhand", library_set().kinds | hand,
                     lambda fmi: installed_binary(PACKAGE_DIR, fmi, "hierhand"),
                     lambda fmi: [ROOT / p for p in native_sources.fmu_sources(framework_sources.fmu_sources(fmi))])


def export_diagram_fmu(diagram: Diagram, out: Path | None = None, fmi: int = 2, **options) -> Path:
    """Write ``diagram`` as an FMU (default path ``fmu/<name>_fmi<N>.fmu``, ``..._se.fmu`` for
    scheduled execution) and return its path; ``options`` go to
    ``blocks.fmu_export.export_fmu`` (``model``, ``step``, ``scheduled``)."""
    name = f"{diagram.name}_fmi{fmi}{'_se' if options.get('scheduled') else ''}.fmu"
    return export_fmu(diagram, _output_path(out, name), fmi, kernel_set=kernel_set(), **options)


def plant_diagram(hand: Path | None = None) -> Diagram:
    """The one-block diagram of the plant export: a ``HandPlant`` of ``hand`` (a hand file;
    default: the shipped hand, as a diagram's plant without parameters) at 0.1 ms, with
    inputs ``tau``, ``f_ext`` and every output port as an output. HandFileError for an
    invalid hand file."""
    from .model import HandPlant, load_hand
    from .model.handfile import SECTIONS, read_hand_file

    sections = {}
    if hand is not None:
        load_hand(hand)  # every problem of the file, at its lines
        raw = read_hand_file(hand)
        sections = {key: raw.get(key) for key in SECTIONS}
    b = DiagramBuilder("HandPlant", "hierhand HandPlant: three-fingered planar hand grasping a square object, "
                                    "penalty contact")
    plant = HandPlant(**sections)
    b.add("plant", plant, period=PLANT_PERIOD)
    b.input("tau", "plant.tau")
    b.input("f_ext", "plant.f_ext")
    for port in plant.outputs:
        b.output(port, f"plant.{port}")
    return b.build()


def export_plant_fmu(out: Path | None = None, fmi: int = 2, hand: Path | None = None) -> Path:
    """Write the hand plant FMU and return its path.

    ``out``: a ``.fmu`` file, or a folder to put ``HandPlant_fmi<N>.fmu`` in (default
    ``fmu/HandPlant_fmi<N>.fmu`` under the current folder); ``fmi``: 2 or 3; ``hand``: a
    hand file whose values become the parameters' start values (default: the shipped
    hand). Raises ``HandFileError`` for an invalid hand file and ``FmuExportError`` when
    the FMU cannot be built.
    """
    if fmi not in FMI_VERSIONS:
        raise ValueError(f"fmi must be 2 or 3, got {fmi!r}")
    return export_fmu(plant_diagram(hand), _output_path(out, default_output_path(fmi).name), fmi,
                      model="HandPlant", step=PLANT_STEP, kernel_set=kernel_set())


def default_output_path(fmi: int) -> Path:
    return FMU_DIR / f"HandPlant_fmi{fmi}.fmu"


def _output_path(out: Path | None, name: str) -> Path:
    if out is None:
        return FMU_DIR / name
    out = Path(out)
    return out if out.suffix.lower() == ".fmu" else out / name
