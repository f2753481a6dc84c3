"""Plots of logged signals: an axis per selection, time in seconds, zero-order-hold steps,
and the diagram's events marked.

A selection (``blocks.plot.select``) is a signal, some of its elements (``plant.q[fore.1]``),
or several of those overlaid on one axis (``plant.q[fore.1],ref.y``). Markers
(``blocks.plot.markers``) show what the diagram makes happen: Step times, and whatever an
application registers (the hand's task phases).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

from blocks.limits import MAX_PLOT_AXES, MAX_PLOT_LINES
from blocks.plot.markers import MARKER_COLOUR, Marker, markers as run_markers
from blocks.plot.select import Trace, by_unit, select
from blocks.results.signals import Results

AXES_PER_PAGE = 6
MARKER_GID = "marker"
"""The gid of every artist that draws a marker (their lines, spans and texts)."""


def plot_signals(results: Results, path: str | Path, signals: Sequence[str] | None = None,
                 title: str | None = None, markers: bool | Sequence[Marker] = True) -> list[Path]:
    """Write PNG(s) of ``signals`` (selections, see ``blocks.plot.select``; default every
    logged signal, one per axis) to ``path``; more than 6 axes make pages, as even as can
    be (13 axes: 5, 4 and 4), named ``STEM-1.png``, ``STEM-2.png``, ...

    A whole signal whose elements differ in unit is an axis per unit (``plant.obj[x,y]``
    in m, ``plant.obj[theta]`` in rad), so that no axis mixes units. Discrete signals hold
    between samples, so they are drawn as steps; a signal's last value is held to the
    run's end time (where a block ended it, if one did, as the title says), or for a failed
    or interrupted run to where it stopped, which a vertical line marks with the status.
    ``markers``: the events to mark on every axis, or True for the diagram's
    (``blocks.plot.markers.markers``), False for none.
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

    def page(self, number: int):
        """Page ``number`` (from 1) laid out (``blocks.plot.page_layout.Page``)."""
        from blocks.plot.page_layout import layout  # Pillow's fonts: not for a command that only checks a plot's size

        return layout(self.results, self.axes[number - 1], self.title, self.events)

    def draw(self, number: int) -> Path:
        """Draw page ``number`` (from 1) into its file; returns the file."""
        from blocks.plot.paint import paint

        out = self.file(number)
        paint(self.page(number)).save(out)
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


def draw_markers(axes, markers: Sequence[Marker]) -> None:
    """Each marker on every one of matplotlib ``axes`` (the application's figures), as a
    signal plot's page draws them: a dotted line at an instant, a light band over a span;
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


