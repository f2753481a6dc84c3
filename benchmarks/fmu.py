"""The re-grasp task with the native plant, with the plant as an exported FMU (in the run's
process and in a process of its own), and as one exported closed-loop FMU stepped by fmpy.

Wall time per simulated second of diagrams/regrasp.yaml (native HandPlant) and of
diagrams/regrasp_fmu.yaml (the same plant exported with `hierhand fmu export`, FMI 2
and 3, run through the FMU block at a 1 ms communication step), in one process, median
of several runs after a warm-up run; prints the ratios FMU / native and, for the FMU run
in a process of its own ('isolation: process': each step one round trip through shared
memory), isolated / in-process. All run the same C core; the FMU adds the FMI calls (set
inputs, doStep, get outputs) every millisecond, the isolation a round trip to the FMU's
process. The first isolated run of a process also starts the process that forks the FMU
processes; that start-up is printed apart.

The plant alone: the exported plant FMU (FMI 2 and 3) stepped by fmpy's low-level slave
at 1 ms with zero inputs, against the native ``HandPlant`` block advanced 10 steps of
0.1 ms per call from Python (the same steps, one Python call per millisecond as fmpy's
doStep), the runs interleaved.

The whole closed loop exported (`hierhand fmu export diagrams/regrasp.yaml`, FMI 2 and 3)
is run by fmpy from its unpacked folder, instantiation included: its low-level slave
stepped at 1 ms (the native run's log interval), without and with reading every output
(the signals the native run logs) after each step, and ``simulate_fmu`` recording them.
The FMU's own C time is the native run's; what the lines add is fmpy's Python per call.

Targets: the FMU plant at most 1.3x the native run; the closed-loop FMU stepped by fmpy at
most 1.2x.

    python benchmarks/fmu.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import numpy as np

from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

import blocks
from hierhand.fmu_export import export_diagram_fmu, export_plant_fmu
from hierhand.model import HandPlant

ROOT = Path(__file__).resolve().parent.parent
TARGET_RATIO = 1.3
LOOP_TARGET_RATIO = 1.2


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


def stepped_wall(fmu: Path, unzipped: str, n: int, read: bool) -> float:
    """Wall time of fmpy's low-level FMU2Slave/FMU3Slave of ``fmu`` (unpacked in
    ``unzipped``), instantiation included, stepped ``n`` times by 1 ms with its inputs at
    their start values, reading every output after each step when ``read``."""
    md = read_model_description(str(fmu))
    refs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
    slave_class = FMU2Slave if md.fmiVersion.startswith("2") else FMU3Slave
    fmu_slave = slave_class(guid=md.guid, unzipDirectory=unzipped,
                            modelIdentifier=md.coSimulation.modelIdentifier, instanceName="bench")
    get = fmu_slave.getReal if md.fmiVersion.startswith("2") else fmu_slave.getFloat64
    t0 = time.perf_counter()
    fmu_slave.instantiate()
    if md.fmiVersion.startswith("2"):
        fmu_slave.setupExperiment(startTime=0.0)
    fmu_slave.enterInitializationMode()
    fmu_slave.exitInitializationMode()
    for k in range(n):
        fmu_slave.doStep(k * 1e-3, 1e-3)
        if read:
            get(refs)
    get(refs)
    wall = time.perf_counter() - t0
    fmu_slave.terminate()
    fmu_slave.freeInstance()
    return wall


def fmpy_walls(fmu: Path, folder: Path, repeat: int) -> dict[str, float]:
    """Median wall times per simulated second of the closed-loop FMU run by fmpy three ways
    (the first run of each, a warm-up, not counted): its low-level FMU2Slave/FMU3Slave
    stepped at 1 ms without and with reading every output after each step, and
    ``simulate_fmu`` recording every output at 1 ms."""
    md = read_model_description(str(fmu))
    unzipped = extract(str(fmu), folder)
    outputs = [v for v in md.modelVariables if v.causality == "output"]
    stop = float(md.defaultExperiment.stopTime)
    n = int(round(stop / 1e-3))

    def recorded() -> float:
        t0 = time.perf_counter()
        simulate_fmu(unzipped, model_description=md, output=[v.name for v in outputs], output_interval=1e-3)
        return time.perf_counter() - t0

    ways = {"fmpy doStep 1 ms": lambda: stepped_wall(fmu, unzipped, n, False),
            "fmpy doStep 1 ms + read outputs": lambda: stepped_wall(fmu, unzipped, n, True),
            "fmpy simulate_fmu, 1 ms record": recorded}
    walls = {}
    for name, way in ways.items():
        way()
        walls[name] = statistics.median(way() for _ in range(repeat)) / stop
    return walls


def native_plant_wall(n: int) -> float:
    """Wall time of the native HandPlant block advanced ``n`` times by 1 ms (10 steps of
    0.1 ms per call, zero inputs), from binding it: the plant FMU's work, called from
    Python once per millisecond as fmpy calls doStep."""
    t0 = time.perf_counter()
    plant = HandPlant()
    plant.bind(Fraction(1, 10000))
    state = plant.initial_state()
    inputs = {"tau": np.zeros(9), "f_ext": np.zeros(3)}
    plant.output(0.0, state, inputs)
    for k in range(n):
        state, _ = plant.advance(k * 1e-3, state, inputs, 10)
    return time.perf_counter() - t0


def plant_fmu_walls(folder: Path, repeat: int) -> dict[str, float]:
    """Median wall times of 1 s of the plant alone, natively (``native_plant_wall``) and as
    the exported plant FMU (FMI 2 and 3) stepped by fmpy at 1 ms with zero inputs, the
    runs interleaved (the first of each, a warm-up, not counted)."""
    n = 1000
    ways = {"native HandPlant.advance, 10 steps": lambda: native_plant_wall(n)}
    for fmi in (2, 3):
        fmu = export_plant_fmu(folder / f"plant{fmi}.fmu", fmi=fmi)
        unzipped = extract(str(fmu), folder / f"plant{fmi}")
        ways[f"plant FMU {fmi}, fmpy doStep 1 ms"] = \
            lambda fmu=fmu, unzipped=unzipped: stepped_wall(fmu, unzipped, n, False)
    times = {name: [] for name in ways}
    for run in range(repeat + 1):
        for name, way in ways.items():
            wall = way()
            if run:
                times[name].append(wall)
    return {name: statistics.median(t) for name, t in times.items()}


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
        plant = plant_fmu_walls(Path(tmp), args.repeat)
        alone = plant.pop("native HandPlant.advance, 10 steps")
        print(f"the plant alone, 1 s at 1 ms steps, zero inputs (interleaved runs, median of {args.repeat})")
        print(f"  {'native HandPlant.advance, 10 steps':<36}: {1000 * alone:7.2f} ms per simulated s")
        for way, wall in plant.items():
            print(f"  {way:<36}: {1000 * wall:7.2f} ms per simulated s   ratio to native {wall / alone:5.2f}")
        loop = blocks.load_diagram(ROOT / "diagrams" / "regrasp.yaml")
        for fmi in (2, 3):
            fmu = export_diagram_fmu(loop, Path(tmp) / f"loop{fmi}.fmu", fmi)
            for way, wall in fmpy_walls(fmu, Path(tmp) / f"loop{fmi}", args.repeat).items():
                ratio = wall / native
                print(f"  {f'loop FMU {fmi}, {way}':<44}: {1000 * wall:7.2f} ms per simulated s"
                      f"   ratio to native {ratio:5.2f}   target <= {LOOP_TARGET_RATIO}: "
                      f"{'met' if ratio <= LOOP_TARGET_RATIO else 'MISSED'}")


if __name__ == "__main__":
    main()
