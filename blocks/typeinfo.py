"""A block type described for people: its summary, its parameters and its ports.

``describe_type`` is the text of ``hierhand blocks``. A block documents its parameters where Python readers look, in a numpydoc section of its
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

from blocks.block import Block, checked_units

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





def summary(cls: type[Block]) -> str:
    """The first paragraph of the class docstring, on one line."""
    doc = inspect.getdoc(cls) or ""
    return " ".join(doc.split("\n\n")[0].split())


def describe_type(cls: type[Block]) -> str:
    """Text for ``hierhand blocks``: name, summary, parameters with defaults, ports."""
    lines = [f"{cls.registered_name()}  ({cls.__module__}.{cls.__qualname__})"]
    if summary(cls):
        lines.append(f"  {summary(cls)}")
    params = cls.parameters()
    docs = parameter_docs(cls)
    if params:
        lines.append("  parameters:")
        for name, p in params.items():
            doc = docs.get(name)
            notes = [doc.type] if doc is not None and doc.type else []
            notes.append("required" if p.default is p.empty else f"default {p.default!r}")
            if name in cls.block_params:
                notes.append("the name of another block of the diagram")
            lines.append(f"    {name} ({'; '.join(notes)})" + (f": {doc.text}" if doc is not None and doc.text else ""))
    try:
        block = cls.example()
    except Exception:
        needs = [n for n in cls.block_params if n in params and params[n].default is params[n].empty]
        lines.append(f"  ports: see 'hierhand validate' of a diagram using it (it needs the block named by "
                     f"{', '.join(needs)})" if needs else "  ports: depend on the parameters")
    else:
        def ports(d: dict) -> str:
            return ", ".join(f"{p}[{'n' if w is None else w}]" for p, w in d.items()) or "none"

        optional = f" (optional: {', '.join(block.input_defaults)})" if block.input_defaults else ""
        details = {p: _port_details(block, p, w) for p, w in (*block.inputs.items(), *block.outputs.items())}
        if any(details.values()):  # a port per line, with its unit and elements
            shown = {p: f"{p}[{'n' if w is None else w}]" for p, w in (*block.inputs.items(), *block.outputs.items())}
            pad = max(map(len, shown.values()))
            for what, d, extra in (("inputs", block.inputs, optional), ("outputs", block.outputs, "")):
                lines.append(f"  {what}{extra}:" if d else f"  {what}: none")
                lines += [f"    {shown[p]:<{pad}}  {details[p]}".rstrip() for p in d]
        else:
            lines.append(f"  inputs: {ports(block.inputs)}{optional}")
            lines.append(f"  outputs: {ports(block.outputs)}")
        lines.append(f"  feedthrough: {_feedthrough(block.feedthrough)}")
        if block.initial_feedthrough is not None:
            lines.append(f"  feedthrough at t = 0: {_feedthrough(block.initial_feedthrough)}")
    if cls.time_varying:
        lines.append("  time-varying source: needs a period")
    return "\n".join(lines)


def unit_text(unit: str) -> str:
    """A unit as people read it: ``1`` (a ratio, a flag) as "1 (dimensionless)"."""
    return "1 (dimensionless)" if unit == "1" else unit


def _port_details(block: Block, port: str, width: int | None) -> str:
    """A port's unit and element names, "rad; elements thumb.1, thumb.2, ..." (each element
    with its own unit where they differ: "x (m), y (m), theta (rad)"); "" if it has neither."""
    try:
        units = checked_units(block.port_units(port), width, port)
        labels = block.element_labels(port)
    except Exception:  # a block whose example cannot say: list the port bare
        return ""
    labels = [str(x) for x in labels] if labels is not None and (width is None or len(labels) == width) else None
    if isinstance(units, list):
        names = labels or [f"[{i}]" for i in range(len(units))]
        return ", ".join(f"{n} ({u or 'unit unknown'})" for n, u in zip(names, units))
    parts = [unit_text(units)] if units else []
    if labels:
        parts.append("elements " + ", ".join(labels))
    return "; ".join(parts)


def _feedthrough(ft) -> str:
    """A feedthrough declaration (``True``, ``False`` or output -> inputs) as text."""
    if ft is True:
        return "yes"
    if ft is False:
        return "no"
    return "; ".join(f"{o} <- {', '.join(sorted(i)) or 'none'}" for o, i in ft.items())
