"""Plots of logged signals: an axis per selection, time in seconds, zero-order-hold steps,
and the diagram's events marked, drawn with matplotlib into PNG, SVG or PDF files (as the
file's name says) or returned as a Figure (``Results.plot``).

A selection (``blocks.plot.select``) is a signal, some of its elements (``plant.q[fore.1]``),
or several of those overlaid on one axis (``plant.q[fore.1],ref.y``). Markers
(``blocks.plot.markers``) show what the diagram makes happen: Step times, and whatever an
application registers (the hand's task phases). A page is drawn by ``blocks.plot.figure``,
imported only when one is: checking a plot's size costs no matplotlib.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

from blocks.limits import MAX_PLOT_AXES, MAX_PLOT_LINES
from blocks.plot.markers import Marker, markers as run_markers
from blocks.plot.select import Trace, by_unit, select

AXES_PER_PAGE = 6
FORMATS = (".png", ".svg", ".pdf")
"""The files a plot is written as, by their name's suffix."""
SAVE_OPTIONS = {".png": {"pil_kwargs": {"compress_level": 3}},  # a faster deflate than 6, a few % more bytes
                ".svg": {"metadata": {"Date": None}},  # no date (and ids from a fixed salt):
                ".pdf": {"metadata": {"CreationDate": None}}}  # the same plot makes the same file


def plot_signals(results: Any, path: str | Path, signals: Sequence[str] | None = None,
                 title: str | None = None, markers: bool | Sequence[Marker] = True) -> list[Path]:
    """Write ``signals`` of ``results`` (selections, see ``blocks.plot.select``; default every
    logged signal, one per axis) to ``path``, a .png, .svg or .pdf file; more than 6 axes
    make pages, as even as can be (13 axes: 5, 4 and 4), named ``STEM-1.png``,
    ``STEM-2.png``, ...

    A whole signal whose elements differ in unit is an axis per unit (``plant.obj[x,y]``
    in m, ``plant.obj[theta]`` in rad), so that no axis mixes units. Discrete signals hold
    between samples, so they are drawn as steps; a signal's last value is held to the
    run's end time (where a block ended it, if one did, as the title says), or for a failed
    or interrupted run to where it stopped, which a vertical line marks with the status.
    ``markers``: the events to mark on every axis, or True for the diagram's
    (``blocks.plot.markers.markers``), False for none.
    Raises ``SelectionError`` (a ValueError) for a selection of nothing logged, ValueError
    for another kind of file. Returns the files written.
    """
    pages = Pages.of(results, path, signals, title, markers)
    return [pages.draw(number) for number in range(1, len(pages) + 1)]


def figure_of(results: Any, signals: Sequence[str] | None = None, title: str | None = None,
              markers: bool | Sequence[Marker] = True):
    """The matplotlib Figure of ``plot_signals``'s axes, all of them on one (a notebook
    shows it; ``fig.savefig`` writes it)."""
    from blocks.plot.figure import signal_figure

    return signal_figure(results, signal_axes(results, signals), title, _events(results, markers))


def signal_axes(results: Any, signals: Sequence[str] | None) -> list[list[Trace]]:
    """The traces of each axis that ``signals`` (default: every logged signal) make, a
    signal of mixed units split by unit; ``SelectionError``, ``PlotSizeError``."""
    selections = list(signals) if signals else list(results)
    if not selections:
        raise ValueError("no signals to plot: the run logged none (add a 'log:' list to the diagram)")
    if len(selections) > MAX_PLOT_AXES:
        check_plot_size(len(selections), 0)
    axes = [axis for s in selections for axis in by_unit(results, select(results, s))]
    check_plot_size(len(axes), sum(len(tr.columns) for traces in axes for tr in traces))
    return axes


def _events(results: Any, markers: bool | Sequence[Marker]) -> list[Marker]:
    return run_markers(results.info)[0] if markers is True else list(markers or [])


@dataclass
class Pages:
    """A plot laid out in pages before any is drawn (``plot_signals`` explains what it
    draws), so that its pages can be drawn one by one, in any order or process."""

    results: Any
    path: Path
    axes: list[list[list[Trace]]]
    """Per page, per axis, the traces it draws."""
    title: str | None
    events: list[Marker]

    @classmethod
    def of(cls, results: Any, path: str | Path, signals: Sequence[str] | None = None,
           title: str | None = None, markers: bool | Sequence[Marker] = True) -> "Pages":
        """The pages of ``plot_signals(results, path, signals, title, markers)``, checked
        (a file of a kind not in FORMATS, ``SelectionError``, ``PlotSizeError``), ``path``'s
        folder made."""
        path = Path(path)
        if path.suffix.lower() not in FORMATS:
            raise ValueError(f"{path}: a plot is written as {', '.join(FORMATS[:-1])} or {FORMATS[-1]}, "
                             f"not '{path.suffix}' (e.g. {path.with_suffix('.png')})")
        axes = signal_axes(results, signals)
        events = _events(results, markers)
        path.parent.mkdir(parents=True, exist_ok=True)
        return cls(results, path, balanced(axes, AXES_PER_PAGE), title, events)

    def __len__(self) -> int:
        return len(self.axes)

    def file(self, number: int) -> Path:
        """Where page ``number`` (from 1) goes: ``path`` itself for a one-page plot."""
        return self.path if len(self) == 1 else self.path.with_name(f"{self.path.stem}-{number}{self.path.suffix}")

    def page(self, number: int):
        """Page ``number`` (from 1) as a matplotlib Figure."""
        from blocks.plot.figure import DPI, VECTOR_COLUMNS_PER_INCH, signal_figure

        columns = DPI if self.path.suffix.lower() == ".png" else VECTOR_COLUMNS_PER_INCH
        return signal_figure(self.results, self.axes[number - 1], self.title, self.events, columns)

    def draw(self, number: int) -> Path:
        """Draw page ``number`` (from 1) into its file; returns the file."""
        from blocks.plot.figure import DPI

        from matplotlib import rc_context

        out = self.file(number)
        suffix = out.suffix.lower()
        fig = self.page(number)
        with rc_context({"svg.hashsalt": "blocks"}):
            fig.savefig(out, format=suffix[1:], dpi=DPI, **SAVE_OPTIONS[suffix])
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
