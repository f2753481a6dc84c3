"""The engine against the physical floor: the toy diagram as a hand-written C loop.

The toy (diagrams/toy.yaml: a discrete plant at 0.1 ms, an integral controller at 1 ms, a
proportional one at 10 ms, every plant sample stored) written out as one C loop, built
with the project's compiler settings (Python's own flags plus
``blocks.engine.native_sources.CFLAGS``, as setup.py builds the extension), loaded with
ctypes and run in the same process, in the same loop of runs, as ``blocks.simulate`` of the
loaded diagram. Both allocate the array of plant samples they return on each call.

Prints, as medians of --repeat runs (each run of the loop times both, one after the
other), in CPU time of the calling thread (``time.thread_time``), which waiting for a
core shared with other work does not inflate:

- the toy's ``simulate`` over 1 s against the C loop over 1 s, and the ratio (target,
  issue 43: at most 4x);
- the fixed cost of one ``simulate`` call: a run of one tick (planning, binding, the
  result arrays and record), against the C loop's one tick;
- the marginal cost per tick, (run of T - run of one tick) / ticks, at 1 s, 10 s and
  100 s, for both, and the spread of simulate's over the three (target: within 1.2x);
- ``load_diagram`` of the toy (target: at most 1 ms).

The C loop's samples are checked against simulate's (the closed form the plant's kernel
steps with rounds differently from the loop's recurrence, so within 1e-12, not bitwise).

    python benchmarks/floor.py [--repeat 9] [--no-long]
"""

from __future__ import annotations

import argparse
import ctypes
import shlex
import statistics
import subprocess
import sysconfig
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

import blocks
from blocks.engine.native_sources import CFLAGS

TOY = Path(__file__).resolve().parent.parent / "diagrams" / "toy.yaml"
TARGET_RATIO = 4.0
TARGET_SPREAD = 1.2
CLOCK = time.thread_time
"""The time this thread spent on the CPU (its page faults included): on a machine shared
with other work, a long run's wall time also counts the time others had the cores."""
LOOP_C = r"""
#include <stdint.h>
/* The toy: y = c x of the plant logged at every tick; at every 10th tick the error
   e = ref - y, the integral's output and update, at every 100th the gain's output, and the
   plant's input u = integral + gain held until the next one; x = a x + b u every tick. */
__attribute__((visibility("default"))) void toy(int64_t n_ticks, const double *p, double *log)
{
    double ap = p[0], bp = p[1], cp = p[2], ai = p[3], bi = p[4], ci = p[5], k = p[6], ref = p[7];
    double xp = p[8], xi = p[9], prop = 0.0, u = 0.0;
    for (int64_t tick = 0;; tick++) {
        double y = cp * xp;
        log[tick] = y;
        if (tick == n_ticks)
            return;
        if (tick % 10 == 0) {
            double e = ref - y, integ = ci * xi;
            if (tick % 100 == 0)
                prop = k * e;
            u = integ + prop;
            xi = ai * xi + bi * e;
        }
        xp = ap * xp + bp * u;
    }
}
"""


def build_loop(folder: Path):
    """The C loop built as a shared library with the extension's flags; its ``toy``."""
    source, library = folder / "toy_loop.c", folder / "toy_loop.so"
    source.write_text(LOOP_C, encoding="utf-8")
    cc = shlex.split(sysconfig.get_config_var("CC") or "cc")
    flags = shlex.split(sysconfig.get_config_var("CFLAGS") or "") + CFLAGS + ["-std=c11", "-fPIC", "-shared"]
    subprocess.run([*cc, *flags, str(source), "-o", str(library)], check=True)
    toy = ctypes.CDLL(str(library)).toy
    toy.restype = None
    toy.argtypes = [ctypes.c_int64, ctypes.c_void_p, ctypes.c_void_p]
    return toy


def parameters(diagram) -> np.ndarray:
    """The loop's numbers, read from the loaded toy's blocks."""
    plant, integ = (diagram.blocks[n].block for n in ("plant", "integ"))
    return np.array([plant.A[0, 0], plant.B[0, 0], plant.C[0, 0], integ.A[0, 0], integ.B[0, 0], integ.C[0, 0],
                     diagram.blocks["prop"].block.k, diagram.blocks["ref"].block.value[0],
                     plant.initial_state()[0], integ.initial_state()[0]], dtype=float)


def options() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=9, help="runs per measurement (median; at least 7)")
    parser.add_argument("--no-long", action="store_true", help="leave out the 100 s run")
    return parser.parse_args()


def main() -> None:
    args = options()
    diagram = blocks.load_diagram(TOY)
    tick = 1e-4
    p = parameters(diagram)
    lengths = {"one tick": 1, "1 s": 10_000, "10 s": 100_000}
    if not args.no_long:
        lengths["100 s"] = 1_000_000
    with tempfile.TemporaryDirectory() as tmp:
        toy = build_loop(Path(tmp))

        def loop(n: int) -> np.ndarray:
            log = np.empty(n + 1)
            toy(n, p.ctypes.data, log.ctypes.data)
            return log

        def hierhand(n: int) -> np.ndarray:
            return blocks.simulate(diagram, t_end=Fraction(n, 10_000))["plant.y"][1][:, 0]

        check = hierhand(10_000)
        gap = float(np.max(np.abs(loop(10_000) - check)))
        if gap > 1e-12:
            raise SystemExit(f"the C loop and simulate disagree by {gap:g}")
        times: dict[str, dict[str, list[float]]] = {name: {"loop": [], "simulate": []} for name in lengths}
        for _ in range(args.repeat):
            for name, n in lengths.items():
                for who, fn in (("loop", loop), ("simulate", hierhand)):
                    fn(n)  # warm: the log's pages, the diagram's plan for this length
                    t0 = CLOCK()
                    fn(n)
                    times[name][who].append(CLOCK() - t0)
    med = {name: {who: statistics.median(ts) for who, ts in v.items()} for name, v in times.items()}

    print(f"toy diagram ({TOY.name}), base tick {tick * 1e6:g} us; medians of {args.repeat} runs, C loop and "
          f"simulate timed in the same loop (thread CPU time); samples agree within {gap:.1e}")
    one = med["1 s"]
    print(f"  1 s (10 000 ticks):  C loop {one['loop'] * 1e6:8.1f} us   simulate {one['simulate'] * 1e6:8.1f} us"
          f"   ratio {one['simulate'] / one['loop']:5.2f}x   (target <= {TARGET_RATIO:g}x)")
    fixed = med["one tick"]
    print(f"  fixed cost of a call (a run of one tick):  C loop {fixed['loop'] * 1e6:7.2f} us   "
          f"simulate {fixed['simulate'] * 1e6:7.1f} us")
    marginal = {}
    for name, n in lengths.items():
        if n == 1:
            continue
        m = {who: (med[name][who] - fixed[who]) / (n - 1) for who in ("loop", "simulate")}
        marginal[name] = m["simulate"]
        print(f"  marginal cost per tick at {name:5s}:  C loop {m['loop'] * 1e9:6.2f} ns   simulate "
              f"{m['simulate'] * 1e9:6.2f} ns   ratio {m['simulate'] / m['loop']:5.2f}x")
    spread = max(marginal.values()) / min(marginal.values())
    print(f"  simulate's marginal cost per tick, largest / smallest over {', '.join(marginal)}: {spread:.2f}x"
          f"   (target <= {TARGET_SPREAD:g}x)")
    print(f"  load_diagram of the toy: {loading(args.repeat) * 1e3:.2f} ms read and planned (target <= 1 ms)")


def loading(repeat: int) -> float:
    """The median of ``load_diagram`` of the toy (read, checked and planned)."""
    times = []
    for _ in range(repeat):
        t0 = CLOCK()
        blocks.load_diagram(TOY)
        times.append(CLOCK() - t0)
    return statistics.median(times)


if __name__ == "__main__":
    main()
