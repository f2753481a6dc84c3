"""SSP (System Structure and Parameterization, Modelica Association): systems of FMUs both ways.

``read_ssp`` reads an SSP (a ``.ssp`` zip archive or a folder with ``SystemStructure.ssd``)
of co-simulation (or model-exchange) FMUs into a ``DiagramBuilder`` (``reader``), which
``blocks.load_diagram`` builds like any diagram; ``export_ssp`` writes a diagram as an SSP
whose components are FMUs (``writer``; ``components``: a block or subsystem as the diagram
its FMU is exported from). Modules: ``package`` (the archive or folder, its files), ``xml``
(namespaces, safe parsing), ``parameters`` (bindings, ``.ssv``, ``.ssm``), ``connections``
(an SSD's connections as wires, conversions and held top-level inputs), ``conversion``
(units read: their definitions and conversions), ``steps`` (the step-size annotations of
libcosim and OMSimulator, and blocks' own stepping one), ``units`` (``ssd:Units`` from the
FMUs, for export).
"""

import importlib
from typing import Any

_HOME = {"SSD_NAME": ".names", "is_ssp": ".names", "read_ssp": ".reader", "export_ssp": ".writer"}
"""Where each public name lives, imported when first used (PEP 562): ``blocks.ssp.names``
alone is what every diagram load needs."""

__all__ = sorted(_HOME)


def __getattr__(name: str) -> Any:
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_HOME[name], __name__), name)
    globals()[name] = value
    return value
