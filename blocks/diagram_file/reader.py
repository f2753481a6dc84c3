"""The diagram file: a YAML front end of ``DiagramBuilder``.

It reads a diagram file within the limits of ``blocks.limits``, checks what only the
YAML text can get wrong (its syntax, the shape of its sections, unknown keys) and says
everything else to a ``DiagramBuilder``, each entry with the ``file:line`` it is written
at; the builder checks what the entries mean and makes the Diagram, so a diagram from a
file and one built in Python are checked by the same code. All problems of a file are
reported at once, each as ``file:line: message (hint: ...)``.

A block entry ``{diagram: pi.yaml, params: {...}, bind: {...}}`` is a subsystem: another
diagram file, relative to the including file's folder and, unless the diagram is
trusted, inside it (as a params file must be). It is read when the build reaches it
(``IncludedFile``), under the same limits, once per load however often it is used.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Mapping

from blocks.builder.api_args import boolean

from blocks.builder.diagram_builder import DiagramBuilder, Site
from blocks.builder.diagram import FileScope
from blocks.builder.context import known, suggest
from blocks.issues import DiagramError, Issue
from blocks.safepath import OUTSIDE_HINT, inside
from blocks.builder.scopes import NAME
from blocks.diagram_file.params_file import read_params_file
from blocks.diagram_file.yaml_source import (
    LineDict,
    LineList,
    YamlSourceError,
    line_of,
    load_yaml,
    read_yaml_file,
)

TOP_KEYS = ("version", "name", "description", "time", "blocks", "connections", "inputs", "outputs", "references",
            "log", "units", "elements")
TIME_KEYS = ("t_end",)
BLOCK_KEYS = ("type", "period", "offset", "params", "params_file", "description", "units", "elements")
SUBSYSTEM_KEYS = ("diagram", "params", "bind", "description")
CONNECTION_KEYS = ("from", "to", "delay", "initial")
LOG_KEYS = ("signal", "decimate")
CODE_DIR_KEY = "."
"""The key of a ``files`` map that gives the diagram's folder itself: where ``python:``
block types' modules are looked for (a diagram copied elsewhere, with its files)."""


def read_builder(path: str | Path, trust: bool = False, files: Mapping[str, str | Path] | None = None) -> DiagramBuilder:
    """The builder of the diagram file ``path``, not built yet: a diagram to use as a
    subsystem from Python (``DiagramBuilder.add_subsystem``), or to build with overrides.
    ``trust`` and ``files`` as for ``blocks.load_diagram``. DiagramError if the file
    cannot be read as a diagram; TypeError for a ``trust`` that is not True or False, or
    a path that is not text or a path object."""
    boolean("trust", trust)
    if not isinstance(path, (str, os.PathLike)) or isinstance(os.fspath(path), bytes):
        raise TypeError(f"path must be a str or a pathlib.Path, got {type(path).__name__}")
    path = Path(path)
    reading = _Reading({k: Path(v) for k, v in (files or {}).items()})
    try:
        text = read_yaml_file(path)
    except FileNotFoundError:
        raise DiagramError([Issue(str(path), None, "diagram file not found",
                                  "check the path; diagrams are YAML files such as diagrams/toy.yaml")]) from None
    except YamlSourceError as exc:
        raise DiagramError([Issue(str(path), exc.line, exc.message, exc.hint)]) from None
    builder = _FrontEnd(reading, str(path), path.parent, trust).parse(text)
    reading.top = (path, builder)
    return builder


def parse_builder(text: str, filename: str = "<diagram>", base_dir: str | Path | None = None, trust: bool = False,
                  files: Mapping[str, str | Path] | None = None) -> DiagramBuilder:
    """The builder of a diagram's YAML text (``base_dir``: where its relative paths lead,
    default the current folder)."""
    boolean("trust", trust)
    if not isinstance(text, str):
        raise TypeError(f"text must be a str of YAML, got {type(text).__name__}")
    reading = _Reading({k: Path(v) for k, v in (files or {}).items()})
    return _FrontEnd(reading, filename, Path(base_dir) if base_dir is not None else Path.cwd(), trust).parse(text)


def _identity(path: Path) -> Path:
    """A file's identity for the files already read: its real path."""
    try:
        return path.resolve()
    except (OSError, RuntimeError):
        return path.absolute()


class _Reading:
    """What the files of one load share: where to read them (``files``) and those read."""

    def __init__(self, files_map: dict[str, Path]):
        self.files_map = files_map
        self.cache: dict[Path, DiagramBuilder] = {}
        self.top: tuple[Path, DiagramBuilder] | None = None
        """The top diagram's file, put in ``cache`` once a subsystem is read (a file that
        includes the top one is then the top one, and closes a chain)."""

    def known(self, path: Path) -> DiagramBuilder | None:
        """The builder of the file ``path`` if it was read in this load."""
        if self.top is not None:
            self.cache.setdefault(_identity(self.top[0]), self.top[1])
            self.top = None
        return self.cache.get(_identity(path))


class IncludedFile:
    """A subsystem's diagram file, as an entry names it; read by the build (``open``)."""

    def __init__(self, reading: _Reading, rel: str, site: Site, folder: Path, trust: bool):
        self.reading = reading
        self.rel = rel
        self.site = site
        self.folder = folder
        self.trust = trust

    def open(self, scope: FileScope, path: str) -> tuple[DiagramBuilder, dict[str, Path]]:
        rel, site = self.rel, self.site
        target = self.folder / rel
        what = f"subsystem '{path}': diagram '{rel}'"
        if not self.trust and not inside(target, self.folder):
            raise DiagramError([site.issue(f"{what} is outside the diagram's folder",
                                           OUTSIDE_HINT, key="diagram")])
        ref = scope.ref(rel)
        real = self.reading.files_map.get(ref, target)
        found = self.reading.known(real)
        if found is not None:
            return found, {ref: real}
        try:
            text = read_yaml_file(real)
        except FileNotFoundError:
            raise DiagramError([site.issue(f"{what} not found (looked at {target})",
                                           "a subsystem's diagram is relative to the including diagram's folder",
                                           key="diagram")]) from None
        except YamlSourceError as exc:
            if exc.line is None:
                raise DiagramError([site.issue(f"{what}: {exc.message}", exc.hint, key="diagram")]) from None
            raise DiagramError([Issue(str(target), exc.line, exc.message, exc.hint)]) from None
        builder = _FrontEnd(self.reading, str(target), target.parent, self.trust).parse(text)
        self.reading.cache[_identity(real)] = builder
        return builder, {ref: real}


class _FrontEnd:
    """One diagram file's text said to a DiagramBuilder."""

    def __init__(self, reading: _Reading, filename: str, base_dir: Path, trust: bool):
        self.reading = reading
        self.file = filename
        self.base_dir = base_dir
        self.trust = trust
        self.b: DiagramBuilder | None = None

    def site(self, line: int | None, mapping: LineDict | None = None) -> Site:
        """The builder's site of an entry at ``line``, written as ``mapping`` (whose keys
        know their lines: the builder's ``Positions``)."""
        return Site(self.file, line, mapping)

    def fail(self, line: int | None, message: str, hint: str = "", name: str | None = None) -> None:
        self.b.fail(Issue(self.file, line, message, hint), name)

    def check_keys(self, mapping: LineDict, allowed: tuple[str, ...], what: str, where: str = "") -> None:
        for key in mapping:
            if key not in allowed:
                hint = suggest(key, allowed) or f"allowed keys: {known(allowed)}"
                self.fail(mapping.line_of(key), f"unknown {what} {key!r}{where}", hint)

    def parse(self, text: str) -> DiagramBuilder:
        try:
            data = load_yaml(text)
        except YamlSourceError as exc:
            raise DiagramError([Issue(self.file, exc.line, exc.message, exc.hint)]) from None
        if not isinstance(data, LineDict):
            raise DiagramError([Issue(self.file, getattr(data, "line", 1) or 1, "a diagram must be a YAML mapping",
                                      f"top-level keys are: {known(TOP_KEYS)}")])
        b = self.b = DiagramBuilder(data.get("name", Path(self.file).stem), data.get("description", ""),
                                    base_dir=self.base_dir, trust=self.trust, where=self.site(1, data),
                                    read_params=read_params_file)
        b.label = self.file
        b.texts.append(text)
        b.files_map = self.reading.files_map
        self.check_keys(data, TOP_KEYS, "top-level key")
        version = data.get("version", 1)
        if version != 1 or isinstance(version, bool):
            self.fail(data.line_of("version"), f"unsupported diagram version {version!r}",
                      "this release reads version: 1")
        self.time_section(data)
        self.blocks_section(data)
        self.connections_section(data)
        self.ports_section(data, "inputs")
        self.ports_section(data, "outputs")
        self.references_section(data)
        self.log_section(data)
        for key in ("units", "elements"):
            self.annotations(data, key, "")
        return b

    def annotations(self, data: LineDict, key: str, block: str) -> None:
        """``units: {plant.y: rad}`` / ``elements: {plant.y: [x, y]}`` (on a block entry by
        port: ``units: {y: rad}``): the diagram's units and element names of ports."""
        section = data.get(key)
        if section is None:
            return
        example = f"{key}: {{{'' if block else 'plant.'}y: {'rad' if key == 'units' else '[x, y, theta]'}}}"
        if not isinstance(section, LineDict):
            self.fail(data.line_of(key), f"'{key}' must map {'ports' if block else 'signals (block.port)'} to "
                      f"{'units' if key == 'units' else 'lists of element names'}", example)
            return
        for port, value in section.items():
            signal = f"{block}.{port}" if block else port
            self.b.annotate(signal, where=self.site(section.line_of(port)), **{key: value})

    def time_section(self, data: LineDict) -> None:
        section = data.get("time")
        if section is None:
            return
        if not isinstance(section, LineDict):
            self.fail(data.line_of("time"), "'time' must be a mapping such as {t_end: 1 s}")
            return
        self.check_keys(section, TIME_KEYS, "key", " in 'time'")
        if "t_end" in section:
            self.b.t_end = section["t_end"]
            self.b.t_end_site = self.site(section.line, section)

    def blocks_section(self, data: LineDict) -> None:
        section = data.get("blocks")
        if not isinstance(section, LineDict) or not section:
            self.fail(line_of(data, "blocks", 1), "the diagram needs a non-empty 'blocks' mapping",
                      "blocks: {name: {type: Gain, params: {k: 2}}, ...}")
            return
        for name, spec in section.items():
            line = section.line_of(name)
            if not isinstance(spec, LineDict):
                if isinstance(name, str) and NAME.match(name):
                    self.fail(line, f"block '{name}' must be a mapping with at least 'type'",
                              f"{name}: {{type: Gain, params: {{k: 2}}}}", name=name)
                    continue
                spec = LineDict()
                spec.line, spec.key_lines = line, {}
            site = self.site(line, spec)
            if "diagram" in spec:
                self.check_keys(spec, SUBSYSTEM_KEYS, "key", f" in subsystem '{name}'")
                rel = spec["diagram"]
                if not isinstance(rel, str) or not rel.strip():
                    self.fail(spec.line_of("diagram"), f"subsystem '{name}': 'diagram' must be the path of a "
                              "diagram file", "ctrl: {diagram: pi.yaml}", name=name)
                    continue
                self.b.add_subsystem(name, IncludedFile(self.reading, rel, site, self.base_dir, self.trust),
                                     params=spec.get("params"), bind=spec.get("bind"), where=site, source=rel)
                continue
            self.check_keys(spec, BLOCK_KEYS, "key", f" in block '{name}'")
            self.b.add(name, spec.get("type"), period=spec.get("period"), offset=spec.get("offset"),
                       params=spec.get("params"), params_file=spec.get("params_file"), where=site)
            for key in ("units", "elements"):
                self.annotations(spec, key, name)

    def connections_section(self, data: LineDict) -> None:
        section = data.get("connections")
        if section is None:
            return
        if not isinstance(section, LineList):
            self.fail(data.line_of("connections"), "'connections' must be a list", "- src.y -> dst.u")
            return
        for i, item in enumerate(section):
            line = section.line_of(i)
            if isinstance(item, str):
                src, arrow, dst = item.partition("->")
                if not arrow:
                    self.fail(line, f"connection {item!r} is not of the form 'block.port -> block.port'",
                              "e.g. - plant.y -> err.u1")
                    continue
                self.b.connect(src, dst, where=self.site(line))
            elif isinstance(item, LineDict):
                self.check_keys(item, CONNECTION_KEYS, "key", " in connection")
                if "from" not in item or "to" not in item:
                    self.fail(line, "a connection mapping needs 'from' and 'to'", "{from: a.y, to: b.u, delay: 1}")
                    continue
                self.b.connect(item["from"], item["to"], delay=item.get("delay", 0), initial=item.get("initial"),
                               where=self.site(line, item))
                self.b.wires[-1].has_initial = "initial" in item
            else:
                self.fail(line, "a connection is 'a.y -> b.u' or {from: a.y, to: b.u, delay: 1}")

    def ports_section(self, data: LineDict, key: str) -> None:
        """``inputs: {e: [integ.u, prop.u]}`` (or ``e: integ.u``); ``outputs: {u: u.y}``."""
        section = data.get(key)
        if section is None:
            return
        example = "inputs: {e: [integ.u, prop.u]}" if key == "inputs" else "outputs: {u: u.y}"
        if not isinstance(section, LineDict):
            self.fail(data.line_of(key), f"'{key}' must be a mapping of port names to inner ports", example)
            return
        for name, value in section.items():
            site = self.site(section.line_of(name))
            if key == "outputs":
                self.b.output(name, value, where=site)
            elif isinstance(value, LineList):
                self.b.input(name, *value, where=site)
            else:
                self.b.input(name, value, where=site)

    def references_section(self, data: LineDict) -> None:
        """``references: [plant]``, or with stand-in types ``references: {plant: HandPlant}``."""
        section = data.get("references")
        if section is None:
            return
        if isinstance(section, LineList):
            for i, name in enumerate(section):
                self.b.reference(name, where=self.site(section.line_of(i)))
        elif isinstance(section, LineDict):
            for name, stand_in in section.items():
                self.b.reference(name, stand_in, where=self.site(section.line_of(name)))
        else:
            self.fail(data.line_of("references"), "'references' must be a list of names, or a mapping of names "
                      "to the block types that stand in for them", "references: {plant: HandPlant}")

    def log_section(self, data: LineDict) -> None:
        section = data.get("log")
        if section is None:
            return
        if section == "all":
            self.b.log_all(where=self.site(data.line_of("log")))
            return
        if not isinstance(section, LineList):
            self.fail(data.line_of("log"), "'log' must be a list of signals or 'all'",
                      "log: [plant.y, {signal: ctrl.u, decimate: 10}]")
            return
        for i, item in enumerate(section):
            line = section.line_of(i)
            if isinstance(item, LineDict):
                self.check_keys(item, LOG_KEYS, "key", " in log entry")
                self.b.log(item.get("signal"), decimate=item.get("decimate", 1), where=self.site(line, item))
            else:
                self.b.log(item, where=self.site(line))
