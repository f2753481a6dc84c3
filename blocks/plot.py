"""Plots of logged signals: one axis per signal, time in seconds, zero-order-hold steps."""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Sequence

import numpy as np

from .results import Results

AXES_PER_PAGE = 8
MAX_LEGEND = 12
TITLE_WIDTH = 100


def plot_signals(results: Results, path: str | Path, signals: Sequence[str] | None = None,
                 title: str | None = None) -> list[Path]:
    """Write PNG(s) of ``signals`` (default all) to ``path``; more than 8 signals make pages.

    Discrete signals hold between samples, so they are drawn as steps; a signal's last
    value is held to the run's end time (where a block ended it, if one did, as the title
    says), or for a failed or interrupted run to where it stopped, which a vertical line
    marks with the status. Returns the files written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(signals) if signals else list(results)
    for name in names:
        results[name]  # raises a KeyError naming the logged signals
    if not names:
        raise ValueError("no signals to plot: the run logged none (add a 'log:' list to the diagram)")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    pages = [names[i:i + AXES_PER_PAGE] for i in range(0, len(names), AXES_PER_PAGE)]
    written = []
    for number, page in enumerate(pages, start=1):
        fig = figure(results, page, title)
        out = path if len(pages) == 1 else path.with_name(f"{path.stem}-{number}{path.suffix}")
        fig.savefig(out, dpi=110)
        plt.close(fig)
        written.append(out)
    return written


def figure(results: Results, names: Sequence[str], title: str | None = None):
    """One page: an axis per signal of ``names``, over the time the run covered."""
    import matplotlib.pyplot as plt

    end, stop = time_span(results)
    fig, axes = plt.subplots(len(names), 1, sharex=True, squeeze=False, figsize=(9, 1.2 + 2.0 * len(names)))
    for ax, name in zip(axes[:, 0], names):
        t, v = results[name]
        if end is not None and len(t) and t[-1] < end:
            t, v = np.append(t, end), np.vstack([v, v[-1:]])
        width = v.shape[1]
        labels = results.element_labels(name) or [str(j) for j in range(width)]
        for j in range(width):
            ax.step(t, v[:, j], where="post", label=f"[{labels[j]}]" if width > 1 else None, lw=1.2)
        if stop is not None:
            ax.axvline(stop, color="tab:red", ls="--", lw=1.0)
        ax.set_ylabel(name, rotation=0, ha="right", va="center")
        ax.grid(True, alpha=0.3)
        if 1 < width <= MAX_LEGEND:
            ax.legend(loc="upper right", fontsize="small", ncol=min(width, 6))
    if stop is not None:
        axes[0, 0].annotate(results.status.split(": ", 1)[0], xy=(stop, 1.0), xycoords=("data", "axes fraction"),
                            xytext=(0, 3), textcoords="offset points", ha="right", va="bottom",
                            color="tab:red", fontsize="small")
    axes[-1, 0].set_xlabel("time (s)")
    heading = title or results.info.get("diagram", "")
    note = results.end_note if results.complete else results.status
    if note:
        heading += "\n" + textwrap.fill(f"[{note}]", TITLE_WIDTH)
    fig.suptitle(heading)
    fig.tight_layout()
    return fig


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
