"""Human-readable description of a block type: summary, parameters and ports."""

from __future__ import annotations

import inspect

from .block import Block
from .paramdocs import parameter_docs


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
        lines.append(f"  inputs: {ports(block.inputs)}{optional}")
        lines.append(f"  outputs: {ports(block.outputs)}")
        lines.append(f"  feedthrough: {_feedthrough(block.feedthrough)}")
        if block.initial_feedthrough is not None:
            lines.append(f"  feedthrough at t = 0: {_feedthrough(block.initial_feedthrough)}")
    if cls.time_varying:
        lines.append("  time-varying source: needs a period")
    return "\n".join(lines)


def _feedthrough(ft) -> str:
    """A feedthrough declaration (``True``, ``False`` or output -> inputs) as text."""
    if ft is True:
        return "yes"
    if ft is False:
        return "no"
    return "; ".join(f"{o} <- {', '.join(sorted(i)) or 'none'}" for o, i in ft.items())
