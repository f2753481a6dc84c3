"""Scheduler overhead: the toy multirate diagram (DESIGN section 5) through the YAML
loader and the executor, against a hand-written Python loop of the same equations.

Prints microseconds per base tick (0.1 ms) for both, median of several runs, and the
ratio. Target (issue 27): loader + executor at most 3 times the hand-written loop.

The same simulate with the check for outputs that are not finite turned off
(``check_finite=False``) shows what that check costs.

Then the same toy with one pure-Python block in the loop: ``u`` (the Sum that feeds the
plant, evaluated at every 1 ms event) as a ``PythonSum``, the library's Sum without its
kernel, so the executor calls its Python ``output`` 1000 times per simulated second
between compiled steps; load + simulate against the same hand-written loop.

Then planning cost: chains ``src: Constant -> g0 -> ... -> g{n-1}`` of n Gain blocks,
generated in memory, loaded and planned (``loads_diagram``) and run for 2 base ticks.
Time per block should stay roughly constant from 1 000 to 100 000 blocks (near-linear
planning); the ratio column compares it with the smallest chain. What growth remains is
mostly Python's cyclic garbage collector walking a heap of millions of objects;
``--no-gc`` pauses it during the chains to show the planner's own growth.

    python benchmarks/scheduler.py [--t-end 1] [--repeat 7] [--chains 1000,10000,100000]
                                   [--chain-repeat 3] [--no-gc]
"""

from __future__ import annotations

import argparse
import gc
import statistics
import time
from pathlib import Path

import numpy as np

import blocks
from blocks.library.math_blocks import Sum
from blocks.registry import block_types

TOY = Path(__file__).resolve().parent.parent / "diagrams" / "toy.yaml"
TARGET_RATIO = 3.0
"""Issue 27: load + simulate of the toy diagram within this many times the hand loop."""


class PythonSum(Sum):
    """The library's Sum run through its Python method only (no kernel)."""

    type_name = "PythonSum"

    def kernel(self):
        return None


def toy_with_python_block() -> str:
    """The toy diagram's text with ``u`` a ``PythonSum``."""
    text = TOY.read_text(encoding="utf-8")
    line = '  u:     {type: Sum, params: {signs: "++"}}'
    if line not in text:
        raise SystemExit(f"{TOY} no longer has the line {line!r}")
    return text.replace(line, line.replace("type: Sum", "type: PythonSum"))


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


def timed_pair(first, second, repeat: int) -> tuple[float, float]:
    """Median seconds of ``first`` and of ``second``, run by turns (so that a change in the
    machine's load falls on both alike)."""
    times: tuple[list[float], list[float]] = ([], [])
    for _ in range(repeat):
        for fn, into in ((first, times[0]), (second, times[1])):
            t0 = time.perf_counter()
            fn()
            into.append(time.perf_counter() - t0)
    return statistics.median(times[0]), statistics.median(times[1])


def chain_text(n: int) -> str:
    """A diagram of a Constant and ``n`` Gain blocks in a line, over 2 base ticks of 1 ms."""
    lines = ["time: {t_end: 2 ms}", "blocks:", "  src: {type: Constant, period: 1 ms, params: {value: 1.0}}"]
    lines += [f"  g{i}: {{type: Gain, params: {{k: 1.0}}}}" for i in range(n)]
    lines += ["connections:", "  - src.y -> g0.u"] + [f"  - g{i - 1}.y -> g{i}.u" for i in range(1, n)]
    lines.append(f"log: [g{n - 1}.y]")
    return "\n".join(lines) + "\n"


def chain_times(n: int, repeat: int) -> tuple[float, float]:
    """Median seconds to load + plan, and to simulate 2 ticks, a chain of ``n`` blocks."""
    text = chain_text(n)
    plans, runs = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        diagram = blocks.loads_diagram(text, filename=f"chain{n}")
        t1 = time.perf_counter()
        results = blocks.simulate(diagram)
        t2 = time.perf_counter()
        if results.status != "complete" or results[f"g{n - 1}.y"][1][-1, 0] != 1.0:
            raise SystemExit(f"chain of {n} blocks: wrong run ({results.status})")
        plans.append(t1 - t0)
        runs.append(t2 - t1)
    return statistics.median(plans), statistics.median(runs)


def report_chains(sizes: list[int], repeat: int, collect: bool) -> None:
    gc_note = "" if collect else ", garbage collector paused"
    print(f"\nplanning cost: chains src -> g0 -> ... of n Gain blocks, 2 base ticks, median of {repeat}{gc_note}")
    print(f"{'blocks':>8} {'load+plan s':>12} {'us/block':>9} {'ratio':>6} {'simulate s':>11} "
          f"{'us/block':>9} {'ratio':>6}")
    first = None
    for n in sizes:
        if not collect:
            gc.disable()
        try:
            plan, run = chain_times(n, repeat)
        finally:
            gc.enable()
        per = (plan / n * 1e6, run / n * 1e6)
        first = first or per
        print(f"{n:>8} {plan:>12.3f} {per[0]:>9.1f} {per[0] / first[0]:>6.2f} {run:>11.3f} "
              f"{per[1]:>9.1f} {per[1] / first[1]:>6.2f}")
    print("ratio: time per block against the smallest chain (near 1: linear growth)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=1.0, help="simulated seconds per run")
    ap.add_argument("--repeat", type=int, default=7, help="runs per measurement (median)")
    ap.add_argument("--chains", default="1000,10000,100000",
                    help="comma-separated chain lengths for the planning cost ('' to skip)")
    ap.add_argument("--chain-repeat", type=int, default=3, help="runs per chain length (median)")
    ap.add_argument("--no-gc", action="store_true", help="pause the garbage collector during the chains")
    args = ap.parse_args()
    n_ticks = round(args.t_end / 1e-4)

    def framework():
        diagram = blocks.load_diagram(TOY)
        return blocks.simulate(diagram, t_end=args.t_end)

    def executor_only(diagram=blocks.load_diagram(TOY)):
        return blocks.simulate(diagram, t_end=args.t_end)

    def executor_unchecked(diagram=blocks.load_diagram(TOY)):
        return blocks.simulate(diagram, t_end=args.t_end, check_finite=False)

    block_types()[PythonSum.type_name] = PythonSum
    python_text = toy_with_python_block()

    def with_python_block():
        return blocks.simulate(blocks.loads_diagram(python_text, filename="toy-python.yaml"), t_end=args.t_end)

    def python_block_executor_only(diagram=blocks.loads_diagram(python_text, filename="toy-python.yaml")):
        return blocks.simulate(diagram, t_end=args.t_end)

    t_hand, ref = timed(lambda: hand_loop(n_ticks), args.repeat)
    t_full, res = timed(framework, args.repeat)
    t_exec, t_unchecked = timed_pair(executor_only, executor_unchecked, args.repeat)
    t_python, res_python = timed(with_python_block, args.repeat)
    t_python_exec, _ = timed(python_block_executor_only, args.repeat)
    err = float(np.max(np.abs(res["plant.y"][1][:, 0] - ref)))
    err_python = float(np.max(np.abs(res_python["plant.y"][1][:, 0] - ref)))
    per = 1e6 / n_ticks
    print(f"toy diagram, {args.t_end:g} s simulated = {n_ticks} base ticks of 0.1 ms, median of {args.repeat}")
    print(f"hand-written loop          : {t_hand * per:7.3f} us/tick")
    print(f"blocks (load + simulate)   : {t_full * per:7.3f} us/tick   ratio to hand loop {t_full / t_hand:6.2f}")
    print(f"blocks (simulate only)     : {t_exec * per:7.3f} us/tick   ratio to hand loop {t_exec / t_hand:6.2f}")
    print(f"simulate, no finite check  : {t_unchecked * per:7.3f} us/tick   the check costs "
          f"{100 * (t_exec / t_unchecked - 1):+.1f} % of simulate only")
    print(f"toy, u a Python block      : {t_python * per:7.3f} us/tick   ratio to hand loop {t_python / t_hand:6.2f}"
          f"   (load + simulate)")
    print(f"toy, u a Python block      : {t_python_exec * per:7.3f} us/tick   ratio to hand loop "
          f"{t_python_exec / t_hand:6.2f}   (simulate only)")
    print(f"max |difference| to hand loop: {err:.2e} (toy), {err_python:.2e} (u a Python block)")
    print(f"target: <= {TARGET_RATIO:g}x the hand-written loop through loader + scheduler: "
          f"{'met' if t_full <= TARGET_RATIO * t_hand else 'NOT met'} ({t_full / t_hand:.2f}x)")
    sizes = [int(n) for n in args.chains.split(",") if n.strip()]
    if sizes:
        report_chains(sizes, args.chain_repeat, collect=not args.no_gc)


if __name__ == "__main__":
    main()
