"""A model-exchange FMU through the FMU block and through fmpy's own ME simulation.

Wall time of 10 s of the driven oscillator of tests/blocks/fmu/sources/linear.c (an FMI 2
model-exchange FMU compiled here) sampled every 1 ms: the FMU block at a 1 ms period, and
``fmpy.simulate_fmu(fmi_type='ModelExchange')`` with a 1 ms output interval, both with
CVode (relative tolerance 1e-6) and with Euler (0.1 ms steps; fmpy's Euler steps and
samples at 0.1 ms, every tenth sample kept). Median of several runs after a warm-up run,
in one process; prints the ratio block / fmpy, with the FMU in the run's process as
fmpy's is ('isolation: none'). The block integrates in C between its hits (CVode's
right-hand side, Euler's sub-steps) and runs Python once per hit; fmpy runs Python once
per output point, and for CVode in every right-hand side evaluation. Also the block with
the FMU in a process of its own ('isolation: process', the default for this FMU), whose
hits run Python in both processes and take a round trip each: the ratio to the block in
the run's process.

Target: the block (in the run's process) at most 1.25x fmpy with either solver.

    python benchmarks/fmu_exchange.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import fmpy

import blocks

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
from tests.blocks.fmu.build import build_error, me_fmu  # noqa: E402

TARGET_RATIO = 1.25
T_END = 10.0


def median_time(call, repeat: int) -> float:
    call()  # warm-up
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        call()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    why = build_error()
    if why:
        raise SystemExit(f"cannot build the test FMU: {why}")
    with tempfile.TemporaryDirectory() as folder:
        path = me_fmu(Path(folder), "linear", 2)
        cases = {"cvode": ("", {"relative_tolerance": 1e-6}),
                 "euler": (", solver: euler, substep: 0.1 ms", {"solver": "Euler", "step_size": 1e-4,
                                                                  "output_interval": 1e-4})}
        worst = 0.0
        for name, (params, theirs) in cases.items():
            def diagram(isolation: str):
                return blocks.loads_diagram(f"""
time: {{t_end: {T_END} s}}
blocks:
  f: {{type: FMU, period: 1 ms, params: {{path: '{path}', tolerance: 1e-6{params}, isolation: {isolation}}}}}
log: [f.x]
""")
            inside, isolated = diagram("none"), diagram("process")
            options = {"output_interval": 1e-3, **theirs}
            ours = median_time(lambda: blocks.simulate(inside), args.repeat)
            apart = median_time(lambda: blocks.simulate(isolated), args.repeat)
            reference = median_time(lambda: fmpy.simulate_fmu(str(path), fmi_type="ModelExchange", stop_time=T_END,
                                                             record_events=False, **options), args.repeat)
            ratio = ours / reference
            worst = max(worst, ratio)
            print(f"{name}: block {ours * 1e3:7.1f} ms, fmpy {reference * 1e3:7.1f} ms for {T_END:g} s: "
                  f"{ratio:.2f}x; the FMU in a process of its own {apart * 1e3:7.1f} ms: {apart / ours:.2f}x the block")
    print(f"worst ratio {worst:.2f}x (target <= {TARGET_RATIO}x): {'met' if worst <= TARGET_RATIO else 'MISSED'}")


if __name__ == "__main__":
    main()
