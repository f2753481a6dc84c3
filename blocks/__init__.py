"""blocks: discrete-time blocks with their own sample periods, wired in YAML, run exactly.

The public API: ``load_diagram`` / ``loads_diagram`` (YAML -> Diagram), ``DiagramBuilder``
(a Diagram made in Python; ``read_builder`` reads one from a file, to use as a subsystem),
``save_diagram`` / ``dump_diagram`` (Diagram -> YAML), ``simulate`` (Diagram -> Results),
``Results.load``, and the ``Block`` base class for new block types.
"""

from .block import Block, BlockError, EndRun, ParameterError
from .builder import DiagramBuilder
from .diagram import Diagram
from .issues import DiagramError, Issue
from .load import load_diagram, loads_diagram
from .loader import read_builder
from .results import Results, ResultsError
from .schedule import Schedule, build_schedule
from .simulate import SimulationError, StopRequest, simulate
from .timebase import parse_duration
from .yamlwriter import WriteError, dump_diagram, save_diagram



def _wiring_svg(diagram: Diagram) -> str:
    """Jupyter's view of a Diagram: its wiring graph (``blocks.graph``, a layer above the
    diagram's data, so attached here, where both are known, and imported when first shown)."""
    from .graph import svg_text

    return svg_text(diagram)


Diagram._repr_svg_ = _wiring_svg

__all__ = [
    "Block", "BlockError", "Diagram", "DiagramBuilder", "DiagramError", "EndRun", "Issue", "ParameterError",
    "Results", "ResultsError", "Schedule", "SimulationError", "StopRequest", "WriteError", "build_schedule",
    "dump_diagram", "load_diagram", "loads_diagram", "parse_duration", "read_builder", "save_diagram", "simulate",
]
