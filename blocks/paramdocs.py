"""Block parameter documentation from one source: the class docstring's ``Parameters``.

A block documents its parameters where Python readers look, in a numpydoc section of its
class docstring::

    class Gain(Block):
        '''Multiplies the input by ``k``.

        Parameters
        ----------
        k : scalar, vector or matrix
            The gain; a matrix maps between widths (y = K @ u).
        '''

``parameter_docs`` reads that section (a small reader, no docstring library) for
``hierhand blocks``; the defaults come from the signature of ``__init__``, so the
docstring does not repeat them. A mixin may document a parameter its blocks share.
"""

from __future__ import annotations

import inspect
import re
from typing import NamedTuple

SECTION = "Parameters"
_UNDERLINE = re.compile(r"^-{3,}$")
_ENTRY = re.compile(r"^(?P<names>\*{0,2}\w+(?:\s*,\s*\*{0,2}\w+)*)\s*(?::\s*(?P<type>.*))?$")


class ParamDoc(NamedTuple):
    """A parameter's documented type (may be empty) and description, each on one line."""

    type: str
    text: str


def parse_parameters(doc: str | None) -> dict[str, ParamDoc]:
    """The entries of the numpydoc ``Parameters`` section of ``doc``, in order.

    An entry is a line ``name : type`` (or ``name``, or ``a, b : type``) at the section's
    indentation, followed by its description indented further; the section ends at the
    next section heading (a line underlined with dashes), a line less indented, or a line
    at its indentation that is no entry. Descriptions are joined into one line.
    """
    lines = inspect.cleandoc(doc or "").splitlines()
    start = _heading(lines, SECTION)
    if start is None:
        return {}
    indent = _indent(lines[start])
    found: dict[str, list] = {}
    current: list[list] = []
    for i in range(start + 2, len(lines)):
        line = lines[i]
        if not line.strip():
            continue
        if _is_heading(lines, i) or _indent(line) < indent:
            break
        if _indent(line) > indent:
            for entry in current:
                entry[1].append(line.strip())
            continue
        match = _ENTRY.match(line.strip())
        if match is None:
            break
        kind = (match.group("type") or "").strip()
        current = [[kind, []] for _ in match.group("names").split(",")]
        for name, entry in zip(match.group("names").split(","), current):
            found[name.strip().lstrip("*")] = entry
    return {name: ParamDoc(kind, " ".join(words)) for name, (kind, words) in found.items()}


def parameter_docs(cls: type) -> dict[str, ParamDoc]:
    """The documented parameters of a block class: the ``Parameters`` section of each
    class of its MRO, the nearest class first (so a subclass or a block using a mixin
    documents only what it adds or changes)."""
    docs: dict[str, ParamDoc] = {}
    for klass in cls.__mro__:
        for name, doc in parse_parameters(vars(klass).get("__doc__")).items():
            docs.setdefault(name, doc)
    return docs


def _heading(lines: list[str], title: str) -> int | None:
    """The index of the section heading ``title`` (underlined with dashes), if any."""
    for i in range(len(lines) - 1):
        if lines[i].strip() == title and _is_heading(lines, i):
            return i
    return None


def _is_heading(lines: list[str], i: int) -> bool:
    return i + 1 < len(lines) and bool(lines[i].strip()) and bool(_UNDERLINE.match(lines[i + 1].strip()))


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())
