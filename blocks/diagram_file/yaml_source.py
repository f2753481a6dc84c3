"""YAML safe loading that remembers where every mapping key and list item was written.

Diagram errors must say ``file:line``; PyYAML forgets positions once it builds Python
objects, so this module builds them itself from the node tree and keeps the line of
each key and item beside the value. It also rejects duplicate keys, which PyYAML
silently collapses.

The text may be hostile, so reading and loading stop at the limits of ``blocks.limits``:
a file's size and kind (``read_yaml_file``), the nesting depth (measured before libyaml
composes, whose recursion would overflow the C stack) and the values aliases may repeat
(the 'billion laughs'). Every refusal is a ``YamlSourceError`` with the line to look at.
"""

from __future__ import annotations

import bisect
import copy
import os
import reprlib
import stat
from pathlib import Path
from typing import Any, Sequence

import yaml

from blocks.limits import MAX_ALIAS_VALUES, MAX_NUMBER_CHARS, MAX_YAML_BYTES, MAX_YAML_DEPTH
from blocks.safepath import unusable_path


_Loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
"""libyaml's parser when PyYAML was built with it (about 10x faster), else pure Python."""


_SEQ_TAG = "tag:yaml.org,2002:seq"
_MAP_TAG = "tag:yaml.org,2002:map"
_MERGE_TAG = "tag:yaml.org,2002:merge"
_NUMBER_TAGS = {"tag:yaml.org,2002:int": "an integer", "tag:yaml.org,2002:float": "a number"}
_SCALAR_TAGS = {"tag:yaml.org,2002:str", "tag:yaml.org,2002:bool", "tag:yaml.org,2002:null", *_NUMBER_TAGS}
_TIMESTAMP_TAG = "tag:yaml.org,2002:timestamp"


class YamlSourceError(Exception):
    """A YAML text that cannot be read; ``line`` is 1-based, or None when unknown."""

    def __init__(self, message: str, line: int | None, hint: str = ""):
        super().__init__(message)
        self.message = message
        self.line = line
        self.hint = hint


class LineDict(dict):
    """A mapping from YAML with ``line`` (of the mapping) and ``key_lines`` (per key)."""

    line: int = 0
    key_lines: dict

    def line_of(self, key: Any) -> int:
        return self.key_lines.get(key, self.line)

    def line_at(self, path: Sequence[Any]) -> tuple[int | None, int]:
        """Where the value at ``path`` inside this mapping is written (``line_at``): the
        builder's ``Positions`` of a mapping read from YAML."""
        return line_at(self, path)

    def __deepcopy__(self, memo: dict) -> "LineDict":
        """A copy with its lines, made directly (copy's generic way is slow, and every
        block's parameters are copied once per load)."""
        new = memo[id(self)] = LineDict()  # registered first, as copy does, should a value hold this mapping
        new.update((k, copy.deepcopy(v, memo)) for k, v in self.items())
        new.__dict__.update(copy.deepcopy(self.__dict__, memo))
        return new


class LineList(list):
    """A sequence from YAML with ``line`` (of the sequence) and ``item_lines``."""

    line: int = 0
    item_lines: list

    def line_of(self, index: int) -> int:
        return self.item_lines[index] if 0 <= index < len(self.item_lines) else self.line

    def line_at(self, path: Sequence[Any]) -> tuple[int | None, int]:
        """Where the value at ``path`` inside this sequence is written (``line_at``)."""
        return line_at(self, path)

    def __deepcopy__(self, memo: dict) -> "LineList":
        """A copy with its lines, made directly (as LineDict's)."""
        new = memo[id(self)] = LineList()
        new.extend(copy.deepcopy(v, memo) for v in self)
        new.__dict__.update(copy.deepcopy(self.__dict__, memo))
        return new


def line_of(container: Any, key: Any, default: int = 0) -> int:
    """Line of ``key`` inside a LineDict/LineList, or ``default`` for plain containers."""
    if isinstance(container, (LineDict, LineList)):
        return container.line_of(key)
    return getattr(container, "line", default) or default


def line_at(data: Any, path: Sequence[Any]) -> tuple[int | None, int]:
    """Where a value inside ``data`` is written: the line of the deepest part of ``path``
    (mapping keys and list indices, ``("fingers", 1, "links")``) that ``data`` holds, and
    how many parts it holds (0: none, the line is that of ``data`` itself, if known)."""
    line, found = getattr(data, "line", None) or None, 0
    for part in path:
        if isinstance(data, LineDict) and part in data:
            line, data = data.line_of(part), data[part]
        elif isinstance(data, LineList) and isinstance(part, int) and 0 <= part < len(data):
            line, data = data.line_of(part), data[part]
        else:
            break
        found += 1
    return line, found


def read_yaml_file(path: str | Path, kind: str = "YAML") -> str:
    """The text of a diagram, params file or hand file (or another small text input, named
    ``kind`` in the hints, such as a CSV points file): a regular file of at most
    MAX_YAML_BYTES bytes of UTF-8 text without NUL bytes.

    The size and kind are checked on the open file before anything is read (a device or
    FIFO is refused unread; opening does not wait for a FIFO's writer). Raises
    FileNotFoundError for a missing file, YamlSourceError for anything else, with the
    line and column of the first bad byte where there is one.
    """
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        raise
    except OSError as exc:
        raise YamlSourceError(f"cannot open: {exc.strerror or exc}", None) from None
    except ValueError as exc:
        raise YamlSourceError(f"cannot open: {unusable_path(exc)}", None) from None
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):
        os.close(fd)
        raise YamlSourceError("not a regular file (a folder, device or pipe)", None, f"name a {kind} file")
    with os.fdopen(fd, "rb") as fh:
        raw = fh.read(MAX_YAML_BYTES + 1) if info.st_size <= MAX_YAML_BYTES else b""
        if info.st_size > MAX_YAML_BYTES or len(raw) > MAX_YAML_BYTES:
            raise YamlSourceError(f"file larger than {MAX_YAML_BYTES} bytes", None,
                                  f"the limit guards against hostile files; keep large data out of {kind}")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line_start = raw.rfind(b"\n", 0, exc.start) + 1
        column = len(raw[line_start:exc.start].decode("utf-8")) + 1
        raise YamlSourceError(f"not UTF-8 text: byte 0x{raw[exc.start]:02x} at column {column}",
                              raw.count(b"\n", 0, exc.start) + 1,
                              f"save the file as UTF-8; a binary file is not {kind}") from None
    text = text.removeprefix("\ufeff")  # a byte order mark, which some editors write first
    if "\x00" in text:
        line, column = _position(text, text.index("\x00"))
        raise YamlSourceError(f"NUL byte at column {column}: a binary file, not {kind} text", line,
                              "save the file as UTF-8 text")
    return text


def load_yaml(text: str) -> Any:
    """Parse one YAML document into LineDict/LineList/scalars; None for an empty text.

    Refuses (YamlSourceError) nesting deeper than MAX_YAML_DEPTH and aliases or merge keys
    that repeat more than MAX_ALIAS_VALUES values.
    """
    lines = _Lines(text)
    try:
        _check_depth(text, lines)
        loader = _Loader(text)
        try:
            node = loader.get_single_node()
            return None if node is None else _Builder(loader, lines).build(node, 1, lines.of(node.start_mark))
        finally:
            loader.dispose()
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        problem = exc.problem or exc.context or "invalid YAML"
        if "maximum nesting depth" in problem:  # libyaml's own limit, met while it scans ahead of our count
            raise YamlSourceError(f"YAML lists and mappings nested deeper than {MAX_YAML_DEPTH} levels",
                                  lines.of(mark), "a diagram needs about 8 levels") from None
        raise YamlSourceError(f"YAML syntax error: {problem}", lines.of(mark),
                              "check indentation, colons and brackets near that line") from None
    except yaml.reader.ReaderError as exc:
        line, column = _position(text, text.find(chr(exc.character)))
        raise YamlSourceError(f"character U+{exc.character:04X} at column {column} is not allowed in YAML",
                              line, "remove it; YAML text has no control characters") from None
    except yaml.YAMLError as exc:
        raise YamlSourceError(f"YAML error: {' '.join(str(exc).split())}", None) from None


def load_yaml_value(text: str, where: str) -> Any:
    """A value given on the command line (``--set``, ``--grid``, a points file's cell) read
    as YAML under the limits of a file's text (depth, aliases, numbers, tags), as plain
    dicts, lists and scalars; ValueError naming ``where`` for anything else."""
    try:
        return _plain(load_yaml(text))
    except YamlSourceError as exc:
        raise ValueError(f"{where}: {exc.message}" + (f" (hint: {exc.hint})" if exc.hint else "")) from None


def _plain(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


class _Lines:
    """Line numbers of a text's marks counted at its newlines only: YAML also breaks lines at
    NEL, LS and PS (U+0085, U+2028, U+2029), which editors do not, so its own line numbers
    would drift past such a character."""

    def __init__(self, text: str):
        self.newlines: list[int] | None = None
        if any(c in text for c in "\x85\u2028\u2029"):
            self.newlines = [i for i, c in enumerate(text) if c == "\n"]

    def of(self, mark: Any) -> int | None:
        if mark is None:
            return None
        if self.newlines is None or getattr(mark, "index", None) is None:
            return mark.line + 1
        return bisect.bisect_left(self.newlines, mark.index) + 1


def _position(text: str, index: int) -> tuple[int, int]:
    """1-based (line, column) of ``text[index]``."""
    return text.count("\n", 0, index) + 1, index - (text.rfind("\n", 0, index) + 1) + 1


def _check_depth(text: str, lines: _Lines) -> None:
    """Refuse nesting deeper than MAX_YAML_DEPTH, from the parser's events (no recursion),
    stopping at the first level too deep."""
    depth = 0
    for event in yaml.parse(text, Loader=_Loader):
        if isinstance(event, yaml.CollectionStartEvent):
            depth += 1
            if depth > MAX_YAML_DEPTH:
                raise YamlSourceError(f"YAML lists and mappings nested deeper than {MAX_YAML_DEPTH} levels",
                                      lines.of(event.start_mark), "a diagram needs about 8 levels")
        elif isinstance(event, yaml.CollectionEndEvent):
            depth -= 1


class _Builder:
    """Builds LineDict/LineList/scalars from a composed node tree.

    An alias is the very node of its anchor, so a node met a second time is a repetition:
    those are counted against MAX_ALIAS_VALUES, and the nesting they add against
    MAX_YAML_DEPTH. ``site`` is the line where the value being built is written (for a
    repetition, where the alias that repeats it is).
    """

    def __init__(self, loader: yaml.SafeLoader, lines: _Lines):
        self.loader = loader
        self.lines = lines
        self.active: set[int] = set()
        self.seen: set[int] = set()
        self.repeated = 0

    def build(self, node: yaml.Node, depth: int, site: int) -> Any:
        line = self.lines.of(node.start_mark)
        fresh = id(node) not in self.seen
        if not fresh:
            self.repeated += 1
            if self.repeated > MAX_ALIAS_VALUES:
                raise YamlSourceError(f"YAML aliases repeat more than {MAX_ALIAS_VALUES} values", site,
                                      "an alias (*name) copies its anchor's whole value; nested aliases "
                                      "multiply: write the values out or use fewer levels of aliases")
        else:
            self.seen.add(id(node))
            site = line
        if isinstance(node, yaml.ScalarNode):
            return self.scalar(node, line)
        if depth > MAX_YAML_DEPTH:
            raise YamlSourceError(f"YAML lists and mappings nested deeper than {MAX_YAML_DEPTH} levels "
                                  "through aliases", site, "a diagram needs about 8 levels")
        if id(node) in self.active:
            raise YamlSourceError("recursive YAML alias", line)
        if node.tag not in (_SEQ_TAG, _MAP_TAG):
            raise YamlSourceError(f"unsupported YAML tag {node.tag!r}", line)
        self.active.add(id(node))
        try:
            if isinstance(node, yaml.SequenceNode):
                out = LineList(self.build(item, depth + 1, site) for item in node.value)
                out.line = line
                out.item_lines = [self.lines.of(item.start_mark) for item in node.value]
                return out
            return self.mapping(node, depth, site, fresh)
        finally:
            self.active.discard(id(node))

    def scalar(self, node: yaml.ScalarNode, line: int) -> Any:
        """A plain value: text, a number of at most MAX_NUMBER_CHARS characters (Python
        refuses to read integers of over 4300 digits, and no parameter needs more than 17
        significant digits), a boolean or null; a date stays the text it is written as.
        Other tags (``!!binary``, ``!!set``, ...) and text that is not what its tag says
        (``!!float garbage``) are refused at their line."""
        tag = node.tag
        if tag == _TIMESTAMP_TAG:
            return node.value
        if tag not in _SCALAR_TAGS:
            raise YamlSourceError(f"unsupported YAML tag {tag!r}", line,
                                  "values are text, numbers, true/false or null")
        if tag in _NUMBER_TAGS and len(node.value) > MAX_NUMBER_CHARS:
            raise YamlSourceError(f"a number written with {len(node.value)} characters (at most "
                                  f"{MAX_NUMBER_CHARS})", line, "a float64 holds 17 significant digits; "
                                  "write the value in exponent form, e.g. 1.5e300")
        try:
            return self.loader.construct_object(node, deep=True)
        except (ValueError, KeyError, AttributeError, TypeError, OverflowError, yaml.YAMLError):
            kind = _NUMBER_TAGS.get(tag, "true or false" if tag.endswith(":bool") else "null")
            raise YamlSourceError(f"{reprlib.repr(node.value)} is not {kind}, as its tag "
                                  f"{tag.rsplit(':', 1)[-1]!r} says", line,
                                  "remove the tag or write a value of that kind") from None

    def mapping(self, node: yaml.MappingNode, depth: int, site: int, fresh: bool) -> "LineDict":
        """A mapping; merge keys (``<<: *base`` or ``<<: [*a, *b]``) give the keys it does not
        write itself, an earlier merged mapping winning over a later one. A merged mapping
        counts as a level of nesting, as it is built inside this one (so a chain of merges
        stays within the recursion limit). In a mapping met for the first time a value is
        written at its key's line, in a repetition at ``site``."""
        merged: dict[Any, tuple[Any, int]] = {}
        out = LineDict()
        out.line = self.lines.of(node.start_mark)
        out.key_lines = {}
        for key_node, value_node in node.value:
            key_line = self.lines.of(key_node.start_mark)
            if key_node.tag == _MERGE_TAG:
                for source in self.merge_sources(value_node, key_line):
                    built = self.build(source, depth + 1, key_line if fresh else site)
                    for key, value in built.items():
                        merged.setdefault(key, (value, built.line_of(key)))
                continue
            key = self.build(key_node, depth + 1, site)
            try:
                hash(key)
            except TypeError:
                raise YamlSourceError("a mapping key must be a plain value, not a list or mapping",
                                      key_line) from None
            if key in out:
                raise YamlSourceError(f"duplicate key {key!r} (first at line {out.key_lines[key]})", key_line)
            out[key] = self.build(value_node, depth + 1, key_line if fresh else site)
            out.key_lines[key] = key_line
        if not merged:
            return out
        full = LineDict()
        full.line = out.line
        full.key_lines = {}
        for key, (value, line) in merged.items():
            if key not in out:
                full[key], full.key_lines[key] = value, line
        full.update(out)
        full.key_lines.update(out.key_lines)
        return full

    @staticmethod
    def merge_sources(node: yaml.Node, line: int) -> list[yaml.MappingNode]:
        sources = node.value if isinstance(node, yaml.SequenceNode) else [node]
        if not all(isinstance(s, yaml.MappingNode) for s in sources):
            raise YamlSourceError("a merge key '<<' takes a mapping or a list of mappings", line)
        return sources
