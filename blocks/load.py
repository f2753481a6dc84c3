"""``load_diagram`` / ``loads_diagram``: a diagram file read, validated and planned.

The loader (``blocks.loader``) checks what the text says by itself; the planner
(``blocks.schedule``) then checks what needs the rates: algebraic loops, incommensurate
periods and an end time that is not a whole number of base ticks. A diagram that loads
can therefore run. The plan made here is kept by the planner, so the first
``simulate`` to the diagram's own end time does not plan again.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping

from .diagram import Diagram
from .loader import parse_diagram, read_diagram
from .schedule import build_schedule


def load_diagram(path: str | Path, overrides: Mapping[str, Any] | None = None,
                 trust: bool = False, origins: Mapping[str, str] | None = None,
                 files: Mapping[str, str | Path] | None = None) -> Diagram:
    """Load and validate a diagram file; ``overrides`` maps ``block.param[.key]`` to a value.

    ``origins`` says how the user gave an override, for the messages about it: by key, the
    text that stands where a file name would (``--grid plant.k=1,2``); by default
    ``--set block.param=value``. ``trust`` allows ``python:`` block types and params files
    outside the diagram's folder. ``files`` says where to read the files the diagram names,
    by the reference it makes (the keys of ``Diagram.files``; ``"."``: the folder where
    ``python:`` modules are looked for): a diagram whose files were copied elsewhere reads
    the copies, while its parameters and messages still name the paths it gives.
    """
    return _planned(read_diagram(path, overrides=overrides, trust=trust, origins=origins, files=files))


def loads_diagram(text: str, filename: str = "<diagram>", base_dir: str | Path | None = None,
                  overrides: Mapping[str, Any] | None = None, trust: bool = False,
                  origins: Mapping[str, str] | None = None,
                  files: Mapping[str, str | Path] | None = None) -> Diagram:
    """Load and validate a diagram from YAML text (``base_dir`` resolves ``params_file``;
    ``files`` as for ``load_diagram``)."""
    return _planned(parse_diagram(text, filename=filename, base_dir=base_dir, overrides=overrides,
                                  trust=trust, origins=origins, files=files))


def _planned(diagram: Diagram) -> Diagram:
    """``diagram``, once the planner has accepted it up to its own end time."""
    build_schedule(diagram, diagram.t_end)
    return diagram
