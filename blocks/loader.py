"""The diagram file: strict loading and validation of YAML text into a ``Diagram``.

Every problem is reported as ``file:line: message (hint: ...)``, and all problems of a
file are collected before raising, so a user fixes a diagram in one pass. This module
checks everything a diagram's text says by itself (keys, types, parameters, ports,
widths, connections, logs); whether its rates can be planned is the planner's check,
which ``blocks.load`` adds to make the public ``load_diagram``.
"""

from __future__ import annotations

import copy
import difflib
import hashlib
import json
import re
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any, Iterable, Mapping, NamedTuple

from .arrays import float_array
from .block import Block, ParameterError
from .diagram import BlockSpec, Connection, Diagram, LogEntry, jsonable
from .issues import DiagramError, Issue
from .limits import MAX_PORT_WIDTH
from .param_paths import PathError, set_path
from .references import build_order, chain_text
from .registry import PYTHON_PREFIX, RegistryError, resolve_type
from .safepath import inside
from .timebase import DurationError, parse_duration
from .widths import propagate_widths
from .yamlsource import LineDict, LineList, YamlSourceError, line_at, line_of, load_yaml, read_yaml_file

TOP_KEYS = ("version", "name", "description", "time", "blocks", "connections", "log")
TIME_KEYS = ("t_end",)
BLOCK_KEYS = ("type", "period", "offset", "params", "params_file", "description")
CONNECTION_KEYS = ("from", "to", "delay", "initial")
LOG_KEYS = ("signal", "decimate")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
CODE_DIR_KEY = "."
"""The key of a ``files`` map that gives the diagram's folder itself: where ``python:``
block types' modules are looked for (a diagram copied elsewhere, with its files)."""
_ENDPOINT = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\.([A-Za-z_][A-Za-z0-9_]*)\s*$")


class _ParamsFile(NamedTuple):
    """A block's params file: its path and its content (a LineDict, or {} when empty)."""

    path: str
    data: Mapping


@dataclass
class _Entry:
    """A block of the file checked up to its constructor call (built once its references are)."""

    name: str
    spec: LineDict
    line: int
    cls: type[Block]
    period: Fraction | None
    offset: Fraction | None
    params: dict
    source: _ParamsFile | None = None
    references: dict[str, str] = field(default_factory=dict)
    arguments: dict[str, str] = field(default_factory=dict)
    """Constructor arguments that differ from ``params``: path parameters read from a
    ``files`` map (``params`` keeps the path the diagram names)."""


def read_diagram(path: str | Path, overrides: Mapping[str, Any] | None = None,
                 trust: bool = False, origins: Mapping[str, str] | None = None,
                 files: Mapping[str, str | Path] | None = None) -> Diagram:
    """Read and validate a diagram file; the arguments are those of
    ``blocks.load.load_diagram``, which also plans the diagram."""
    path = Path(path)
    try:
        text = read_yaml_file(path)
    except FileNotFoundError:
        raise DiagramError([Issue(str(path), None, "diagram file not found",
                                  "check the path; diagrams are YAML files such as diagrams/toy.yaml")]) from None
    except YamlSourceError as exc:
        raise DiagramError([Issue(str(path), exc.line, exc.message, exc.hint)]) from None
    return parse_diagram(text, filename=str(path), base_dir=path.parent, overrides=overrides, trust=trust,
                         origins=origins, files=files)


def parse_diagram(text: str, filename: str = "<diagram>", base_dir: str | Path | None = None,
                  overrides: Mapping[str, Any] | None = None, trust: bool = False,
                  origins: Mapping[str, str] | None = None,
                  files: Mapping[str, str | Path] | None = None) -> Diagram:
    """Validate a diagram from YAML text (``base_dir`` resolves ``params_file``); the
    arguments are those of ``blocks.load.loads_diagram``."""
    loader = _Loader(filename, Path(base_dir) if base_dir is not None else Path.cwd(),
                     dict(overrides or {}), trust, dict(origins or {}),
                     {k: Path(v) for k, v in (files or {}).items()})
    return loader.load(text)


def _suggest(word: str, choices: Iterable[str]) -> str:
    close = difflib.get_close_matches(str(word), list(choices), n=1)
    return f"did you mean '{close[0]}'?" if close else ""


def _known(choices: Iterable[str]) -> str:
    return ", ".join(choices) or "none"


def _parse_endpoint(text: Any) -> tuple[str, str] | None:
    m = _ENDPOINT.match(text) if isinstance(text, str) else None
    return (m.group(1), m.group(2)) if m else None


def deep_merge(base: Mapping, top: Mapping) -> dict:
    """``top`` over ``base``: nested mappings merge key by key, anything else replaces."""
    out = {k: copy.deepcopy(v) for k, v in base.items()}
    for key, value in top.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = deep_merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


class _Loader:
    """One pass over a diagram text, collecting every issue before raising."""

    def __init__(self, filename: str, base_dir: Path, overrides: dict[str, Any], trust: bool,
                 origins: dict[str, str], files: dict[str, Path] | None = None):
        self.file = filename
        self.base_dir = base_dir
        self.files_map = files or {}
        """Where to read each file the diagram names (``load_diagram``'s ``files``)."""
        self.code_dir = self.files_map.get(CODE_DIR_KEY, base_dir)
        """Where ``python:`` modules are looked for: the diagram's folder, or its copy."""
        self.files: dict[str, Path] = {}
        """The files read, by the reference the diagram makes (``Diagram.files``)."""
        self.path_refs: dict[tuple[str, str], str] = {}
        """(block, path parameter) -> the path as the diagram (or an override) gives it."""
        self.overrides = overrides
        self.trust = trust
        self.origins = origins
        self.issues: list[Issue] = []
        self.failed_blocks: set[str] = set()
        self.hash = hashlib.sha256()

    def error(self, line: int | None, message: str, hint: str = "", file: str | None = None) -> None:
        self.issues.append(Issue(file or self.file, line, message, hint))

    def override_error(self, key: str, message: str, hint: str = "") -> None:
        origin = self.origins.get(key) or f"--set {key}={self.overrides[key]!r}"
        self.issues.append(Issue(origin, None, message, hint, override=key))

    def load(self, text: str) -> Diagram:
        self.hash.update(text.encode("utf-8"))
        self.hash.update(json.dumps(jsonable(self.overrides), sort_keys=True).encode())
        try:
            data = load_yaml(text)
        except YamlSourceError as exc:
            raise DiagramError([Issue(self.file, exc.line, exc.message, exc.hint)]) from None
        if not isinstance(data, LineDict):
            raise DiagramError([Issue(self.file, getattr(data, "line", 1) or 1,
                                      "a diagram must be a YAML mapping",
                                      f"top-level keys are: {_known(TOP_KEYS)}")])
        self.check_keys(data, TOP_KEYS, "top-level key")
        version = data.get("version", 1)
        if version != 1 or isinstance(version, bool):
            self.error(data.line_of("version"), f"unsupported diagram version {version!r}",
                       "this release reads version: 1")
        name = self.text_field(data, "name", Path(self.file).stem)
        description = self.text_field(data, "description", "")
        t_end, t_end_line = self.time_section(data)
        blocks = self.blocks_section(data)
        for key in self.overrides:
            if key.partition(".")[0] not in blocks and key.partition(".")[0] not in self.failed_blocks:
                self.override_error(key, f"no block named '{key.partition('.')[0]}'",
                                    _suggest(key.partition(".")[0], blocks) or
                                    f"blocks are: {_known(blocks)}")
        connections = self.connections_section(data, blocks)
        if not self.issues:
            self.infer_widths(blocks, connections)
        if not self.issues:
            self.check_inputs(blocks, connections)
        log = self.log_section(data, blocks)
        if self.issues:
            raise DiagramError(self.issues)
        return Diagram(name=name, description=description, file=self.file, blocks=blocks,
                       connections=connections, log=log, t_end=t_end,
                       source_hash=self.hash.hexdigest(), t_end_line=t_end_line,
                       base_dir=self.base_dir, files=dict(self.files))

    # -- the files a diagram names ----------------------------------------------------

    def found(self, ref: str, default: Path) -> Path:
        """Where to read the file the diagram names as ``ref``: its entry in the files map,
        else ``default`` (``ref`` resolved against the diagram's folder); recorded in
        ``self.files`` when it is a file."""
        real = self.files_map.get(ref, default)
        if real.is_file():
            self.files[ref] = real
        return real

    def module_files(self, cls: type) -> None:
        """Record the files of a ``python:`` type's module when it comes from the diagram's
        folder (a package: every .py file in it); installed modules are not the diagram's."""
        import sys

        module = sys.modules.get(cls.__module__)
        origin = getattr(module, "__file__", None)
        if not origin:
            return
        folder = Path(self.code_dir).resolve()
        origin = Path(origin).resolve()
        top = origin.relative_to(folder).parts[0] if inside(origin, folder) else None
        if top is None:
            return
        found = sorted((folder / top).rglob("*.py")) if (folder / top).is_dir() else [folder / top]
        for path in found:
            if "__pycache__" not in path.parts:
                self.files[path.relative_to(folder).as_posix()] = path

    # -- small field helpers ----------------------------------------------------------

    def check_keys(self, mapping: LineDict, allowed: tuple[str, ...], what: str, where: str = "") -> None:
        for key in mapping:
            if key not in allowed:
                hint = _suggest(key, allowed) or f"allowed keys: {_known(allowed)}"
                self.error(mapping.line_of(key), f"unknown {what} {key!r}{where}", hint)

    def text_field(self, data: LineDict, key: str, default: str) -> str:
        value = data.get(key, default)
        if not isinstance(value, str):
            self.error(data.line_of(key), f"'{key}' must be text, got {type(value).__name__}")
            return default
        return value

    def duration(self, mapping: LineDict, key: str, what: str) -> Fraction | None:
        try:
            return parse_duration(mapping[key])
        except DurationError as exc:
            self.error(mapping.line_of(key), f"{what}: {exc}")
            return None

    # -- sections ---------------------------------------------------------------------

    def time_section(self, data: LineDict) -> tuple[Fraction | None, int | None]:
        section = data.get("time")
        if section is None:
            return None, None
        if not isinstance(section, LineDict):
            self.error(data.line_of("time"), "'time' must be a mapping such as {t_end: 1 s}")
            return None, None
        self.check_keys(section, TIME_KEYS, "key", " in 'time'")
        if "t_end" not in section:
            return None, None
        t_end = self.duration(section, "t_end", "time.t_end")
        if t_end is not None and t_end <= 0:
            self.error(section.line_of("t_end"), f"time.t_end must be positive, got {section['t_end']!r}")
            t_end = None
        return t_end, section.line_of("t_end")

    def blocks_section(self, data: LineDict) -> dict[str, BlockSpec]:
        section = data.get("blocks")
        if not isinstance(section, LineDict) or not section:
            self.error(line_of(data, "blocks", 1), "the diagram needs a non-empty 'blocks' mapping",
                       "blocks: {name: {type: Gain, params: {k: 2}}, ...}")
            return {}
        names: list[str] = []
        entries: dict[str, _Entry] = {}
        for name, spec in section.items():
            line = section.line_of(name)
            if not isinstance(name, str) or not _NAME.match(name):
                self.error(line, f"invalid block name {name!r}",
                           "use letters, digits and '_' (not starting with a digit)")
                continue
            names.append(name)
            if not isinstance(spec, LineDict):
                self.error(line, f"block '{name}' must be a mapping with at least 'type'",
                           f"{name}: {{type: Gain, params: {{k: 2}}}}")
                self.failed_blocks.add(name)
                continue
            entry = self.entry(name, spec, line)
            if entry is None or not self.references(entry, names=section):
                self.failed_blocks.add(name)
            else:
                entries[name] = entry
        order, cycles = build_order({name: e.references for name, e in entries.items()})
        cyclic = {r.block for cycle in cycles for r in cycle}
        for cycle in cycles:
            first = entries[cycle[0].block]
            self.param_error(first, (cycle[0].param,), f"block references form a cycle: {chain_text(cycle)}",
                             "a referenced block is built before the blocks that refer to it; "
                             "remove one of these references")
        built: dict[str, BlockSpec] = {}
        for name in order:
            entry = entries[name]
            # a block on a cycle, or referring to a block that failed (reported there), is not built
            spec = None if name in cyclic or any(t not in built for t in entry.references.values()) \
                else self.build(entry, built)
            if spec is None:
                self.failed_blocks.add(name)
            else:
                built[name] = spec
        return {name: built[name] for name in names if name in built}

    def entry(self, name: str, spec: LineDict, line: int) -> _Entry | None:
        """Check a block's keys, type, timing and parameters, up to its constructor call."""
        self.check_keys(spec, BLOCK_KEYS, "key", f" in block '{name}'")
        type_name = spec.get("type")
        if not isinstance(type_name, str):
            self.error(spec.line_of("type") if "type" in spec else line,
                       f"block '{name}' needs a 'type' naming a block type",
                       "run 'hierhand blocks' to list the registered types")
            return None
        try:
            cls = resolve_type(type_name, self.trust, self.code_dir)
        except RegistryError as exc:
            self.error(spec.line_of("type"), f"block '{name}': {exc}", exc.hint)
            return None
        if type_name.startswith(PYTHON_PREFIX):
            self.module_files(cls)
        period = offset = None
        if "period" in spec:
            period = self.duration(spec, "period", f"block '{name}' period")
            if period is not None and period <= 0:
                self.error(spec.line_of("period"), f"block '{name}': period must be positive, got "
                           f"{spec['period']!r}", "write e.g. period: 1 ms; leave it out to inherit")
                period = None
            elif period is None:
                return None
        if "offset" in spec:
            offset = self.duration(spec, "offset", f"block '{name}' offset")
            if offset is None:
                return None
            if period is None:
                self.error(spec.line_of("offset"), f"block '{name}': an offset needs a period",
                           "add period: ... to the block")
                return None
            if not 0 <= offset < period:
                self.error(spec.line_of("offset"), f"block '{name}': offset must be in [0, period)",
                           "an offset is a phase within one period")
                return None
        source = None
        if "params_file" in spec:
            source = self.params_file(spec, name)
            if source is None:
                return None
        params = self.params(name, spec, cls, line, source)
        if params is None:
            return None
        entry = _Entry(name, spec, line, cls, period, offset, params, source)
        for key in cls.path_params:
            ref = self.path_refs.get((name, key))
            if ref is not None:
                real = self.found(ref, Path(params[key]).expanduser())
                if real != Path(params[key]).expanduser():
                    entry.arguments[key] = str(real)
        return entry

    def references(self, entry: _Entry, names: Mapping) -> bool:
        """Check the block's block-reference parameters against the diagram's block names
        and record them in ``entry.references``; False (reported) if one is bad."""
        ok = True
        for key in entry.cls.block_params:
            if key not in entry.params:
                continue
            target = entry.params[key]
            if not isinstance(target, str):
                self.param_error(entry, (key,), f"block '{entry.name}': parameter '{key}' must be the name of "
                                 f"a block of this diagram, got {target!r}", f"e.g. {key}: <block name>")
            elif target == entry.name:
                self.param_error(entry, (key,), f"block '{entry.name}': parameter '{key}' refers to the block "
                                 "itself", f"name another block of this diagram; blocks are: {_known(names)}")
            elif target not in names:
                self.param_error(entry, (key,), f"block '{entry.name}': parameter '{key}' names no block "
                                 f"'{target}'", _suggest(target, names) or f"blocks are: {_known(names)}")
            else:
                entry.references[key] = target
                continue
            ok = False
        return ok

    def param_error(self, entry: _Entry, path: tuple, message: str, hint: str = "") -> None:
        """An issue about a parameter value (``path``: the parameter, then keys and indices
        into it), reported where that value comes from: the --set that gave it (or a part
        of it), else the deepest part of the path written in the block's ``params:`` or
        its params file, else the block's parameters as a whole."""
        parts = [str(p) for p in path]
        for key in self.overrides:
            block, _, rest = key.partition(".")
            given = rest.split(".")
            if parts and block == entry.name and (given[:len(parts)] == parts or parts[:len(given)] == given):
                self.override_error(key, message, hint)
                return
        inline = entry.spec.get("params")
        line, found = line_at(inline, path) if isinstance(inline, LineDict) else (None, 0)
        file = None
        if entry.source is not None:
            file_line, file_found = line_at(entry.source.data, path)
            if file_found > found:
                file, line, found = entry.source.path, file_line, file_found
        if not found:
            written = "params" if "params" in entry.spec else "params_file"
            line = entry.spec.line_of(written) if written in entry.spec else entry.line
        self.error(line, message, hint, file=file)

    def build(self, entry: _Entry, built: Mapping[str, BlockSpec]) -> BlockSpec | None:
        """Construct and bind the block, its references given as the blocks they name."""
        name, spec, line, cls, period = entry.name, entry.spec, entry.line, entry.cls, entry.period
        type_name = spec["type"]
        arguments = dict(entry.params)
        arguments.update(entry.arguments)
        arguments.update({key: built[target].block for key, target in entry.references.items()})
        try:
            block = cls(**arguments)
        except Exception as exc:  # a block's own message says which parameter is wrong
            problems = exc.problems if isinstance(exc, ParameterError) else [((), str(exc))]
            for path, text in problems:
                self.param_error(entry, path, f"block '{name}' ({type_name}): {text}",
                                 f"see 'hierhand blocks {cls.registered_name()}' for its parameters")
            return None
        try:
            block.bind(period)
        except Exception as exc:  # the period does not suit the block: said at the period
            self.error(spec.line_of("period") if "period" in spec else line, f"block '{name}' ({type_name}): {exc}")
            return None
        if period is None and block.period is not None:
            period = block.period  # a block with a natural rate (an FMU's default step)
        block.name = name
        for kind in ("inputs", "outputs"):
            ports = getattr(block, kind)
            if not isinstance(ports, Mapping) or not all(
                    isinstance(p, str) and (w is None or (isinstance(w, int) and 0 < w <= MAX_PORT_WIDTH))
                    for p, w in ports.items()):
                self.error(line, f"block '{name}' ({type_name}) declares invalid {kind}: {ports!r}",
                           f"ports map names to integer widths from 1 to {MAX_PORT_WIDTH} (or None to infer)")
                return None
        params_file = str(self.base_dir / spec["params_file"]) if "params_file" in spec else None
        return BlockSpec(name, cls.registered_name(), block, period, entry.offset or Fraction(0), entry.params,
                         line, params_file)

    def params(self, name: str, spec: LineDict, cls: type[Block], line: int,
               source: _ParamsFile | None) -> dict | None:
        inline = spec.get("params", {})
        if inline is None:
            inline = {}
        if not isinstance(inline, Mapping):
            self.error(spec.line_of("params"), f"block '{name}': 'params' must be a mapping")
            return None
        params = deep_merge(source.data if source else {}, inline)
        declared = cls.parameters()
        accepts_any = cls.accepts_any_parameter()
        ok = True
        given = [(inline, None, spec.line_of("params"))]
        if source is not None:
            given.insert(0, (source.data, source.path, 1))
        for mapping, file, default_line in given:
            for key in mapping:
                if key not in declared and not accepts_any:
                    self.error(line_of(mapping, key, default_line),
                               f"block '{name}' ({cls.registered_name()}) has no parameter {key!r}",
                               _suggest(key, declared) or f"parameters: {_known(declared)}", file=file)
                    ok = False
        for key, value in self.overrides.items():
            block_name, _, path = key.partition(".")
            if block_name != name:
                continue
            parts = path.split(".") if path else []
            if not parts or not all(parts):
                self.override_error(key, "expected --set block.param=value")
                ok = False
                continue
            if parts[0] not in declared and not accepts_any:
                self.override_error(key, f"block '{name}' ({cls.registered_name()}) has no parameter "
                                    f"{parts[0]!r}", _suggest(parts[0], declared) or
                                    f"parameters: {_known(declared)}")
                ok = False
                continue
            try:
                set_path(params, name, parts, value, cls.param_default)
            except PathError as exc:
                self.override_error(key, str(exc), exc.hint)
                ok = False
        for key in cls.path_params:
            value = params.get(key)
            if isinstance(value, str) and value.strip():
                self.path_refs[(name, key)] = value
                if not Path(value).expanduser().is_absolute():
                    params[key] = str(self.base_dir / value)
        missing = [p for p, d in declared.items() if d.default is d.empty and p not in params]
        if missing:
            self.error(spec.line_of("params") if "params" in spec else line,
                       f"block '{name}' ({cls.registered_name()}) is missing parameter(s) "
                       f"{', '.join(missing)}", f"add them under params: of block '{name}'")
            ok = False
        return params if ok else None

    def params_file(self, spec: LineDict, name: str) -> _ParamsFile | None:
        """Read the block's params file; without ``trust`` it must lie in the diagram's
        folder tree (see ``blocks.safepath``)."""
        rel = spec["params_file"]
        line = spec.line_of("params_file")
        if not isinstance(rel, str):
            self.error(line, f"block '{name}': params_file must be a path")
            return None
        path = (self.base_dir / rel)
        if not self.trust and not inside(path, self.base_dir):
            self.error(line, f"block '{name}': params_file '{rel}' is outside the diagram's folder",
                       "a diagram reads files only from its own folder and below; pass --trust "
                       "(Python: trust=True) if you trust this diagram")
            return None
        try:
            text = read_yaml_file(self.files_map.get(rel, path))
            self.found(rel, path)
            self.hash.update(text.encode("utf-8"))
            data = load_yaml(text)
        except FileNotFoundError:
            self.error(line, f"block '{name}': params_file '{rel}' not found (looked at {path})",
                       "params_file is relative to the diagram's folder")
            return None
        except YamlSourceError as exc:
            if exc.line is None:  # the file as a whole: reported where the diagram names it
                self.error(line, f"block '{name}': params_file '{rel}': {exc.message}", exc.hint)
            else:
                self.error(exc.line, exc.message, exc.hint, file=str(path))
            return None
        if data is None:
            return _ParamsFile(str(path), {})
        if not isinstance(data, Mapping):
            self.error(1, "a params file must be a YAML mapping of parameter names to values",
                       file=str(path))
            return None
        return _ParamsFile(str(path), data)

    def connections_section(self, data: LineDict, blocks: dict[str, BlockSpec]) -> list[Connection]:
        section = data.get("connections")
        if section is None:
            return []
        if not isinstance(section, LineList):
            self.error(data.line_of("connections"), "'connections' must be a list",
                       "- src.y -> dst.u")
            return []
        connections: list[Connection] = []
        driven: dict[tuple[str, str], Connection] = {}
        for i, item in enumerate(section):
            line = section.line_of(i)
            conn = self.connection(item, line, blocks)
            if conn is None:
                continue
            key = (conn.dst_block, conn.dst_port)
            if key in driven:
                first = driven[key]
                self.error(line, f"input {conn.dst} is driven twice: by {conn.src} and by "
                           f"{first.src} (line {first.line})", "an input takes exactly one connection; "
                           "add a Sum block to combine signals")
                continue
            driven[key] = conn
            connections.append(conn)
        return connections

    def connection(self, item: Any, line: int, blocks: dict[str, BlockSpec]) -> Connection | None:
        delay, initial = 0, None
        if isinstance(item, str):
            src_text, arrow, dst_text = item.partition("->")
            if not arrow:
                self.error(line, f"connection {item!r} is not of the form 'block.port -> block.port'",
                           "e.g. - plant.y -> err.u1")
                return None
        elif isinstance(item, LineDict):
            self.check_keys(item, CONNECTION_KEYS, "key", " in connection")
            if "from" not in item or "to" not in item:
                self.error(line, "a connection mapping needs 'from' and 'to'",
                           "{from: a.y, to: b.u, delay: 1}")
                return None
            src_text, dst_text = item["from"], item["to"]
            delay = item.get("delay", 0)
            if delay not in (0, 1) or isinstance(delay, bool):
                self.error(item.line_of("delay"), f"connection delay must be 0 or 1, got {delay!r}",
                           "delay: 1 is one sample of the destination's rate")
                return None
            if "initial" in item:
                try:
                    initial = tuple(float(v) for v in float_array(item["initial"], "initial", ndim=1))
                except ValueError:
                    self.error(item.line_of("initial"), "connection 'initial' must be a number or list "
                               "of numbers")
                    return None
                if not delay:
                    self.error(item.line_of("initial"), "'initial' only applies to a connection with delay: 1")
                    return None
        else:
            self.error(line, "a connection is 'a.y -> b.u' or {from: a.y, to: b.u, delay: 1}")
            return None
        src, dst = _parse_endpoint(src_text), _parse_endpoint(dst_text)
        text = f"{str(src_text).strip()} -> {str(dst_text).strip()}"
        if src is None or dst is None:
            bad = src_text if src is None else dst_text
            self.error(line, f"connection '{text}': {str(bad).strip()!r} is not 'block.port'",
                       "e.g. - plant.y -> err.u1")
            return None
        ok = self.endpoint(src, "outputs", text, line, blocks)
        ok = self.endpoint(dst, "inputs", text, line, blocks) and ok
        if not ok:
            return None
        return Connection(src[0], src[1], dst[0], dst[1], int(delay), initial, line)

    def endpoint(self, ep: tuple[str, str], kind: str, text: str, line: int,
                 blocks: dict[str, BlockSpec]) -> bool:
        block, port = ep
        if block not in blocks:
            if block not in self.failed_blocks:
                self.error(line, f"connection '{text}': no block named '{block}'",
                           _suggest(block, blocks) or f"blocks are: {_known(blocks)}")
            return False
        spec = blocks[block]
        ports = getattr(spec.block, kind)
        if port not in ports:
            other = spec.block.inputs if kind == "outputs" else spec.block.outputs
            what = "output" if kind == "outputs" else "input"
            hint = _suggest(port, ports) or f"{what}s of '{block}' ({spec.type_name}): {_known(ports)}"
            if port in other:
                hint = f"'{block}.{port}' is an {'input' if kind == 'outputs' else 'output'}; " \
                       f"connections go from an output to an input"
            hint = spec.block.port_hint(port) or hint
            self.error(line, f"connection '{text}': block '{block}' ({spec.type_name}) has no "
                       f"{what} '{port}'", hint)
            return False
        return True

    def infer_widths(self, blocks: dict[str, BlockSpec], connections: list[Connection]) -> None:
        """Give polymorphic ports (width None) the width of what they connect to."""
        inferred = propagate_widths(lambda block, kind, port: getattr(blocks[block].block, kind)[port],
                                    connections)
        for name, spec in blocks.items():
            ports = {**spec.block.inputs, **spec.block.outputs}
            if any(w is None for w in ports.values()):
                if name not in inferred:
                    self.error(spec.line, f"cannot infer the port widths of block '{name}' "
                               f"({spec.type_name}): nothing with a known width is connected to it",
                               "connect it to a block with fixed widths or give it a width parameter")
                    continue
                spec.block.set_width(inferred[name])
        for c in connections:
            ws = blocks[c.src_block].block.outputs[c.src_port]
            wd = blocks[c.dst_block].block.inputs[c.dst_port]
            if ws is not None and wd is not None and ws != wd:
                self.error(c.line, f"connection '{c.src} -> {c.dst}': width mismatch: {c.src} has width "
                           f"{ws}, {c.dst} has width {wd}", "insert a Gain with a matrix k to map "
                           "between widths, or fix the block parameters")
            elif c.initial is not None and ws is not None and len(c.initial) not in (1, ws):
                self.error(c.line, f"connection '{c.src} -> {c.dst}': 'initial' has {len(c.initial)} "
                           f"values, the signal has width {ws}")

    def check_inputs(self, blocks: dict[str, BlockSpec], connections: list[Connection]) -> None:
        driven = {(c.dst_block, c.dst_port) for c in connections}
        for name, spec in blocks.items():
            for port in spec.block.inputs:
                if (name, port) not in driven and port not in spec.block.input_defaults:
                    self.error(spec.line, f"input {name}.{port} of block '{name}' ({spec.type_name}) "
                               "is not connected", f"add a connection '- <block>.<port> -> {name}.{port}'")

    def log_section(self, data: LineDict, blocks: dict[str, BlockSpec]) -> list[LogEntry]:
        section = data.get("log")
        if section is None:
            return []
        if section == "all":
            return [LogEntry(b, p, 1, data.line_of("log")) for b, s in blocks.items() for p in s.block.outputs]
        if not isinstance(section, LineList):
            self.error(data.line_of("log"), "'log' must be a list of signals or 'all'",
                       "log: [plant.y, {signal: ctrl.u, decimate: 10}]")
            return []
        entries: list[LogEntry] = []
        seen: set[str] = set()
        for i, item in enumerate(section):
            line = section.line_of(i)
            decimate = 1
            if isinstance(item, LineDict):
                self.check_keys(item, LOG_KEYS, "key", " in log entry")
                decimate = item.get("decimate", 1)
                if not isinstance(decimate, int) or isinstance(decimate, bool) or decimate < 1:
                    self.error(item.line_of("decimate"), f"log decimate must be a positive integer, "
                               f"got {decimate!r}")
                    continue
                item = item.get("signal")
            ep = _parse_endpoint(item)
            if ep is None:
                self.error(line, f"log entry {item!r} is not 'block.port'", "e.g. - plant.y")
                continue
            block, port = ep
            if block not in blocks:
                if block not in self.failed_blocks:
                    self.error(line, f"log entry '{block}.{port}': no block named '{block}'",
                               _suggest(block, blocks) or f"blocks are: {_known(blocks)}")
                continue
            outputs = blocks[block].block.outputs
            if port not in outputs:
                self.error(line, f"log entry '{block}.{port}': block '{block}' "
                           f"({blocks[block].type_name}) has no output '{port}'",
                           blocks[block].block.port_hint(port) or _suggest(port, outputs)
                           or f"outputs: {_known(outputs)}")
                continue
            if f"{block}.{port}" in seen:
                self.error(line, f"signal '{block}.{port}' is logged twice")
                continue
            seen.add(f"{block}.{port}")
            entries.append(LogEntry(block, port, decimate, line))
        return entries
