"""A params file read for the builder: a YAML mapping of a block's parameter names to values.

The builder knows no file format; it reads a block's ``params_file`` with the reader its
front end gave it (``blocks.builder.records.ParamsReader``). This is the diagram file's,
which every builder made in Python uses too: the file is read under the limits of
``blocks.diagram_file.yaml_source``, and its mappings tell the builder where each
parameter is written, so that a problem with one is reported at its ``file:line``.
"""

from __future__ import annotations

from pathlib import Path

from blocks.builder.records import ParamsText, SourceError
from blocks.diagram_file.yaml_source import LineDict, YamlSourceError, load_yaml, read_yaml_file


def read_params_file(path: Path) -> ParamsText:
    """The params file at ``path``: FileNotFoundError when there is none, SourceError (at
    its line) when it is not a YAML mapping within the limits."""
    try:
        text = read_yaml_file(path)
        data = load_yaml(text)
    except YamlSourceError as exc:
        raise SourceError(exc.message, exc.line, exc.hint) from None
    if data is None:
        return ParamsText(text, {})
    if not isinstance(data, LineDict):
        raise SourceError("a params file must be a YAML mapping of parameter names to values", 1)
    return ParamsText(text, data, data)
