"""matplotlib's floor for a run's signal plots: the same pages drawn by a bare script, with
nothing of the project imported and one figure reused for every page.

``benchmarks/pictures.py`` writes what each page shows (a JSON spec: the signals and
their columns per axis, line styles, legend labels, axis labels and ranges, markers, the
page's size and margins, read off the project's own pages) and times this script in a
fresh process, as it times ``hierhand plot``. The script loads the logged signals with
numpy, draws every sample as a step (matplotlib's own path simplification, no thinning)
and saves each page as PNG.

    python benchmarks/bare_pages.py SPEC.json OUT_DIR
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


def main(spec_file: str, out_dir: str) -> None:
    spec = json.loads(Path(spec_file).read_text())
    data = np.load(spec["npz"])
    fig = Figure(dpi=spec["dpi"])
    FigureCanvasAgg(fig)
    for number, page in enumerate(spec["pages"], start=1):
        fig.clear()
        fig.set_size_inches(*page["size"])
        fig.subplots_adjust(**page["margins"])
        axes = fig.subplots(len(page["axes"]), 1, sharex=True, squeeze=False)[:, 0]
        for ax, axis in zip(axes, page["axes"]):
            for line in axis["lines"]:
                t, v = data["time:" + line["signal"]], data[line["signal"]][:, line["column"]]
                if spec["end"] is not None and len(t) and t[-1] < spec["end"]:
                    t, v = np.append(t, spec["end"]), np.append(v, v[-1])
                ax.step(t, v, where="post", label=line["label"], **line["style"])
            ax.set_ylim(*axis["ylim"])
            ax.grid(True, alpha=0.3)
            ax.set_ylabel(axis["ylabel"])
            if axis["legend_columns"]:
                ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small", frameon=False,
                          ncol=axis["legend_columns"], borderaxespad=0.0, handlelength=2.5)
        for start, end, label in spec["markers"]:
            for ax in axes:
                if end <= start:
                    ax.axvline(start, color="dimgray", ls=":", lw=1.0)
                else:
                    ax.axvspan(start, end, color="dimgray", alpha=0.08, lw=0)
            axes[0].annotate(label, xy=(start, 1.0), xycoords=("data", "axes fraction"), xytext=(2, -2),
                             textcoords="offset points", rotation=90, ha="left", va="top", fontsize="x-small",
                             color="dimgray", annotation_clip=True, clip_on=True,
                             bbox={"boxstyle": "square,pad=0.1", "facecolor": "white", "alpha": 0.7, "linewidth": 0})
        axes[0].set_xlim(*spec["xlim"])
        axes[-1].set_xlabel("time (s)")
        fig.suptitle(spec["title"], y=1 - 0.12 / page["size"][1], va="top", fontsize=12)
        fig.savefig(Path(out_dir, f"bare-{number}.png"), dpi=spec["dpi"], pil_kwargs={"compress_level": 3})


if __name__ == "__main__":
    main(*sys.argv[1:3])
