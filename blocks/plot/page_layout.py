"""One page of a signal plot laid out: its panels (one axis each) in pixels, what each
draws (step curves, legend, ticks, labels, a failed run's stop and last samples) and the
diagram's events, before anything is painted (``blocks.plot.paint``).

The layout follows the data and the text it has to show: margins in inches for the
labels and the title, the right margin as wide as the widest legend (measured in the
page's font), the time axis spanning the data, each value axis the data's span with a
margin. What a page shows is decided here once; tests read it from here, and the painter
only turns it into pixels.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from blocks.plot.canvas import DPI, fit, points, text_size
from blocks.plot.markers import Marker
from blocks.plot.select import Trace, select
from blocks.plot.ticks import Ticks, data_range, ticks
from blocks.results.signals import Results

FIGURE_WIDTH = 11.0
AXES_HEIGHT = 2.3
TITLE_LINES = 2     # at most, of the title
NOTE_LINES = 3      # at most, of the status or end note under it
LABEL_LINES = 2     # at most, of an axis label's name (its unit takes one more)
LEGEND_WIDTH = 3.0  # inches, at most, of a legend's text (of each column's, over its columns)
STOP_MARGIN = 0.02
LEFT = 1.25         # inches left of the axes: tick labels and a two-line axis label
BOTTOM = 0.55       # below the last axis: its tick labels and the time label
TITLE_LINE = 0.24   # per line of the page's title
GAP = 0.3           # between two axes
MAX_LEGEND = 24
LEGEND_ROWS = 12
LEGEND_HANDLE = 2.5  # em: a legend entry's line sample
LEGEND_PAD = 0.8     # em: between the sample and the text
LEGEND_COLUMN = 1.5  # em: between two columns
LEGEND_PITCH = 1.45  # em: from one entry to the next

SIZE = 10.0          # points: tick labels, axis labels
SMALL = 8.33         # legends, the stop's word
X_SMALL = 6.94       # markers' names
LARGE = 12.0         # the page's title
TICK_LENGTH = 3.5    # points
TICK_PAD = 3.5       # points, between a tick and its label
LABEL_PAD = 4.0      # points, between the tick labels and the axis label
Y_TICK_SPACING = 30  # pixels between two y ticks, at least about
X_TICK_SPACING = 120  # pixels between two time ticks, at least about


@dataclass
class Curve:
    """A drawn line: samples ``t``, ``v`` held after each (a step curve), its style
    (``blocks.plot.pages.line_styles``) and its legend label (None: not in the legend)."""

    t: np.ndarray
    v: np.ndarray
    style: dict
    label: str | None


@dataclass
class Panel:
    """An axis: its ``box`` (x0, y0, x1, y1 in pixels), its data limits and ticks, what it
    draws, and its legend (``legend_box`` in pixels; None without a legend)."""

    box: tuple[float, float, float, float]
    xlim: tuple[float, float]
    ylim: tuple[float, float]
    xticks: Ticks
    yticks: Ticks
    ylabel: str
    curves: list[Curve]
    legend: list[Curve] = field(default_factory=list)
    legend_columns: int = 1
    legend_box: tuple[float, float, float, float] | None = None
    dots: list[tuple[float, np.ndarray]] = field(default_factory=list)
    """A failed or interrupted run's last sample of each element: (time, values)."""
    time_labels: bool = False
    """Whether this panel labels the time axis (the bottom one)."""

    def to_pixels(self, t, v) -> tuple[np.ndarray, np.ndarray]:
        """Data coordinates to page pixels (in halves, so that limits near the largest
        double do not overflow)."""
        x0, y0, x1, y1 = self.box
        (a, b), (lo, hi) = self.xlim, self.ylim
        x = x0 + (np.asarray(t, dtype=float) / 2 - a / 2) * ((x1 - x0) / (b / 2 - a / 2))
        y = y1 - (np.asarray(v, dtype=float) / 2 - lo / 2) * ((y1 - y0) / (hi / 2 - lo / 2))
        return x, y

    @property
    def legend_labels(self) -> list[str]:
        return [c.label for c in self.legend]


@dataclass
class Page:
    """A page of panels stacked over one time axis, ``width`` x ``height`` pixels."""

    width: int
    height: int
    title: str
    panels: list[Panel]
    markers: list[Marker]
    stop: float | None = None
    """Where a failed or interrupted run stopped (a dashed line on every panel)."""
    stop_word: str = ""
    """The stop's word over the top panel (``failed at t=0.005 s``)."""
    time_label: str = "time (s)"


def layout(results: Results, selections: Sequence[str | list[Trace]], title: str | None = None,
           markers: Sequence[Marker] = ()) -> Page:
    """One page: a panel per selection (a selection's text, or its traces), over the time
    the run covered, with ``markers`` on every panel.

    A panel of one signal is labelled with its name and unit; its legend, right of the
    panel, names the elements as the block does (``thumb.1``), each with its unit where they
    differ. Elements named ``group.member`` share a colour per group and a line style per
    member, so nine joints read as three fingers of three. A panel of several signals
    names each line ``signal[element]``. The time axis spans the data: from the first
    sample to the end time, or to where a failed or interrupted run stopped, which a
    dashed line marks, with a dot on each element's last sample."""
    panels_traces = [select(results, s) if isinstance(s, str) else list(s) for s in selections]
    end, stop = time_span(results)
    width = round(FIGURE_WIDTH * DPI)
    heading = fit(title or results.info.get("diagram", ""), 0.95 * width, LARGE, TITLE_LINES)
    note = results.end_note if results.complete else results.status
    if note:
        heading += "\n" + fit(f"[{note}]", 0.95 * width, LARGE, NOTE_LINES)
    n = len(panels_traces)
    top = 0.25 + TITLE_LINE * (heading.count("\n") + 1)
    entries = [_entries(results, traces) for traces in panels_traces]
    right = max([0.3 * DPI] + [_legend_size(labels)[0] + 0.15 * DPI for labels in entries])
    height = round((top + BOTTOM + AXES_HEIGHT * n) * DPI)
    x0, x1 = LEFT * DPI, width - right
    axes_height = (AXES_HEIGHT * n - GAP * (n - 1)) / n * DPI
    xlim = _time_limits(results, panels_traces, end, stop)
    xticks = ticks(*xlim, max(2, int((x1 - x0) / X_TICK_SPACING)))
    panels = []
    for k, (traces, labels) in enumerate(zip(panels_traces, entries)):
        y0 = top * DPI + k * (axes_height + GAP * DPI)
        box = (x0, y0, x1, y0 + axes_height)
        curves, dots, units = _curves(results, traces, end, stop, labels, columns=int(x1 - x0))
        values = np.concatenate([c.v for c in curves]) if curves else np.empty(0)
        ylim = data_range(values)
        panel = Panel(box, xlim, ylim, xticks, ticks(*ylim, max(2, int(axes_height / Y_TICK_SPACING))),
                      _axis_label(", ".join(tr.title for tr in traces), units, axes_height), curves, dots=dots,
                      time_labels=k == n - 1)
        legend = [c for c in curves if c.label is not None]
        if 1 < len(legend) <= MAX_LEGEND:
            panel.legend = legend
            panel.legend_columns = _legend_columns(len(legend))
            lw, lh = _legend_size([c.label for c in legend])
            left = x1 + 0.01 * (x1 - x0)
            panel.legend_box = (left, y0, left + lw, y0 + lh)
        panels.append(panel)
    stop_word = results.status.split(": ", 1)[0] if stop is not None else ""
    return Page(width, height, heading, panels, list(markers), stop, stop_word)


def _time_limits(results: Results, panels_traces, end: float | None, stop: float | None) -> tuple[float, float]:
    """From the first sample to the end time (a little past a stop, so that its line and
    dots show), or the samples' span where the run gives no end."""
    firsts = [float(results[tr.signal][0][0]) for traces in panels_traces for tr in traces
              if len(results[tr.signal][0])]
    start = min(firsts, default=0.0)
    if end is not None and end > start:
        return start, end + (STOP_MARGIN * (end - start) if stop is not None else 0.0)
    times = np.concatenate([results[tr.signal][0] for traces in panels_traces for tr in traces] or [np.empty(0)])
    return data_range(times)


def _entries(results: Results, traces: list[Trace]) -> list[str | None]:
    """The legend label of each line of a panel (None: unlabelled), cut short past
    LEGEND_WIDTH inches over the legend's columns."""
    overlaid = len(traces) > 1
    labels = []
    for tr in traces:
        units = _units(results, tr)
        mixed = units is not None and len(set(units)) > 1
        width = len(tr.columns)
        for j in range(width):
            unit = f" ({units[j] or '?'})" if mixed else ""
            if overlaid:
                labels.append((tr.title if width == 1 else f"{tr.signal}[{tr.labels[j]}]") + unit)
            else:
                labels.append(tr.labels[j] + unit if width > 1 else None)
    columns = _legend_columns(sum(label is not None for label in labels))
    return [label if label is None else fit(label, LEGEND_WIDTH * DPI / columns, SMALL) for label in labels]


def _units(results: Results, trace: Trace) -> list[str] | None:
    """The units of a trace's elements (None: its block gave none)."""
    units = results.units(trace.signal)
    return None if units is None else [units[c] for c in trace.columns]


def _legend_columns(entries: int) -> int:
    return 1 if entries <= LEGEND_ROWS else 2


def _legend_size(labels: Sequence[str | None]) -> tuple[float, float]:
    """(width, height) in pixels of a legend of ``labels`` (0, 0: no legend)."""
    shown = [label for label in labels if label is not None]
    if not 1 < len(shown) <= MAX_LEGEND:
        return 0.0, 0.0
    em = points(SMALL)
    columns = _legend_columns(len(shown))
    rows = -(-len(shown) // columns)
    column = (LEGEND_HANDLE + LEGEND_PAD) * em + max(text_size(label, SMALL)[0] for label in shown)
    return columns * column + (columns - 1) * LEGEND_COLUMN * em, rows * LEGEND_PITCH * em


def _curves(results: Results, traces: list[Trace], end: float | None, stop: float | None,
            labels: list[str | None], columns: int) -> tuple[list[Curve], list, list[str]]:
    """A panel's curves (thinned to ``columns`` pixel columns, ``blocks.plot.pages.envelope``),
    its stop dots, and the units of its lines."""
    overlaid = len(traces) > 1
    if overlaid:
        styles = line_styles([f"{tr.signal}[{label}]" for tr in traces for label in tr.labels])
    curves, dots, shown_units, drawn = [], [], [], 0
    for tr in traces:
        t, v = results[tr.signal]
        v = v[:, list(tr.columns)]
        if stop is not None and len(t):
            dots.append((float(t[-1]), v[-1].astype(float)))
        if end is not None and len(t) and t[-1] < end:
            t, v = np.append(t, end), np.vstack([v, v[-1:]])
        t, v = envelope(t, v, columns)
        width = v.shape[1]
        shown_units += _units(results, tr) or []
        trace_styles = styles[drawn:drawn + width] if overlaid else line_styles(list(tr.labels))
        for j in range(width):
            curves.append(Curve(t, v[:, j], trace_styles[j], labels[drawn + j]))
        drawn += width
    return curves, dots, shown_units


def _axis_label(name: str, units: list[str], height: float) -> str:
    """A panel's axis label (``axis_label``), each line no longer than the panel is high."""
    label = axis_label(fit(name, height, SIZE, LABEL_LINES), units or None)
    if units:
        name_lines, _, unit_line = label.rpartition("\n")
        label = name_lines + "\n" + fit(unit_line, height, SIZE)
    return label


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


def time_span(results: Results) -> tuple[float | None, float | None]:
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
