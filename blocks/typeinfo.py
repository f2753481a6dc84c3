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
from typing import Any, NamedTuple

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


class ParamInfo(NamedTuple):
    """A parameter as documentation and the diagram file's schema show it."""

    name: str
    type: str
    """The numpydoc type text (may be empty)."""
    text: str
    default: Any
    """The signature's default, or ``REQUIRED``."""
    block_reference: bool
    """True when the value names another block of the diagram."""


class PortInfo(NamedTuple):
    """A port of a block's example instance: its width (None: inferred), units and element
    names (None where the block gives none), and whether an input is optional."""

    name: str
    width: int | None
    units: str | list[str] | None
    labels: list[str] | None
    optional: bool = False


class TypeInfo(NamedTuple):
    """A block type described for people and tools: ``hierhand blocks``, the generated
    block reference and the diagram file's JSON Schema all read this one record."""

    name: str
    qualname: str
    summary: str
    parameters: list[ParamInfo]
    any_parameter: bool
    """True when the block takes any parameter (``**kwargs``)."""
    inputs: list[PortInfo] | None
    """None: the ports depend on the parameters, or on a block the type needs (``ports_note``)."""
    outputs: list[PortInfo] | None
    ports_note: str
    feedthrough: str
    initial_feedthrough: str | None
    time_varying: bool


REQUIRED = inspect.Parameter.empty
"""The default of a required parameter."""


def type_info(cls: type[Block]) -> TypeInfo:
    """The record of ``cls``: parameters from the signature and the numpydoc section, ports
    and feedthrough from its example instance (``Block.example``)."""
    params = cls.parameters()
    docs = parameter_docs(cls)
    parameters = [ParamInfo(name, docs[name].type if name in docs else "", docs[name].text if name in docs else "",
                            p.default, name in cls.block_params) for name, p in params.items()]
    inputs = outputs = None
    note = feedthrough = ""
    initial = None
    try:
        block = cls.example()
    except Exception:
        needs = [n for n in cls.block_params if n in params and params[n].default is params[n].empty]
        note = (f"see 'hierhand validate' of a diagram using it (it needs the block named by {', '.join(needs)})"
                if needs else "depend on the parameters")
    else:
        inputs = [_port_info(block, p, w, p in block.input_defaults) for p, w in block.inputs.items()]
        outputs = [_port_info(block, p, w) for p, w in block.outputs.items()]
        feedthrough = _feedthrough(block.feedthrough)
        if block.initial_feedthrough is not None:
            initial = _feedthrough(block.initial_feedthrough)
    return TypeInfo(cls.registered_name(), f"{cls.__module__}.{cls.__qualname__}", summary(cls), parameters,
                    cls.accepts_any_parameter(), inputs, outputs, note, feedthrough, initial, cls.time_varying)


def _port_info(block: Block, port: str, width: int | None, optional: bool = False) -> PortInfo:
    """A port's record; units and labels that the example cannot give are left out."""
    try:
        units = checked_units(block.port_units(port), width, port)
        labels = block.element_labels(port)
    except Exception:  # a block whose example cannot say: the port bare
        return PortInfo(port, width, None, None, optional)
    labels = [str(x) for x in labels] if labels is not None and (width is None or len(labels) == width) else None
    return PortInfo(port, width, units, labels, optional)


def describe_type(cls: type[Block]) -> str:
    """Text for ``hierhand blocks``: name, summary, parameters with defaults, ports."""
    info = type_info(cls)
    lines = [f"{info.name}  ({info.qualname})"]
    if info.summary:
        lines.append(f"  {info.summary}")
    if info.parameters:
        lines.append("  parameters:")
        for p in info.parameters:
            notes = [p.type] if p.type else []
            notes.append("required" if p.default is REQUIRED else f"default {p.default!r}")
            if p.block_reference:
                notes.append("the name of another block of the diagram")
            lines.append(f"    {p.name} ({'; '.join(notes)})" + (f": {p.text}" if p.text else ""))
    if info.inputs is None:
        lines.append(f"  ports: {info.ports_note}")
    else:
        def shown(port: PortInfo) -> str:
            return f"{port.name}[{'n' if port.width is None else port.width}]"

        optional = [p.name for p in info.inputs if p.optional]
        optional_text = f" (optional: {', '.join(optional)})" if optional else ""
        details = {p.name: port_details(p) for p in (*info.inputs, *info.outputs)}
        if any(details.values()):  # a port per line, with its unit and elements
            pad = max(len(shown(p)) for p in (*info.inputs, *info.outputs))
            for what, ports, extra in (("inputs", info.inputs, optional_text), ("outputs", info.outputs, "")):
                lines.append(f"  {what}{extra}:" if ports else f"  {what}: none")
                lines += [f"    {shown(p):<{pad}}  {details[p.name]}".rstrip() for p in ports]
        else:
            lines.append(f"  inputs: {', '.join(map(shown, info.inputs)) or 'none'}{optional_text}")
            lines.append(f"  outputs: {', '.join(map(shown, info.outputs)) or 'none'}")
        lines.append(f"  feedthrough: {info.feedthrough}")
        if info.initial_feedthrough is not None:
            lines.append(f"  feedthrough at t = 0: {info.initial_feedthrough}")
    if info.time_varying:
        lines.append("  time-varying source: needs a period")
    return "\n".join(lines)


def unit_text(unit: str) -> str:
    """A unit as people read it: ``1`` (a ratio, a flag) as "1 (dimensionless)"."""
    return "1 (dimensionless)" if unit == "1" else unit


def port_details(port: PortInfo) -> str:
    """A port's unit and element names, "rad; elements thumb.1, thumb.2, ..." (each element
    with its own unit where they differ: "x (m), y (m), theta (rad)"); "" if it has neither."""
    units, labels = port.units, port.labels
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
