"""Plots of logged signals: one axis per signal, time in seconds, zero-order-hold steps."""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from .results import Results

AXES_PER_PAGE = 8
MAX_LEGEND = 12


def plot_signals(results: Results, path: str | Path, signals: Sequence[str] | None = None,
                 title: str | None = None) -> list[Path]:
    """Write PNG(s) of ``signals`` (default all) to ``path``; more than 8 signals make pages.

    Discrete signals hold between samples, so they are drawn as steps; a signal's last
    value is held to the run's end time. Returns the files written.
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
    t_end = results.info.get("t_end")
    pages = [names[i:i + AXES_PER_PAGE] for i in range(0, len(names), AXES_PER_PAGE)]
    written = []
    for number, page in enumerate(pages, start=1):
        fig, axes = plt.subplots(len(page), 1, sharex=True, squeeze=False,
                                 figsize=(9, 1.2 + 2.0 * len(page)))
        for ax, name in zip(axes[:, 0], page):
            t, v = results[name]
            if t_end is not None and len(t) and t[-1] < t_end:
                t, v = np.append(t, t_end), np.vstack([v, v[-1:]])
            width = v.shape[1]
            for j in range(width):
                ax.step(t, v[:, j], where="post", label=f"[{j}]" if width > 1 else None, lw=1.2)
            ax.set_ylabel(name, rotation=0, ha="right", va="center")
            ax.grid(True, alpha=0.3)
            if 1 < width <= MAX_LEGEND:
                ax.legend(loc="upper right", fontsize="small", ncol=min(width, 6))
        axes[-1, 0].set_xlabel("time (s)")
        heading = title or results.info.get("diagram", "")
        if results.info.get("status", "complete") != "complete":
            heading += f"  [{results.info['status']}]"
        fig.suptitle(heading)
        fig.tight_layout()
        out = path if len(pages) == 1 else path.with_name(f"{path.stem}-{number}{path.suffix}")
        fig.savefig(out, dpi=110)
        plt.close(fig)
        written.append(out)
    return written
