"""What an axis of a signal plot draws, before matplotlib sees it: its step curves (held to
the run's end, thinned to what each pixel column shows), their styles and legend labels,
a failed run's last samples, the axis's label with its unit, and the ranges of both axes.

Kept apart from the drawing (``blocks.plot.figure``) so that what a page shows is decided
in one place, in plain numbers, and tests can read it without drawing.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from blocks.plot.select import Trace

STOP_MARGIN = 0.02
"""Of the time span, drawn past where a failed or interrupted run stopped, so that its mark shows."""

MARGIN = 0.05
"""Of the data's span, added each side of a value axis."""


@dataclass
class Curve:
    """A drawn line: samples ``t``, ``v`` held after each (a step curve), its ``style``
    (``line_styles``) and its legend ``label`` (None: not in the legend)."""

    t: np.ndarray
    v: np.ndarray
    style: dict
    label: str | None


@dataclass
class Axis:
    """What one axis draws: its ``curves``, a failed or interrupted run's last sample of
    each element (``dots``: (time, values) per signal), the units of its lines and its
    name (the selections it shows)."""

    curves: list[Curve]
    dots: list[tuple[float, np.ndarray]]
    units: list[str]
    name: str

    @property
    def legend(self) -> list[Curve]:
        return [c for c in self.curves if c.label is not None]

    def ylim(self) -> tuple[float, float]:
        values = np.concatenate([c.v for c in self.curves]) if self.curves else np.empty(0)
        return data_range(values)


def axis_of(results: Any, traces: list[Trace], end: float | None, stop: float | None, columns: int) -> Axis:
    """The axis of ``traces``: each element a curve held to ``end`` and thinned to ``columns``
    pixel columns (``envelope``), labelled for a legend (``legend_labels``)."""
    labels = legend_labels(results, traces)
    overlaid = len(traces) > 1
    if overlaid:
        styles = line_styles([f"{tr.signal}[{label}]" for tr in traces for label in tr.labels])
    curves, dots, units, drawn = [], [], [], 0
    for tr in traces:
        t, v = results[tr.signal]
        v = v[:, list(tr.columns)]
        if stop is not None and len(t):
            dots.append((float(t[-1]), v[-1].astype(float)))
        if end is not None and len(t) and t[-1] < end:
            t, v = np.append(t, end), np.vstack([v, v[-1:]])
        t, v = envelope(t, v, columns)
        width = v.shape[1]
        units += element_units(results, tr) or []
        trace_styles = styles[drawn:drawn + width] if overlaid else line_styles(list(tr.labels))
        for j in range(width):
            curves.append(Curve(t, v[:, j], trace_styles[j], labels[drawn + j]))
        drawn += width
    return Axis(curves, dots, units, ", ".join(tr.title for tr in traces))


def legend_labels(results: Any, traces: list[Trace]) -> list[str | None]:
    """The legend label of each line of an axis (None: unlabelled): the elements' names
    for one signal (none for a single element), ``signal[element]`` for overlaid ones,
    each with its unit where they differ."""
    overlaid = len(traces) > 1
    labels = []
    for tr in traces:
        units = element_units(results, tr)
        mixed = units is not None and len(set(units)) > 1
        width = len(tr.columns)
        for j in range(width):
            unit = f" ({units[j] or '?'})" if mixed else ""
            if overlaid:
                labels.append((tr.title if width == 1 else f"{tr.signal}[{tr.labels[j]}]") + unit)
            else:
                labels.append(tr.labels[j] + unit if width > 1 else None)
    return labels


def element_units(results: Any, trace: Trace) -> list[str] | None:
    """The units of a trace's elements (None: its block gave none)."""
    units = results.units(trace.signal)
    return None if units is None else [units[c] for c in trace.columns]


def envelope(t: np.ndarray, v: np.ndarray, columns: int) -> tuple[np.ndarray, np.ndarray]:
    """Samples ``(t, v)`` (held after each) thinned for a plot ``columns`` pixels wide to
    what draws the same picture: in each pixel column its first value, its least and its
    greatest at the column's first time, and its last value at its last time, so every
    excursion still shows and the value held into the next column is the last one. Fewer
    samples than four per column are returned as they are."""
    if len(t) <= 4 * columns or t[-1] <= t[0]:
        return t, v
    bucket = np.minimum(((t - t[0]) / (t[-1] - t[0]) * columns).astype(np.int64), columns - 1)
    starts = np.flatnonzero(np.r_[True, bucket[1:] != bucket[:-1]])
    lasts = np.r_[starts[1:] - 1, len(t) - 1]
    low, high = np.minimum.reduceat(v, starts, axis=0), np.maximum.reduceat(v, starts, axis=0)
    times = np.column_stack([t[starts], t[starts], t[starts], t[lasts]]).ravel()
    values = np.stack([v[starts], low, high, v[lasts]], axis=1).reshape(-1, v.shape[1])
    return times, values


def axis_label(name: str, units: Sequence[str] | None) -> str:
    """'name' over '(unit)': the shared unit, the distinct ones where elements differ, and
    '(dimensionless)' for ``1``; the name alone when the block gave no units."""
    if not units:
        return name
    distinct = list(dict.fromkeys(u or "?" for u in units))
    text = "dimensionless" if distinct == ["1"] else ", ".join(distinct)
    return f"{name}\n({text})"


LINE_STYLES = ("-", "--", ":", "-.")


def line_styles(labels: Sequence[str]) -> list[dict]:
    """Colour, line style and width per element: for labels ``group.member`` (``thumb.1``,
    ``fore.x``) with at most 10 groups of at most 4 members, a colour per group and a
    style per member; otherwise the colour cycle (solid, then dashed past 10). Earlier
    colours draw wider, so that a line another one covers (two fingers both in contact)
    still shows at its edges."""
    parts = [label.split(".", 1) for label in labels]
    if len(labels) > 1 and all(len(p) == 2 for p in parts):
        groups = list(dict.fromkeys(p[0] for p in parts))
        members = list(dict.fromkeys(p[1] for p in parts))
        if 1 < len(groups) <= 10 and len(members) <= len(LINE_STYLES):
            return [{"color": f"C{groups.index(g)}", "ls": LINE_STYLES[members.index(m)],
                     "lw": _width(groups.index(g), len(groups))} for g, m in parts]
    n = min(len(labels), 10)
    return [{"color": f"C{j % 10}", "ls": LINE_STYLES[(j // 10) % len(LINE_STYLES)], "lw": _width(j % 10, n)}
            for j in range(len(labels))]


def _width(k: int, n: int) -> float:
    """Line width of colour ``k`` of ``n``: from 2.2 for the first down to 1.0 for the last."""
    return 1.1 if n <= 1 else 2.2 - 1.2 * k / (n - 1)


def time_span(results: Any) -> tuple[float | None, float | None]:
    """(the time the plots reach, the time a failed or interrupted run stopped or None).

    A complete run reaches its t_end, or where a block ended it; an incomplete one where it
    stopped (its last sample when its run.json does not say), never its t_end: its signals
    were not held that far."""
    stop = results.stop_time
    if results.complete:
        return (results.info.get("t_end") if stop is None else stop), None
    if stop is None:
        stop = max((float(t[-1]) for t, _ in results.signals.values() if len(t)), default=None)
    return stop, stop


def time_limits(results: Any, axes_traces: list[list[Trace]], end: float | None,
                stop: float | None) -> tuple[float, float]:
    """The time axis: from the first sample to the end time (a little past a stop, so that
    its line and dots show), or the samples' span where the run gives no end."""
    firsts = [float(results[tr.signal][0][0]) for traces in axes_traces for tr in traces
              if len(results[tr.signal][0])]
    start = min(firsts, default=0.0)
    if end is not None and end > start:
        return start, end + (STOP_MARGIN * (end - start) if stop is not None else 0.0)
    times = np.concatenate([results[tr.signal][0] for traces in axes_traces for tr in traces] or [np.empty(0)])
    return data_range(times)


LARGEST = 1e306
"""The largest magnitude a value axis reaches: matplotlib's transforms and tick locator
overflow for a span within a few hundred times the largest double (1.8e308). Values
beyond it (a diverged run's) run off the axis's edge."""


def data_range(values: np.ndarray, margin: float = MARGIN) -> tuple[float, float]:
    """The span of the finite ``values`` widened by ``margin`` each side; a single value
    gets a span around it, and no finite value (0, 1). The range lies within +-LARGEST."""
    finite = np.clip(values[np.isfinite(values)], -LARGEST, LARGEST)
    if finite.size == 0:
        return 0.0, 1.0
    lo, hi = float(finite.min()), float(finite.max())
    if hi - lo <= 1e-12 * max(1.0, abs(lo), abs(hi)):
        pad = 0.05 * abs(lo) if lo != 0 else 0.05
        lo, hi = lo - pad, hi + pad
    pad = margin * (hi - lo)
    lo, hi = max(lo - pad, -LARGEST), min(hi + pad, LARGEST)
    return (lo, hi) if lo < hi else (hi - 0.1 * abs(hi), hi)
