"""The re-grasp task with the native plant and with the plant as an exported FMU, in the
run's process and in a process of its own.

Wall time per simulated second of diagrams/regrasp.yaml (native HandPlant) and of
diagrams/regrasp_fmu.yaml (the same plant exported with `hierhand fmu export`, FMI 2
and 3, run through the FMU block at a 1 ms communication step), in one process, median
of several runs after a warm-up run; prints the ratios FMU / native and, for the FMU run
in a process of its own ('isolation: process': each step one round trip through shared
memory), isolated / in-process. All run the same C core; the FMU adds the FMI calls (set
inputs, doStep, get outputs) every millisecond, the isolation a round trip to the FMU's
process. The first isolated run of a process also starts the process that forks the FMU
processes; that start-up is printed apart.

Target: the FMU plant at most 1.3x the native run.

    python benchmarks/fmu.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import blocks
from hierhand.fmu_export import export_plant_fmu

ROOT = Path(__file__).resolve().parent.parent
TARGET_RATIO = 1.3


def per_simulated_second(diagram, repeat: int) -> tuple[float, float]:
    """(the median wall time per simulated second, the warm-up run's wall time)."""
    t0 = time.perf_counter()
    results = blocks.simulate(diagram)  # warm-up: JIT, FMU instantiation (and, isolated, its process)
    first = time.perf_counter() - t0
    assert results.complete, results.status
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        blocks.simulate(diagram)
        times.append(time.perf_counter() - t0)
    return statistics.median(times) / float(diagram.t_end), first


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="runs per measurement (median)")
    args = ap.parse_args()
    native, _ = per_simulated_second(blocks.load_diagram(ROOT / "diagrams" / "regrasp.yaml"), args.repeat)
    print(f"re-grasp, 1 s simulated, median of {args.repeat} runs after a warm-up run")
    print(f"  {'native HandPlant':<36}: {1000 * native:7.2f} ms per simulated s")
    with tempfile.TemporaryDirectory() as tmp:
        for fmi in (2, 3):
            fmu = export_plant_fmu(Path(tmp) / f"plant{fmi}.fmu", fmi=fmi)
            walls = {}
            for isolation in ("process", "none"):
                diagram = blocks.load_diagram(ROOT / "diagrams" / "regrasp_fmu.yaml",
                                              overrides={"plant.path": str(fmu), "plant.isolation": isolation})
                walls[isolation], first = per_simulated_second(diagram, args.repeat)
                ratio = walls[isolation] / native
                where = "its own process" if isolation == "process" else "the run's process"
                line = (f"  {f'FMU plant (FMI {fmi}), {where}':<36}: {1000 * walls[isolation]:7.2f} ms per simulated s"
                        f"   ratio to native {ratio:5.2f}")
                if isolation == "none":
                    line += f"   target <= {TARGET_RATIO}: {'met' if ratio <= TARGET_RATIO else 'MISSED'}"
                print(line + f"   (first run {1000 * first:.0f} ms)")
            print(f"  {f'isolated / in-process (FMI {fmi})':<36}: {walls['process'] / walls['none']:7.2f}")


if __name__ == "__main__":
    main()
