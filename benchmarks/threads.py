"""Threads: re-grasp runs serially against the same runs in a thread pool.

Each run loads diagrams/regrasp.yaml and simulates its 1 s (``blocks.load_diagram`` +
``blocks.engine.simulate``), as a user's ThreadPoolExecutor or a Dask worker's threads would.
The executor releases the GIL while it runs kernels that need none (``Kernel.nogil``:
the hand's and the library's), so threads run in parallel for the compiled stretches;
loading, planning and the Python between C calls still take turns on the GIL.

Reports, as medians of --repeat rounds after one warm-up round: the wall time of
--runs runs one after the other and in a pool of --threads threads (default: one per
core, at least 2), the speed-up, and whether every threaded run's logged samples and
times equal the serial run's to the last bit.

    python benchmarks/threads.py [--runs 8] [--threads N] [--repeat 5]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

import blocks

REGRASP = Path(__file__).resolve().parent.parent / "diagrams" / "regrasp.yaml"


def regrasp(_: int = 0) -> blocks.Results:
    return blocks.simulate(blocks.load_diagram(REGRASP))


def same(a: blocks.Results, b: blocks.Results) -> bool:
    """Every logged signal's times and values equal, bit for bit."""
    return list(a) == list(b) and all(np.array_equal(a[s][0], b[s][0]) and np.array_equal(a[s][1], b[s][1])
                                      for s in a)


def serial(runs: int) -> list[blocks.Results]:
    return [regrasp() for _ in range(runs)]


def threaded(runs: int, threads: int) -> list[blocks.Results]:
    with ThreadPoolExecutor(threads) as pool:
        return list(pool.map(regrasp, range(runs)))


def timed(fn, repeat: int) -> tuple[float, list[blocks.Results]]:
    """Median wall time of ``fn()`` over ``repeat`` rounds after one warm-up, and the
    results of all the rounds' runs."""
    results = fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        results = results + fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=8, help="re-grasp runs per round (default 8)")
    parser.add_argument("--threads", type=int, default=max(2, os.cpu_count() or 1),
                        help="pool threads (default: one per core, at least 2)")
    parser.add_argument("--repeat", type=int, default=5, help="timed rounds (default 5)")
    args = parser.parse_args()
    reference = regrasp()
    t_serial, serial_runs = timed(lambda: serial(args.runs), args.repeat)
    t_threads, threaded_runs = timed(lambda: threaded(args.runs, args.threads), args.repeat)
    equal = all(same(reference, r) for r in serial_runs + threaded_runs)
    print(f"re-grasp (diagrams/regrasp.yaml, 1 s simulated, load + simulate), {args.runs} runs per round, "
          f"median of {args.repeat} rounds after a warm-up round, {os.cpu_count()} cores")
    print(f"  serial                 {t_serial * 1e3:8.1f} ms   {t_serial / args.runs * 1e3:6.2f} ms per run")
    print(f"  {args.threads} threads              {t_threads * 1e3:8.1f} ms   "
          f"{t_threads / args.runs * 1e3:6.2f} ms per run")
    print(f"  speed-up               {t_serial / t_threads:8.2f}x")
    print(f"  results equal to a serial run, bit for bit: {'yes' if equal else 'NO'} "
          f"({len(serial_runs) + len(threaded_runs)} runs)")


if __name__ == "__main__":
    main()
