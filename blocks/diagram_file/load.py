"""``load_diagram`` / ``loads_diagram``: a diagram file read, validated and planned.

The YAML front end (``blocks.diagram_file.reader``) reads the file into a ``DiagramBuilder``, whose
``build`` checks everything (the planner's checks too: algebraic loops, incommensurate
periods, an end time that is not a whole number of base ticks). A diagram that loads
can therefore run, and the plan made here is kept by the planner, so the first
``simulate`` to the diagram's own end time does not plan again.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

from blocks.builder.diagram import Diagram
from blocks.diagram_file.reader import parse_builder, read_builder
from blocks.ssp.names import is_ssp


def load_diagram(path: str | Path, overrides: Mapping[str, Any] | None = None,
                 trust: bool = False, origins: Mapping[str, str] | None = None,
                 files: Mapping[str, str | Path] | None = None, step: Any = None) -> Diagram:
    """Load and validate a diagram file (YAML, or an SSP: ``blocks.ssp``); ``overrides`` maps ``block.param[.key]`` to a value
    (inside a subsystem ``ctrl.block.param``).

    ``origins`` says how the user gave an override, for the messages about it: by key, the
    text that stands where a file name would (``--grid plant.k=1,2``); by default
    ``--set block.param=value``. ``trust`` allows ``python:`` block types, and params files
    and subsystem diagrams outside the diagram's folder. ``files`` says where to read the
    files the diagram names, by the reference it makes (the keys of ``Diagram.files``;
    ``"."``: the folder where ``python:`` modules are looked for): a diagram whose files
    were copied elsewhere reads the copies, while its parameters and messages still name
    the paths it gives. ``step``: for an SSP, the communication step of the components
    its SSD gives none.
    """
    if is_ssp(path):
        from blocks.ssp.reader import read_ssp

        return read_ssp(path, trust=trust, step=step).build(overrides, origins=origins)
    if step is not None:
        from blocks.issues import DiagramError, Issue

        raise DiagramError([Issue(str(path), None, "a step (--step) is for the components of an SSP",
                                  "a YAML diagram gives each block its period")])
    return read_builder(path, trust=trust, files=files).build(overrides, origins=origins)


def loads_diagram(text: str, filename: str = "<diagram>", base_dir: str | Path | None = None,
                  overrides: Mapping[str, Any] | None = None, trust: bool = False,
                  origins: Mapping[str, str] | None = None,
                  files: Mapping[str, str | Path] | None = None) -> Diagram:
    """Load and validate a diagram from YAML text (``base_dir`` resolves its relative
    paths; ``files`` as for ``load_diagram``)."""
    return parse_builder(text, filename=filename, base_dir=base_dir, trust=trust, files=files).build(
        overrides, origins=origins)
