"""A page of a signal plot as a matplotlib ``Figure`` (no pyplot): an axis per selection
stacked over one time axis, legends right of the axes, the diagram's events marked, and a
failed or interrupted run's stop.

The page is laid out by measure (margins in inches for the labels and the title, the
right margin as wide as the widest legend) rather than by matplotlib's constrained
layout, which would measure every text of the page once more before drawing it. Labels
are fitted to where they go (``fit``), so a 300-character element name cannot push the
data off the page.
"""

from __future__ import annotations

import io
from typing import Any, Sequence

from matplotlib import rc_context
from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties

from blocks.plot.curves import Axis, axis_label, axis_of, time_limits, time_span
from blocks.plot.markers import Marker, draw_markers
from blocks.plot.select import Trace

DPI = 110
"""Pixels per inch of a PNG page."""
VECTOR_COLUMNS_PER_INCH = 300
"""How finely an SVG or PDF page's curves are thinned (``curves.envelope``): a print's resolution."""
FIGURE_WIDTH = 11.0
AXES_HEIGHT = 2.3   # inches per axis, its share of the gaps included
LEFT = 1.25         # inches left of the axes: tick labels and a two-line axis label
BOTTOM = 0.55       # below the last axis: its tick labels and the time label
TITLE_LINE = 0.24   # per line of the page's title
GAP = 0.3           # between two axes
TITLE_LINES = 2     # at most, of the title
NOTE_LINES = 3      # at most, of the status or end note under it
LABEL_LINES = 2     # at most, of an axis label's name (its unit takes one more)
LEGEND_WIDTH = 3.0  # inches, at most, of a legend's text (of each column's, over its columns)
MAX_LEGEND = 24
LEGEND_ROWS = 12
SIZE, SMALL, X_SMALL, LARGE = 10.0, 8.33, 6.94, 12.0  # points: labels, legends, markers' words, the title
STOP_COLOUR = "tab:red"
STOP_GID = "stop"
"""The gid of every artist that marks where a failed or interrupted run stopped."""


class SignalFigure(Figure):
    """A Figure that a notebook shows inline as a PNG even where pyplot was never imported."""

    def _repr_png_(self) -> bytes:
        out = io.BytesIO()
        self.savefig(out, format="png", dpi=DPI)
        return out.getvalue()


def signal_figure(results: Any, axes_traces: Sequence[list[Trace]], title: str | None = None,
                  markers: Sequence[Marker] = (), columns_per_inch: float = DPI) -> Figure:
    """A page: an axis per entry of ``axes_traces`` (``blocks.plot.select``), over the time
    the run covered, with ``markers`` on every axis.

    An axis of one signal is labelled with its name and unit; its legend, right of the
    axis, names the elements as the block does (``thumb.1``), each with its unit where they
    differ. An axis of several signals names each line ``signal[element]``. The time axis
    spans the data: from the first sample to the end time, or to where a failed or
    interrupted run stopped, which a dashed line marks, with a dot on each element's last
    sample and the status over the top axis. Curves are thinned to ``columns_per_inch``."""
    with rc_context({"text.parse_math": False}):  # a '$' in a name is a dollar sign
        return _draw(results, list(axes_traces), title, markers, columns_per_inch)


def _draw(results: Any, axes_traces: list[list[Trace]], title: str | None, markers: Sequence[Marker],
          columns_per_inch: float) -> Figure:
    fig = SignalFigure(dpi=DPI)
    FigureCanvasAgg(fig)  # measures the legends, and draws a PNG
    fit = Fitter()
    end, stop = time_span(results)
    width = FIGURE_WIDTH * DPI
    heading = fit(title or results.info.get("diagram", ""), 0.95 * width, LARGE, TITLE_LINES)
    note = results.end_note if results.complete else results.status
    if note:
        heading += "\n" + fit(f"[{note}]", 0.95 * width, LARGE, NOTE_LINES)
    n = len(axes_traces)
    top = 0.25 + TITLE_LINE * (heading.count("\n") + 1)
    height = top + BOTTOM + AXES_HEIGHT * n
    fig.set_size_inches(FIGURE_WIDTH, height)
    axes = list(fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0])
    axes_px = (AXES_HEIGHT * n - GAP * (n - 1)) / n * DPI
    columns = int((FIGURE_WIDTH - LEFT) * columns_per_inch)
    legends = [_axis(ax, axis_of(results, traces, end, stop, columns), stop, fit, axes_px)
               for ax, traces in zip(axes, axes_traces)]
    axes[0].set_xlim(*time_limits(results, axes_traces, end, stop))
    words = axes_px - 6  # a marker's words start 2 points below the axis's top, on a backdrop
    draw_markers(axes, [Marker(m.start, m.end, fit(m.label, words, X_SMALL)) for m in markers])
    if stop is not None:
        axes[0].annotate(results.status.split(": ", 1)[0], xy=(stop, 1.0), xycoords=("data", "axes fraction"),
                         xytext=(0, 3), textcoords="offset points", ha="right", va="bottom",
                         color=STOP_COLOUR, fontsize=SMALL, gid=STOP_GID)
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(heading, y=1 - 0.12 / height, va="top", fontsize=LARGE)
    renderer = fig.canvas.get_renderer()
    widest = max([0.0] + [lg.get_window_extent(renderer).width / DPI for lg in legends if lg is not None])
    # the legend starts 1 % of the axes' width right of them, and ends 0.15 in inside the page
    right = max(0.3, (widest + 0.15 + 0.01 * (FIGURE_WIDTH - LEFT)) / 1.01)
    fig.subplots_adjust(left=LEFT / FIGURE_WIDTH, right=1 - right / FIGURE_WIDTH, top=1 - top / height,
                        bottom=BOTTOM / height, hspace=GAP / (AXES_HEIGHT - GAP))
    return fig


def _axis(ax, axis: Axis, stop: float | None, fit: "Fitter", height_px: float):
    """Draw one axis's curves, stop marks, grid and label; returns its legend (None: none).
    Its ranges are set, not autoscaled: matplotlib's autoscaling overflows for values near
    the largest double."""
    ax.set_autoscale_on(False)
    ax.set_ylim(*axis.ylim())
    handles = []
    for curve in axis.curves:
        (line,) = ax.plot(curve.t, curve.v, drawstyle="steps-post", **curve.style)
        if curve.label is not None:
            handles.append(line)
    for t, values in axis.dots:
        ax.plot([t] * len(values), values, ls="", marker="o", ms=4.8, color=STOP_COLOUR, clip_on=False,
                zorder=5, gid=STOP_GID)
    if stop is not None:
        ax.axvline(stop, color=STOP_COLOUR, ls="--", lw=1.0, gid=STOP_GID)
    ax.grid(True, alpha=0.3)
    label = axis_label(fit(axis.name, height_px, SIZE, LABEL_LINES), axis.units or None)
    if axis.units:  # the unit's line fitted too: a block may name a long one
        name_lines, _, unit_line = label.rpartition("\n")
        label = name_lines + "\n" + fit(unit_line, height_px, SIZE)
    ax.set_ylabel(label)
    shown = axis.legend
    if not 1 < len(shown) <= MAX_LEGEND:
        return None
    columns = 1 if len(shown) <= LEGEND_ROWS else 2
    labels = [fit(c.label, LEGEND_WIDTH * DPI / columns, SMALL) for c in shown]
    return ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=SMALL,
                     frameon=False, ncol=columns, borderaxespad=0.0, handlelength=2.5, columnspacing=1.5)


ELLIPSIS = "\u2026"


class Fitter:
    """Text fitted to a width in pixels, measured in the page's font: ``fit(text, width,
    size_pt, lines)`` wraps at spaces where it can, within words where it must, into at
    most ``lines`` lines, the last cut short with an ellipsis if the text is longer."""

    def __init__(self):
        self._renderer = RendererAgg(1, 1, DPI)  # measures only
        self._fonts: dict[float, FontProperties] = {}

    def width(self, text: str, size_pt: float) -> float:
        font = self._fonts.setdefault(size_pt, FontProperties(size=size_pt))
        return self._renderer.get_text_width_height_descent(text, font, ismath=False)[0]

    def __call__(self, text: str, width: float, size_pt: float, lines: int = 1) -> str:
        out: list[str] = []
        rest = " ".join(text.split())
        while rest and len(out) < lines:
            if self.width(rest, size_pt) <= width:
                out.append(rest)
                rest = ""
                break
            cut = self._longest_fitting(rest, width, size_pt)
            space = rest.rfind(" ", 0, cut + 1)
            if space > 0:
                cut = space
            out.append(rest[:cut].rstrip())
            rest = rest[cut:].lstrip()
        if rest:
            last = out[-1] if out else ""
            while last and self.width(last + ELLIPSIS, size_pt) > width:
                last = last[:-1]
            out[-1:] = [last.rstrip() + ELLIPSIS]
        return "\n".join(out)

    def _longest_fitting(self, text: str, width: float, size_pt: float) -> int:
        """How many of ``text``'s first characters fit in ``width`` pixels (at least one)."""
        lo, hi = 1, len(text)
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if self.width(text[:mid], size_pt) <= width:
                lo = mid
            else:
                hi = mid - 1
        return lo
