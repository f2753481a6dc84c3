"""Scheduler overhead: the toy multirate diagram (DESIGN section 5) through the YAML
loader and the executor, against a hand-written Python loop of the same equations.

Prints microseconds per base tick (0.1 ms) for both, median of several runs, and the
ratio. Target: at most 1 us per base tick through the executor.

    python benchmarks/scheduler.py [--t-end 1] [--repeat 7]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

import blocks

TOY = Path(__file__).resolve().parent.parent / "diagrams" / "toy.yaml"


def hand_loop(n_ticks: int) -> np.ndarray:
    """The toy diagram's equations written out: plant every tick, integ every 10, prop every 100."""
    xp = xi = yi = yprop = u = 0.0
    out = np.empty(n_ticks + 1)
    for k in range(n_ticks + 1):
        yp = xp
        out[k] = yp
        if k == n_ticks:
            break
        if k % 10 == 0:
            e = 1.0 - yp
            yi = xi
            if k % 100 == 0:
                yprop = 5.0 * e
            u = yi + yprop
            xi = xi + 0.02 * e
        xp = 0.999 * xp + 1.0e-4 * u
    return out


def timed(fn, repeat: int) -> tuple[float, object]:
    times, result = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=1.0, help="simulated seconds per run")
    ap.add_argument("--repeat", type=int, default=7, help="runs per measurement (median)")
    args = ap.parse_args()
    n_ticks = round(args.t_end / 1e-4)

    def framework():
        diagram = blocks.load_diagram(TOY)
        return blocks.simulate(diagram, t_end=args.t_end)

    def executor_only(diagram=blocks.load_diagram(TOY)):
        return blocks.simulate(diagram, t_end=args.t_end)

    t_hand, ref = timed(lambda: hand_loop(n_ticks), args.repeat)
    t_full, res = timed(framework, args.repeat)
    t_exec, _ = timed(executor_only, args.repeat)
    err = float(np.max(np.abs(res["plant.y"][1][:, 0] - ref)))
    per = 1e6 / n_ticks
    print(f"toy diagram, {args.t_end:g} s simulated = {n_ticks} base ticks of 0.1 ms, median of {args.repeat}")
    print(f"hand-written loop          : {t_hand * per:7.3f} us/tick")
    print(f"blocks (load + simulate)   : {t_full * per:7.3f} us/tick   ratio to hand loop {t_full / t_hand:6.2f}")
    print(f"blocks (simulate only)     : {t_exec * per:7.3f} us/tick   ratio to hand loop {t_exec / t_hand:6.2f}")
    print(f"max |difference| to hand loop: {err:.2e}")
    print(f"target: <= 1 us/tick through loader + scheduler: {'met' if t_full * per <= 1.0 else 'NOT met'}")


if __name__ == "__main__":
    main()
