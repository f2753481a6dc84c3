"""YAML safe loading that remembers where every mapping key and list item was written.

Diagram errors must say ``file:line``; PyYAML forgets positions once it builds Python
objects, so this module builds them itself from the node tree and keeps the line of
each key and item beside the value. It also rejects duplicate keys, which PyYAML
silently collapses.
"""

from __future__ import annotations

from typing import Any

import yaml


_Loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
"""libyaml's parser when PyYAML was built with it (about 10x faster), else pure Python."""


_SEQ_TAG = "tag:yaml.org,2002:seq"
_MAP_TAG = "tag:yaml.org,2002:map"


class YamlSourceError(Exception):
    """A YAML text that cannot be read; ``line`` is 1-based, or None when unknown."""

    def __init__(self, message: str, line: int | None):
        super().__init__(message)
        self.message = message
        self.line = line


class LineDict(dict):
    """A mapping from YAML with ``line`` (of the mapping) and ``key_lines`` (per key)."""

    line: int = 0
    key_lines: dict

    def line_of(self, key: Any) -> int:
        return self.key_lines.get(key, self.line)


class LineList(list):
    """A sequence from YAML with ``line`` (of the sequence) and ``item_lines``."""

    line: int = 0
    item_lines: list

    def line_of(self, index: int) -> int:
        return self.item_lines[index] if 0 <= index < len(self.item_lines) else self.line


def line_of(container: Any, key: Any, default: int = 0) -> int:
    """Line of ``key`` inside a LineDict/LineList, or ``default`` for plain containers."""
    if isinstance(container, (LineDict, LineList)):
        return container.line_of(key)
    return getattr(container, "line", default) or default


def load_yaml(text: str) -> Any:
    """Parse one YAML document into LineDict/LineList/scalars; None for an empty text."""
    loader = _Loader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        return _build(loader, node, set())
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        problem = exc.problem or exc.context or "invalid YAML"
        raise YamlSourceError(f"YAML syntax error: {problem}", mark.line + 1 if mark else None) from None
    except yaml.YAMLError as exc:
        raise YamlSourceError(f"YAML error: {exc}", None) from None
    except RecursionError:
        raise YamlSourceError("YAML nesting too deep", None) from None
    finally:
        loader.dispose()


def _build(loader: yaml.SafeLoader, node: yaml.Node, active: set[int]) -> Any:
    line = node.start_mark.line + 1
    if isinstance(node, yaml.ScalarNode):
        return loader.construct_object(node, deep=True)
    if id(node) in active:
        raise YamlSourceError("recursive YAML alias", line)
    active.add(id(node))
    try:
        if node.tag not in (_SEQ_TAG, _MAP_TAG):
            raise YamlSourceError(f"unsupported YAML tag {node.tag!r}", line)
        if isinstance(node, yaml.SequenceNode):
            out = LineList(_build(loader, item, active) for item in node.value)
            out.line = line
            out.item_lines = [item.start_mark.line + 1 for item in node.value]
            return out
        if isinstance(node, yaml.MappingNode):
            loader.flatten_mapping(node)
            out = LineDict()
            out.line = line
            out.key_lines = {}
            for key_node, value_node in node.value:
                key_line = key_node.start_mark.line + 1
                key = _build(loader, key_node, active)
                try:
                    hash(key)
                except TypeError:
                    raise YamlSourceError("a mapping key must be a plain value, not a list or mapping",
                                          key_line) from None
                if key in out:
                    raise YamlSourceError(
                        f"duplicate key {key!r} (first at line {out.key_lines[key]})", key_line)
                out[key] = _build(loader, value_node, active)
                out.key_lines[key] = key_line
            return out
    finally:
        active.discard(id(node))
    raise YamlSourceError(f"unsupported YAML node {node.tag}", line)
