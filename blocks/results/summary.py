"""A run's results at a glance: its status and a table of its signals, as text (``repr``)
and as HTML (what Jupyter shows for a ``Results``)."""

from __future__ import annotations

import html
from typing import Any

import numpy as np

COLUMNS = ("signal", "width", "samples", "time", "unit")


def heading(results: Any) -> str:
    """'toy-multirate: complete, t_end 1 s, 1 signal' (the diagram's name, if known)."""
    info = results.info
    parts = [results.status]
    if info.get("t_end") is not None:
        parts.append(f"t_end {info['t_end']:g} s")
    if info.get("wall_time_s") is not None:
        parts.append(f"wall {info['wall_time_s']:.3g} s")
    count = len(results.signals)
    parts.append(f"{count} signal{'' if count == 1 else 's'}")
    name = info.get("diagram")
    return (f"{name}: " if name else "") + ", ".join(parts)


def rows(results: Any) -> list[tuple[str, str, str, str, str]]:
    """One row per signal: name, width, samples, the span of its times, its unit(s)."""
    out = []
    for name, (t, v) in results.signals.items():
        span = f"{t[0]:g} to {t[-1]:g} s" if len(t) else "-"
        units = results.units(name)
        unit = results.unit(name) or (", ".join(u or "?" for u in units) if units else "")
        out.append((name, str(np.shape(v)[1]), str(len(t)), span, unit))
    return out


def as_text(results: Any) -> str:
    """The heading and the table, aligned columns, for ``repr``."""
    table = rows(results)
    lines = [f"<Results {heading(results)}>"]
    if table:
        widths = [max(len(c), *(len(r[i]) for r in table)) for i, c in enumerate(COLUMNS)]
        for row in [COLUMNS, *table]:
            lines.append("  " + "  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip())
    return "\n".join(lines)


def as_html(results: Any) -> str:
    """The heading and the table as HTML."""
    head = "".join(f"<th>{c}</th>" for c in COLUMNS)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(cell)}</td>" for cell in row) + "</tr>"
                   for row in rows(results))
    return (f"<div><p><b>Results</b> {html.escape(heading(results))}</p>"
            f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table></div>")
