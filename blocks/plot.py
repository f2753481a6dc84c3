"""Plots of logged signals: an axis per selection, time in seconds, zero-order-hold steps,
and the diagram's events marked.

A selection (``blocks.plot_select``) is a signal, some of its elements (``plant.q[fore.1]``),
or several of those overlaid on one axis (``plant.q[fore.1],ref.y``). Markers
(``blocks.plot_markers``) show what the diagram makes happen: Step times, and whatever an
application registers (the hand's task phases).
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from .limits import MAX_PLOT_AXES, MAX_PLOT_LINES
from .plot_markers import Marker, markers as run_markers
from .plot_select import Trace, by_unit, select
from .results import Results

AXES_PER_PAGE = 6
MAX_LEGEND = 24
LEGEND_ROWS = 12
FIGURE_WIDTH = 11.0
AXES_HEIGHT = 2.3
TITLE_WIDTH = 110
STOP_MARGIN = 0.02
DPI = 110
LEFT = 1.25         # inches left of the axes: tick labels and a two-line axis label
BOTTOM = 0.55       # below the last axis: its tick labels and the time label
TITLE_LINE = 0.24   # per line of the page's title
GAP = 0.3           # between two axes
LEGEND_CHAR = 0.068  # inches per character of a legend entry ("small" text)
LEGEND_HANDLE = 0.6  # a legend entry's line sample and spacing
PNG = {"compress_level": 3}
"""PNG settings: a faster deflate than the default 6, for a few percent more bytes."""
MARKER_COLOUR = "dimgray"
MARKER_GID = "marker"
"""The gid of every artist that draws a marker (their lines, spans and texts)."""


def plot_signals(results: Results, path: str | Path, signals: Sequence[str] | None = None,
                 title: str | None = None, markers: bool | Sequence[Marker] = True) -> list[Path]:
    """Write PNG(s) of ``signals`` (selections, see ``blocks.plot_select``; default every
    logged signal, one per axis) to ``path``; more than 6 axes make pages, as even as can
    be (13 axes: 5, 4 and 4), named ``STEM-1.png``, ``STEM-2.png``, ...

    A whole signal whose elements differ in unit is an axis per unit (``plant.obj[x,y]``
    in m, ``plant.obj[theta]`` in rad), so that no axis mixes units. Discrete signals hold
    between samples, so they are drawn as steps; a signal's last value is held to the
    run's end time (where a block ended it, if one did, as the title says), or for a failed
    or interrupted run to where it stopped, which a vertical line marks with the status.
    ``markers``: the events to mark on every axis, or True for the diagram's
    (``blocks.plot_markers.markers``), False for none.
    Raises ``SelectionError`` (a ValueError) for a selection of nothing logged. Returns
    the files written.
    """
    pages = Pages.of(results, path, signals, title, markers)
    return [pages.draw(number) for number in range(1, len(pages) + 1)]


@dataclass
class Pages:
    """A plot laid out in pages before any is drawn (``plot_signals`` explains what it
    draws), so that its pages can be drawn one by one, in any order or process."""

    results: Results
    path: Path
    axes: list[list[list[Trace]]]
    """Per page, per axis, the traces it draws."""
    title: str | None
    events: list[Marker]

    @classmethod
    def of(cls, results: Results, path: str | Path, signals: Sequence[str] | None = None,
           title: str | None = None, markers: bool | Sequence[Marker] = True) -> "Pages":
        """The pages of ``plot_signals(results, path, signals, title, markers)``, checked
        (``SelectionError``, ``PlotSizeError``), ``path``'s folder made."""
        selections = list(signals) if signals else list(results)
        if not selections:
            raise ValueError("no signals to plot: the run logged none (add a 'log:' list to the diagram)")
        if len(selections) > MAX_PLOT_AXES:
            check_plot_size(len(selections), 0)
        axes = [axis for s in selections for axis in by_unit(results, select(results, s))]
        check_plot_size(len(axes), sum(len(tr.columns) for traces in axes for tr in traces))
        events = run_markers(results.info)[0] if markers is True else list(markers or [])
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        return cls(results, path, balanced(axes, AXES_PER_PAGE), title, events)

    def __len__(self) -> int:
        return len(self.axes)

    def file(self, number: int) -> Path:
        """Where page ``number`` (from 1) goes: ``path`` itself for a one-page plot."""
        return self.path if len(self) == 1 else self.path.with_name(f"{self.path.stem}-{number}{self.path.suffix}")

    def draw(self, number: int) -> Path:
        """Draw page ``number`` (from 1) into its file; returns the file."""
        fig = figure(self.results, self.axes[number - 1], self.title, self.events)
        out = self.file(number)
        fig.savefig(out, dpi=DPI, pil_kwargs=PNG)
        return out


def balanced(items: list, most: int) -> list[list]:
    """``items`` in as few pages of at most ``most`` as can be, the pages as even as can
    be (the first ones one longer)."""
    count = -(-len(items) // most)
    size, extra = divmod(len(items), count)
    pages, start = [], 0
    for page in range(count):
        stop = start + size + (page < extra)
        pages.append(items[start:stop])
        start = stop
    return pages


class PlotSizeError(ValueError):
    """More axes or lines than one plot draws (``limits.MAX_PLOT_AXES``, ``MAX_PLOT_LINES``)."""


def check_plot_size(axes: int, lines: int) -> None:
    """Refuse a plot of more than MAX_PLOT_AXES axes or MAX_PLOT_LINES lines before any is drawn."""
    if axes > MAX_PLOT_AXES or lines > MAX_PLOT_LINES:
        what = f"{axes} axes" if axes > MAX_PLOT_AXES else f"{lines} lines"
        raise PlotSizeError(f"a plot of {what} is more than one plot draws ({MAX_PLOT_AXES} axes, "
                            f"{MAX_PLOT_LINES} lines) (hint: choose what to draw with -s SIGNAL, or "
                            "elements with -s 'SIGNAL[0:10]')")


def figure(results: Results, selections: Sequence[str | list[Trace]], title: str | None = None,
           markers: Sequence[Marker] = ()):
    """One page: an axis per selection (a selection's text, or its traces), over the time
    the run covered, with ``markers`` drawn on every axis.

    An axis of one signal is labelled with its name and unit; its legend, right of the
    axis, names the elements as the block does (``thumb.1``), each with its unit where they
    differ. Elements named ``group.member`` share a colour per group and a line style per
    member, so nine joints read as three fingers of three. An axis of several signals
    names each line ``signal[element]``. The time axis spans the data: from the first
    sample to the end time, or to where a failed or interrupted run stopped, which a
    dashed line marks, with a dot on each element's last sample.

    The page is laid out by measure (margins in inches for the labels, the title and the
    widest legend) rather than by matplotlib's constrained layout, which would measure
    every text of the page once more before drawing it."""
    from matplotlib.figure import Figure

    axes_traces = [select(results, s) if isinstance(s, str) else list(s) for s in selections]
    end, stop = time_span(results)
    firsts = [float(results[tr.signal][0][0]) for traces in axes_traces for tr in traces
              if len(results[tr.signal][0])]
    start = min(firsts, default=0.0)
    heading = title or results.info.get("diagram", "")
    note = results.end_note if results.complete else results.status
    if note:
        heading += "\n" + textwrap.fill(f"[{note}]", TITLE_WIDTH)
    n = len(axes_traces)
    top = 0.25 + TITLE_LINE * (heading.count("\n") + 1)
    right = max([0.3] + [legend_width(results, traces) for traces in axes_traces])
    height = top + BOTTOM + AXES_HEIGHT * n
    fig = Figure(figsize=(FIGURE_WIDTH, height))
    fig.subplots_adjust(left=LEFT / FIGURE_WIDTH, right=1 - right / FIGURE_WIDTH, top=1 - top / height,
                        bottom=BOTTOM / height, hspace=GAP / (AXES_HEIGHT - GAP))
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)
    columns = int((FIGURE_WIDTH - LEFT - right) * DPI)
    for ax, traces in zip(axes[:, 0], axes_traces):
        lines = _draw_traces(ax, results, traces, end, stop, columns)
        if 1 < lines <= MAX_LEGEND:
            ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False,
                      ncol=1 if lines <= LEGEND_ROWS else 2, borderaxespad=0.0, handlelength=2.5)
        ax.grid(True, alpha=0.3)
    if end is not None and end > start:  # past a stop a little, so that its line and dots show
        axes[0, 0].set_xlim(start, end + (STOP_MARGIN * (end - start) if stop is not None else 0.0))
    draw_markers(axes[:, 0], markers)
    if stop is not None:
        axes[0, 0].annotate(results.status.split(": ", 1)[0], xy=(stop, 1.0), xycoords=("data", "axes fraction"),
                            xytext=(0, 3), textcoords="offset points", ha="right", va="bottom",
                            color="tab:red", fontsize="small")
    axes[-1, 0].set_xlabel("time (s)")
    fig.suptitle(heading, y=1 - 0.12 / height, va="top")
    return fig


def legend_width(results: Results, traces: list[Trace]) -> float:
    """Inches the legend of an axis of ``traces`` takes right of it (0: none)."""
    labels = [f"{tr.signal}[{label}] (?)" if len(traces) > 1 else f"{label} (?)"
              for tr in traces for label in tr.labels]
    if not 1 < len(labels) <= MAX_LEGEND:
        return 0.0
    columns = 1 if len(labels) <= LEGEND_ROWS else 2
    return 0.2 + columns * (LEGEND_HANDLE + LEGEND_CHAR * max(map(len, labels)))


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


def _draw_traces(ax, results: Results, traces: list[Trace], end: float | None, stop: float | None,
                 columns: int = 1000) -> int:
    """Draw an axis's traces (thinned to ``columns`` pixel columns, see ``envelope``);
    returns how many lines carry a legend label."""
    overlaid = len(traces) > 1
    if overlaid:
        styles = line_styles([f"{tr.signal}[{label}]" for tr in traces for label in tr.labels])
    labelled, drawn, shown_units = 0, 0, []
    for tr in traces:
        t, v = results[tr.signal]
        v = v[:, list(tr.columns)]
        last_t, last_v = (t[-1], v[-1]) if len(t) else (None, None)
        if end is not None and len(t) and t[-1] < end:
            t, v = np.append(t, end), np.vstack([v, v[-1:]])
        t, v = envelope(t, v, columns)
        width = v.shape[1]
        all_units = results.units(tr.signal)
        units = [all_units[c] for c in tr.columns] if all_units is not None else None
        shown_units += units or []
        mixed = units is not None and len(set(units)) > 1
        trace_styles = styles[drawn:drawn + width] if overlaid else line_styles(list(tr.labels))
        drawn += width
        for j in range(width):
            if overlaid:
                label = tr.title if width == 1 else f"{tr.signal}[{tr.labels[j]}]"
                label += f" ({units[j] or '?'})" if mixed else ""
            else:
                label = tr.labels[j] + (f" ({units[j] or '?'})" if mixed else "") if width > 1 else None
            ax.step(t, v[:, j], where="post", label=label, **trace_styles[j])
            labelled += label is not None
        if stop is not None and last_t is not None:
            ax.scatter(np.full(width, last_t), last_v, s=18, color="tab:red", zorder=5, clip_on=False)
    if stop is not None:
        ax.axvline(stop, color="tab:red", ls="--", lw=1.0)
    name = ", ".join(tr.title for tr in traces)
    ax.set_ylabel(axis_label(textwrap.fill(name, 40), shown_units if shown_units else None))
    return labelled


def draw_markers(axes, markers: Sequence[Marker]) -> None:
    """Each marker on every axis: a dotted line at an instant, a light band over a span;
    its words at the top of the first axis."""
    for m in markers:
        for ax in axes:
            if m.instant:
                ax.axvline(m.start, color=MARKER_COLOUR, ls=":", lw=1.0, gid=MARKER_GID)
            else:
                ax.axvspan(m.start, m.end, color=MARKER_COLOUR, alpha=0.08, lw=0, gid=MARKER_GID)
        axes[0].annotate(m.label, xy=(m.start, 1.0), xycoords=("data", "axes fraction"), xytext=(2, -2),
                         textcoords="offset points", rotation=90, ha="left", va="top", fontsize="x-small",
                         color=MARKER_COLOUR, gid=MARKER_GID, annotation_clip=True,
                         bbox={"boxstyle": "square,pad=0.1", "facecolor": "white", "alpha": 0.7, "linewidth": 0})


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
