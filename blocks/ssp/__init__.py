"""SSP (System Structure and Parameterization, Modelica Association): systems of FMUs both ways.

``read_ssp`` reads an SSP (a ``.ssp`` zip archive or a folder with ``SystemStructure.ssd``)
of co-simulation (or model-exchange) FMUs into a ``DiagramBuilder`` (``reader``), which
``blocks.load_diagram`` builds like any diagram; ``export_ssp`` writes a diagram as an SSP
whose components are FMUs (``writer``). Modules: ``package`` (the archive or folder, its
files), ``xml`` (namespaces, safe parsing), ``parameters`` (bindings, ``.ssv``, ``.ssm``),
``steps`` (the step-size annotations of libcosim and OMSimulator).
"""

from .package import SSD_NAME, is_ssp
from .reader import read_ssp
from .writer import export_ssp

__all__ = ["SSD_NAME", "export_ssp", "is_ssp", "read_ssp"]
