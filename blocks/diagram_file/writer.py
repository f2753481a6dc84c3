"""A Diagram written back as a YAML diagram file, which loads to the same diagram.

The top level is written as its file (or its Python calls) said it: its blocks with
their type, period, offset and parameters after params files and overrides (inline, so
the file needs no params file), its subsystems as ``{diagram: FILE, params, bind}``
entries, its wires, its own ports, references and logged signals. A subsystem read from
a file is written as an entry naming that file (from the new file's folder); one built
in Python has no file, so ``save_diagram`` writes it beside the diagram
(``NAME.SUBSYSTEM.yaml``), and ``dump_diagram`` refuses it. ``save_diagram`` also writes
beside the diagram a subsystem whose file is outside the new file's folder, which the
loader would refuse to read from there unless trusted. Paths in path parameters (an
FMU's ``path``) are written from the new file's folder.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Mapping

import numpy as np
import yaml

from blocks.builder.diagram import Composite, Diagram
from blocks.timebase import exact_duration_text
from blocks.builder.api_args import diagram_argument


class WriteError(ValueError):
    """A diagram that cannot be written as YAML (a parameter YAML cannot hold, ...)."""


def dump_diagram(diagram: Diagram, folder: str | Path | None = None) -> str:
    """The diagram as YAML text, its paths written from ``folder`` (default: the
    diagram's own folder). WriteError for a subsystem built in Python (``save_diagram``
    writes those too) or a parameter YAML cannot hold."""
    diagram_argument(diagram)
    return _Writer(diagram, Path(folder) if folder is not None else diagram.base_dir, None).text(diagram.root)


def save_diagram(diagram: Diagram, path: str | Path) -> Path:
    """Write the diagram to ``path``, and each subsystem built in Python beside it as
    ``<stem>.<subsystem>.yaml``; returns ``path``."""
    diagram_argument(diagram)
    path = Path(path)
    writer = _Writer(diagram, path.parent, path.stem)
    text = writer.text(diagram.root)
    path.parent.mkdir(parents=True, exist_ok=True)
    for name, sub_text in writer.extra.items():
        (path.parent / name).write_text(sub_text, encoding="utf-8")
    path.write_text(text, encoding="utf-8")
    return path


class _Writer:
    def __init__(self, diagram: Diagram, folder: Path, stem: str | None):
        self.d = diagram
        self.folder = folder
        self.stem = stem
        self.extra: dict[str, str] = {}
        """File name -> text of the subsystems built in Python, written beside the diagram."""

    def text(self, level: Composite | None) -> str:
        if level is None:
            raise WriteError("the diagram was not made by a DiagramBuilder; nothing says how it was composed")
        return yaml.safe_dump(self.level_data(level), sort_keys=False, allow_unicode=True, width=100,
                              default_flow_style=None)

    def level_data(self, level: Composite) -> dict:
        d = self.d
        data: dict[str, Any] = {"name": level.diagram_name if level.path else d.name}
        if not level.path and d.description:
            data["description"] = d.description
        if not level.path and d.t_end is not None:
            data["time"] = {"t_end": exact_duration_text(d.t_end)}
        blocks: dict[str, Any] = {}
        subsystems = {path: d.subsystems[path] for path in level.subsystems}
        for name in d.blocks:
            local = level.name_of(name) if not level.path or name.startswith(level.path + ".") else None
            head = local.split(".")[0] if local else None
            if head is None or head in blocks:
                continue
            path = f"{level.path}.{head}" if level.path else head
            blocks[head] = self.subsystem_entry(subsystems[path]) if path in subsystems else \
                self.block_entry(name)
        data["blocks"] = blocks
        if level.wires:
            data["connections"] = [self.wire(level, c) for c in level.wires]
        if level.inputs:
            data["inputs"] = {n: [level.name_of(s) for s in p.signals] for n, p in level.inputs.items()}
        if level.outputs:
            data["outputs"] = {n: level.name_of(p.signals[0]) for n, p in level.outputs.items()}
        if level.references:
            data["references"] = {n: r.type_name for n, r in level.references.items()}
        if level.log:
            data["log"] = [level.name_of(e.signal) if e.decimate == 1 else
                           {"signal": level.name_of(e.signal), "decimate": e.decimate} for e in level.log]
        return data

    def block_entry(self, name: str) -> dict:
        spec = self.d.blocks[name]
        entry: dict[str, Any] = {"type": spec.type_ref or spec.type_name}
        if spec.period is not None:
            entry["period"] = self.duration(spec.period, name, "period")
        if spec.offset:
            entry["offset"] = self.duration(spec.offset, name, "offset")
        path_params = type(spec.block).path_params
        params = {}
        for key, value in spec.params.items():
            if key in path_params and isinstance(value, str) and value.strip():
                value = self.path(value)
            params[key] = plain(value, f"block '{name}' parameter '{key}'")
        if params:
            entry["params"] = params
        if spec.units:
            entry["units"] = {port: plain(units, f"block '{name}' units") for port, units in spec.units.items()}
        if spec.labels:
            entry["elements"] = {port: list(names) for port, names in spec.labels.items()}
        return entry

    def subsystem_entry(self, sub: Composite) -> dict:
        source = self.path(sub.file) if sub.file is not None else None
        if source is None or (self.stem is not None and not _below(source)):
            if self.stem is None:
                raise WriteError(f"subsystem '{sub.path}' was built in Python and has no file; save_diagram() "
                                 "writes it beside the diagram")
            source = f"{self.stem}.{sub.path}.yaml"
            self.extra[source] = self.text(sub)
        entry: dict[str, Any] = {"diagram": source}
        if sub.params:
            entry["params"] = {k: plain(v, f"subsystem '{sub.path}' parameter '{k}'") for k, v in sub.params.items()}
        if sub.bind:
            entry["bind"] = dict(sub.bind)
        return entry

    def wire(self, level: Composite, c) -> str | dict:
        text = (level.name_of(c.src) + ("" if c.src_select is None else f"[{c.src_select}]"),
                level.name_of(c.dst) + ("" if c.dst_select is None else f"[{c.dst_select}]"))
        if not c.delay:
            return f"{text[0]} -> {text[1]}"
        out: dict[str, Any] = {"from": text[0], "to": text[1], "delay": c.delay}
        if c.initial is not None:
            out["initial"] = list(c.initial)
        return out

    def duration(self, value, name: str, what: str) -> str:
        try:
            return exact_duration_text(value)
        except ValueError as exc:
            raise WriteError(f"block '{name}' {what}: {exc}") from None

    def path(self, value: str) -> str:
        """``value`` (a path as the diagram resolved it) from the new file's folder."""
        target = Path(value).expanduser()
        try:
            return Path(os.path.relpath(target.absolute(), self.folder.absolute())).as_posix()
        except ValueError:  # another drive
            return str(target.absolute())


def _below(relative: str) -> bool:
    """Whether a path written from the new file's folder stays inside that folder."""
    path = Path(relative)
    return not path.is_absolute() and ".." not in path.parts


def plain(value: Any, what: str) -> Any:
    """``value`` as YAML's plain types (mappings, lists, numbers, text, booleans, null);
    WriteError for anything else, which would not load back as the same value."""
    if isinstance(value, Mapping):
        return {str(k): plain(v, what) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v, what) for v in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist(), what)
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (bool, int, float, str)) or value is None:
        return value
    raise WriteError(f"{what} is a {type(value).__name__}, which a YAML diagram cannot hold")
