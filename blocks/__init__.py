"""blocks: discrete-time blocks with their own sample periods, wired in YAML, run exactly.

The public API: ``load_diagram`` / ``loads_diagram`` (YAML -> Diagram), ``DiagramBuilder``
(a Diagram made in Python; ``read_builder`` reads one from a file, to use as a subsystem),
``save_diagram`` / ``dump_diagram`` (Diagram -> YAML), ``simulate`` (Diagram -> Results),
``Results.load``, and the ``Block`` base class for new block types.
"""

import importlib
import sys
import types

_EXPORTS = {
    ".block": ("Block", "BlockError", "EndRun", "ParameterError"),
    ".builder": ("DiagramBuilder",),
    ".diagram": ("Diagram",),
    ".issues": ("DiagramError", "Issue"),
    ".load": ("load_diagram", "loads_diagram"),
    ".loader": ("read_builder",),
    ".results": ("Results", "ResultsError"),
    ".schedule": ("Schedule", "build_schedule"),
    ".simulate": ("SimulationError", "simulate"),
    ".stop": ("StopRequest",),
    ".timebase": ("parse_duration",),
    ".yamlwriter": ("WriteError", "dump_diagram", "save_diagram"),
}
"""Where each public name lives. They are imported when first used (PEP 562), so that
importing a light part of the package (``blocks.stop``, which a command line installs its
signal handlers from before anything else) does not import numpy and the rest."""

_HOME = {name: module for module, names in _EXPORTS.items() for name in names}

__all__ = sorted(_HOME)


class _Package(types.ModuleType):
    """The package, whose function ``simulate`` shares its name with its module: importing
    the module ``blocks.simulate`` sets the package's attribute to the module, which would
    hide the function; the function stays."""

    def __setattr__(self, name: str, value: object) -> None:
        if isinstance(value, types.ModuleType) and name in _HOME and hasattr(value, name):
            value = getattr(value, name)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


def __getattr__(name: str) -> object:
    module = _HOME.get(name)
    if module is None:
        raise AttributeError(f"module 'blocks' has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_HOME))
