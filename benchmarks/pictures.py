"""How long the pictures of the 1 s re-grasp take, against the run that makes their data.

Each command runs in a fresh process, as a user runs it, medians of ``--repeat`` runs
(interleaved, so that a busy machine slows both sides alike):

- ``hierhand run regrasp.yaml`` with ``--plot`` against without it (target: at most 1.5x);
- ``hierhand animate`` of that run to a GIF at the default speed (251 frames): its wall
  time (target: at most 15 s) and its peak resident memory (target: at most 250 MB),
  against ``hierhand run``;
- ``hierhand graph regrasp.yaml -o wiring.png`` against ``hierhand validate`` (the same
  loading without the drawing), and the drawing alone in this process (target: under 1 s).

Python's bytecode caches are on for these processes, as on a user's machine, even where
the environment turns them off (``PYTHONDONTWRITEBYTECODE``, which makes every process
compile the project's modules again: the run then takes half as long again); a first
round, not counted, writes them.

    python benchmarks/pictures.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
REGRASP = ROOT / "diagrams" / "regrasp.yaml"


USER_ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
"""The environment of the timed processes: bytecode caches on."""


def timed(*args: str) -> tuple[float, float]:
    """Wall seconds and peak resident MB of ``python -m hierhand ARGS`` in a fresh process."""
    start = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "hierhand", *args], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, env=USER_ENV)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode:
        raise SystemExit(f"hierhand {' '.join(args)} failed: {proc.stderr.read().decode()}")
    return wall, usage.ru_maxrss / 1024


def median(values) -> float:
    return statistics.median(values)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="pictures-") as tmp:
        out = Path(tmp)
        runs, plotted, animated, memory, graphs, validates = [], [], [], [], [], []
        timed("run", str(REGRASP), "-q", "--plot", "-o", str(out / "plotted"))  # writes the caches
        timed("graph", str(REGRASP), "-o", str(out / "wiring.png"))
        for _ in range(args.repeat):
            runs.append(timed("run", str(REGRASP), "-q", "-o", str(out / "run"))[0])
            plotted.append(timed("run", str(REGRASP), "-q", "--plot", "-o", str(out / "plotted"))[0])
            wall, mb = timed("animate", str(out / "run"), "-o", str(out / "hand.gif"))
            animated.append(wall)
            memory.append(mb)
            validates.append(timed("validate", str(REGRASP))[0])
            graphs.append(timed("graph", str(REGRASP), "-o", str(out / "wiring.png"))[0])
        import blocks
        from blocks.graph import render

        diagram = blocks.load_diagram(REGRASP)
        schedule = blocks.build_schedule(diagram, None)
        render(diagram, schedule, out / "warm.png")  # imports matplotlib and its fonts
        drawing = []
        for _ in range(args.repeat):
            start = time.perf_counter()
            render(diagram, schedule, out / "drawn.png")
            drawing.append(time.perf_counter() - start)
    run_s = median(runs)
    print(f"medians of {args.repeat} fresh processes each")
    print(f"run --plot: {median(plotted):.2f} s, run: {run_s:.2f} s: {median(plotted) / run_s:.2f}x (target <= 1.5x)")
    print(f"animate to GIF (default speed): {median(animated):.2f} s ({median(animated) / run_s:.1f}x run), "
          f"peak {max(memory):.0f} MB resident (targets <= 15 s, <= 250 MB)")
    print(f"graph -o wiring.png: {median(graphs):.2f} s, validate: {median(validates):.2f} s: "
          f"{median(graphs) / median(validates):.2f}x; the drawing alone {median(drawing):.2f} s (target < 1 s)")


if __name__ == "__main__":
    main()
