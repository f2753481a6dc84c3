"""blocks: discrete-time blocks with their own sample periods, wired in YAML, run exactly.

The public API: ``load_diagram`` / ``loads_diagram`` (YAML -> Diagram), ``simulate``
(Diagram -> Results), ``Results.load``, and the ``Block`` base class for new block types.
"""

from .block import Block, BlockError, EndRun, ParameterError
from .diagram import Diagram
from .issues import DiagramError, Issue
from .load import load_diagram, loads_diagram
from .results import Results, ResultsError
from .schedule import Schedule, build_schedule
from .simulate import SimulationError, StopRequest, simulate
from .timebase import parse_duration

__all__ = [
    "Block", "BlockError", "Diagram", "DiagramError", "EndRun", "Issue", "ParameterError", "Results",
    "ResultsError", "Schedule", "SimulationError", "StopRequest", "build_schedule", "load_diagram",
    "loads_diagram", "parse_duration", "simulate",
]
