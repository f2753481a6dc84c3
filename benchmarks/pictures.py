"""How long the pictures of the 1 s re-grasp take, against the run that makes their data.

Each command runs in a fresh process, as a user runs it, medians of ``--repeat`` runs
(interleaved, so that a busy machine slows both sides alike):

- the signal plots against matplotlib's floor (target: at most 1.15x): ``hierhand run
  regrasp.yaml --plot`` against ``hierhand run`` plus ``benchmarks/bare_pages.py``, a bare
  script that draws the same pages with one reused figure (nothing of the project
  imported); and ``hierhand plot RUN`` against that script alone. Also what a page costs
  drawn and saved in a warm process (the seconds per page the docs quote);
- ``hierhand animate`` of that run to a GIF at the default speed (251 frames): its wall
  time (target: at most 15 s) and its peak resident memory (target: at most 250 MB),
  against ``hierhand run``;
- ``hierhand graph regrasp.yaml -o wiring.png`` against ``hierhand validate`` (the same
  loading without the drawing), and the drawing alone in this process (target: under 1 s).

Python's bytecode caches are on for these processes, as on a user's machine, even where
the environment turns them off (``PYTHONDONTWRITEBYTECODE``, which makes every process
compile the project's modules again: the run then takes half as long again); a first
round, not counted, writes them.

    python benchmarks/pictures.py [--repeat 5] [--plots-only]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
REGRASP = ROOT / "diagrams" / "regrasp.yaml"
BARE = ROOT / "benchmarks" / "bare_pages.py"


USER_ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
"""The environment of the timed processes: bytecode caches on."""


def timed(*args: str, script: Path | None = None) -> tuple[float, float, float]:
    """Wall seconds, peak resident MB and CPU seconds (its own and its children's) of
    ``python -m hierhand ARGS`` (or of ``python SCRIPT ARGS``) in a fresh process."""
    start = time.perf_counter()
    command = [sys.executable, *([str(script)] if script else ["-m", "hierhand"]), *args]
    proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=USER_ENV)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode:
        raise SystemExit(f"{' '.join(command[1:])} failed: {proc.stderr.read().decode()}")
    return wall, usage.ru_maxrss / 1024, usage.ru_utime + usage.ru_stime


def median(values) -> float:
    return statistics.median(values)


def bare_spec(run: Path, spec: Path) -> int:
    """Write what each page of ``run``'s plot shows, read off the project's own pages, as
    the JSON that ``bare_pages.py`` draws; returns the number of pages."""
    from blocks import Results
    from blocks.plot.curves import axis_label, axis_of, time_limits, time_span
    from blocks.plot.figure import DPI
    from blocks.plot.markers import markers
    from blocks.plot.pages import Pages

    results = Results.load(run)
    pages = Pages.of(results, spec.with_suffix(".png"))
    end, stop = time_span(results)
    described = []
    for number, page in enumerate(pages.axes, start=1):
        fig = pages.page(number)
        axes = []
        for traces in page:
            axis = axis_of(results, traces, end, stop, columns=2**62)  # every sample: styles and labels only
            columns = [(tr.signal, c) for tr in traces for c in tr.columns]
            labelled = len(axis.legend)
            axes.append({"lines": [{"signal": signal, "column": c, "style": curve.style, "label": curve.label}
                                   for (signal, c), curve in zip(columns, axis.curves)],
                         "ylim": axis.ylim(), "ylabel": axis_label(axis.name, axis.units or None),
                         "legend_columns": 0 if not 1 < labelled <= 24 else 1 if labelled <= 12 else 2})
        sp = fig.subplotpars
        described.append({"size": list(fig.get_size_inches()), "axes": axes,
                          "margins": {"left": sp.left, "right": sp.right, "top": sp.top, "bottom": sp.bottom,
                                      "hspace": sp.hspace}})
    spec.write_text(json.dumps({
        "npz": str(run / "signals.npz"), "dpi": DPI, "end": end, "title": pages.page(1).texts[0].get_text(),
        "xlim": time_limits(results, [t for page in pages.axes for t in page], end, stop),
        "markers": [(m.start, m.end, m.label) for m in markers(results.info)[0]], "pages": described}))
    return len(pages)


def page_seconds(run: Path, out: Path, repeat: int) -> tuple[list[float], list[float]]:
    """Wall and CPU seconds per page of ``run``'s plot drawn and saved in this process,
    warm (each page drawn once before); the CPU seconds say what a page costs on a machine
    that others keep busy."""
    from blocks import Results
    from blocks.plot.pages import Pages

    pages = Pages.of(Results.load(run), out / "warm" / "signals.png")
    for number in range(1, len(pages) + 1):
        pages.draw(number)
    wall, cpu = [], []
    for _ in range(repeat):
        for number in range(1, len(pages) + 1):
            start, start_cpu = time.perf_counter(), time.process_time()
            pages.draw(number)
            wall.append(time.perf_counter() - start)
            cpu.append(time.process_time() - start_cpu)
    return wall, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--plots-only", action="store_true", help="time the signal plots only")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="pictures-") as tmp:
        out = Path(tmp)
        runs, plotted, plots, bares, animated, memory, graphs, validates = [], [], [], [], [], [], [], []
        timed("run", str(REGRASP), "-q", "--plot", "-o", str(out / "plotted"))  # writes the caches
        timed("run", str(REGRASP), "-q", "-o", str(out / "run"))
        count = bare_spec(out / "run", out / "spec.json")
        timed(str(out / "spec.json"), str(out), script=BARE)
        if not args.plots_only:
            timed("graph", str(REGRASP), "-o", str(out / "wiring.png"))
        for _ in range(args.repeat):
            runs.append(timed("run", str(REGRASP), "-q", "-o", str(out / "run")))
            plotted.append(timed("run", str(REGRASP), "-q", "--plot", "-o", str(out / "plotted")))
            plots.append(timed("plot", str(out / "run"), "-o", str(out / "again.png")))
            bares.append(timed(str(out / "spec.json"), str(out), script=BARE))
            if args.plots_only:
                continue
            wall, mb, _ = timed("animate", str(out / "run"), "-o", str(out / "hand.gif"))
            animated.append(wall)
            memory.append(mb)
            validates.append(timed("validate", str(REGRASP))[0])
            graphs.append(timed("graph", str(REGRASP), "-o", str(out / "wiring.png"))[0])
        per_page, per_page_cpu = page_seconds(out / "run", out, args.repeat)
        drawing = []
        if not args.plots_only:
            import blocks
            from blocks.graph import render

            diagram = blocks.load_diagram(REGRASP)
            schedule = blocks.build_schedule(diagram, None)
            render(diagram, schedule, out / "warm.png")  # imports matplotlib and its fonts
            for _ in range(args.repeat):
                start = time.perf_counter()
                render(diagram, schedule, out / "drawn.png")
                drawing.append(time.perf_counter() - start)
    run_s, bare_s, plotted_s, plot_s = (median(t[0] for t in times) for times in (runs, bares, plotted, plots))
    run_cpu, bare_cpu, plotted_cpu, plot_cpu = (median(t[2] for t in times) for times in (runs, bares, plotted, plots))
    print(f"medians of {args.repeat} fresh processes each; the re-grasp's plot: {count} pages; "
          f"{len(os.sched_getaffinity(0))} cores")
    print(f"run --plot: {plotted_s:.2f} s, against run {run_s:.2f} s + the bare script's pages {bare_s:.2f} s "
          f"= {run_s + bare_s:.2f} s: {plotted_s / (run_s + bare_s):.2f}x (target <= 1.15x); "
          f"{plotted_s / run_s:.2f}x run; CPU {plotted_cpu:.2f} s against {run_cpu + bare_cpu:.2f} s: "
          f"{plotted_cpu / (run_cpu + bare_cpu):.2f}x")
    print(f"plot RUN: {plot_s:.2f} s, against the bare script's pages {bare_s:.2f} s: {plot_s / bare_s:.2f}x "
          f"(target <= 1.15x); CPU {plot_cpu:.2f} s against {bare_cpu:.2f} s: {plot_cpu / bare_cpu:.2f}x")
    print(f"a page drawn and saved as PNG in a warm process: {median(per_page):.3f} s, "
          f"{median(per_page_cpu):.3f} s of CPU (medians of {len(per_page)}); load average "
          f"{os.getloadavg()[0]:.1f}")
    if args.plots_only:
        return
    print(f"animate to GIF (default speed): {median(animated):.2f} s ({median(animated) / run_s:.1f}x run), "
          f"peak {max(memory):.0f} MB resident (targets <= 15 s, <= 250 MB)")
    print(f"graph -o wiring.png: {median(graphs):.2f} s, validate: {median(validates):.2f} s: "
          f"{median(graphs) / median(validates):.2f}x; the drawing alone {median(drawing):.2f} s (target < 1 s)")


if __name__ == "__main__":
    main()
