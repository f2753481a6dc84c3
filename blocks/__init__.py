"""blocks: discrete-time blocks with their own sample periods, wired in YAML, run exactly.

The public API: ``load_diagram`` / ``loads_diagram`` (YAML -> Diagram), ``DiagramBuilder``
(a Diagram made in Python; ``read_builder`` reads one from a file, to use as a subsystem),
``save_diagram`` / ``dump_diagram`` (Diagram -> YAML), ``simulate`` (Diagram -> Results),
``Results.load``, and the ``Block`` base class for new block types.
"""

import importlib

TYPE_CHECKING = False  # typing's constant, without importing typing (a command line starts here)

if TYPE_CHECKING:  # what type checkers and IDEs see; at run time the names come from __getattr__
    from .block import Block, BlockError, EndRun, ParameterError
    from .builder.diagram import Diagram
    from .builder.diagram_builder import DiagramBuilder
    from .diagram_file.load import load_diagram, loads_diagram
    from .diagram_file.reader import read_builder
    from .diagram_file.writer import WriteError, dump_diagram, save_diagram
    from .engine.schedule import Schedule, build_schedule
    from .engine.simulate import SimulationError, simulate
    from .issues import DiagramError, Issue
    from .process.stop import StopRequest
    from .results.signals import Results, ResultsError
    from .timebase import parse_duration

from blocks.builder.params_reader import use_params_reader as _use_params_reader

_EXPORTS = {
    ".block": ("Block", "BlockError", "EndRun", "ParameterError"),
    ".builder.diagram_builder": ("DiagramBuilder",),
    ".builder.diagram": ("Diagram",),
    ".issues": ("DiagramError", "Issue"),
    ".diagram_file.load": ("load_diagram", "loads_diagram"),
    ".diagram_file.reader": ("read_builder",),
    ".results.signals": ("Results", "ResultsError"),
    ".engine.schedule": ("Schedule", "build_schedule"),
    ".engine.simulate": ("SimulationError", "simulate"),
    ".process.stop": ("StopRequest",),
    ".timebase": ("parse_duration",),
    ".diagram_file.writer": ("WriteError", "dump_diagram", "save_diagram"),
}
"""Where each public name lives. They are imported when first used (PEP 562), so that
importing a light part of the package (``blocks.process.stop``, which a command line installs its
signal handlers from before anything else) does not import numpy and the rest."""

_HOME = {name: module for module, names in _EXPORTS.items() for name in names}

__all__ = sorted(_HOME)


def _read_params_file(path):
    """A params file read as the diagram file reads one (YAML): the reader of the builders
    made in Python. It is given here, at the package's root, since the builder knows no
    file format and its front ends are a layer above it."""
    from blocks.diagram_file.params_file import read_params_file

    return read_params_file(path)


_use_params_reader(_read_params_file)


def __getattr__(name: str) -> object:
    module = _HOME.get(name)
    if module is None:
        raise AttributeError(f"module 'blocks' has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_HOME))
