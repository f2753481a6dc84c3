"""The re-grasp task with the native plant and with the plant as an exported FMU.

Wall time per simulated second of diagrams/regrasp.yaml (native HandPlant) and of
diagrams/regrasp_fmu.yaml (the same plant exported with `hierhand fmu export`, FMI 2
and 3, run through the FMU block at a 1 ms communication step), in one process, median
of several runs after a warm-up run; prints the ratio FMU / native. Both run the same C
core; the FMU adds the FMI calls (set inputs, doStep, get outputs) every millisecond.

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


def per_simulated_second(diagram, repeat: int) -> float:
    results = blocks.simulate(diagram)  # warm-up: JIT, FMU instantiation
    assert results.complete, results.status
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        blocks.simulate(diagram)
        times.append(time.perf_counter() - t0)
    return statistics.median(times) / float(diagram.t_end)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="runs per measurement (median)")
    args = ap.parse_args()
    native = per_simulated_second(blocks.load_diagram(ROOT / "diagrams" / "regrasp.yaml"), args.repeat)
    print(f"re-grasp, 1 s simulated, median of {args.repeat} runs after a warm-up run")
    print(f"  {'native HandPlant':<22}: {1000 * native:7.2f} ms per simulated s")
    with tempfile.TemporaryDirectory() as tmp:
        for fmi in (2, 3):
            fmu = export_plant_fmu(Path(tmp) / f"plant{fmi}.fmu", fmi=fmi)
            diagram = blocks.load_diagram(ROOT / "diagrams" / "regrasp_fmu.yaml",
                                          overrides={"plant.path": str(fmu)})
            wall = per_simulated_second(diagram, args.repeat)
            ratio = wall / native
            print(f"  {f'FMU plant (FMI {fmi})':<22}: {1000 * wall:7.2f} ms per simulated s   "
                  f"ratio to native {ratio:5.2f}   target <= {TARGET_RATIO}: {'met' if ratio <= TARGET_RATIO else 'MISSED'}")


if __name__ == "__main__":
    main()
