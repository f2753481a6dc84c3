"""Per-step cost of the hand plant at 0.1 ms with the object pinched by two fingers.

Reports, as medians over repeated runs that each start from the same pinched state:

- the bare C core: ``hierhand._native.advance`` called directly over 2000 steps into
  preallocated rows (the baseline, in this process);
- the block's ``advance`` with n = 10 (as the executor calls it between 1 ms controller
  events) and n = 1000, and the slow path (``update`` then ``output`` per step);
- their ratios to the bare core, and the start-up of a fresh process (import, first
  output, update, advance and Hand query): there is nothing to compile at run time.

Target: at most 0.8 us per step through ``advance`` at n = 10. Reference: MuJoCo stepping
the same pinched hand, about 4.75 us per step on this machine type.

    python benchmarks/plant.py
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from hierhand import _native
from hierhand.model import HandPlant
from hierhand.layouts import OUTPUT

ROOT = Path(__file__).resolve().parents[1]
DT = 1e-4
STEPS_PER_RUN = 2000  # 0.2 s simulated per timed run
RUNS = 9
TARGET_US = 0.8
MUJOCO_US = 4.75


def pinched_plant():
    """A plant and the torques and state of a settled thumb-forefinger pinch."""
    plant = HandPlant()
    plant.bind(DT)
    hand = plant.hand
    q0 = hand.q0
    tips = hand.tip_positions(q0)
    r = hand.tip_radius
    points = np.array([tips[0] + [r[0], 0.0], tips[1] - [r[1], 0.0], tips[2]])
    share = hand.params.object.mass * 9.81 / 2
    squeeze = 1.5 * share / hand.params.contact.mu_s
    tau = hand.static_torques(q0, [[squeeze, share], [-squeeze, share], [0.0, 0.0]], points)
    state, rows = plant.advance(0.0, plant.initial_state(), {"tau": tau, "f_ext": np.zeros(3)}, 500)
    assert rows["contact"][-1].tolist() == [1.0, 1.0, 0.0], "benchmark setup is not pinched"
    return plant, {"tau": tau, "f_ext": np.zeros(3)}, state


def median_us_per_step(run_once) -> float:
    """Median over RUNS of the per-step time of ``run_once()`` (which does STEPS_PER_RUN)."""
    times = []
    for _ in range(RUNS):
        t0 = time.perf_counter()
        run_once()
        times.append((time.perf_counter() - t0) / STEPS_PER_RUN * 1e6)
    return statistics.median(times)


def bench_core(plant, inputs, start) -> float:
    rows = np.empty((STEPS_PER_RUN, OUTPUT.size))
    state = start.copy()
    model = plant._model  # the bound model: the bare core steps exactly what advance does

    def once():
        state[:] = start
        code, _, _ = _native.advance(model, state, inputs["tau"], inputs["f_ext"], rows)
        assert code == 0

    once()
    us = median_us_per_step(once)
    assert rows[-1, 36:38].tolist() == [1.0, 1.0], "contact lost during the core benchmark"
    return us


def bench_advance(plant, inputs, start, n: int) -> float:
    calls = STEPS_PER_RUN // n
    last = {}

    def once():
        state = start.copy()
        t = 0.0
        for _ in range(calls):
            state, rows = plant.advance(t, state, inputs, n)
            t += n * DT
        last.update(rows)

    once()
    us = median_us_per_step(once)
    assert last["contact"][-1, :2].tolist() == [1.0, 1.0], "contact lost during the advance benchmark"
    return us


def bench_update_output(plant, inputs, start) -> float:
    def once():
        state = start.copy()
        for i in range(STEPS_PER_RUN):
            state = plant.update(i * DT, state, inputs)
            plant.output((i + 1) * DT, state, inputs)

    once()
    return median_us_per_step(once)


START_SCRIPT = """
import time
t0 = time.perf_counter()
import numpy as np
from hierhand.model import HandPlant
t1 = time.perf_counter()
p = HandPlant(); p.bind(1e-4); s = p.initial_state(); tau = np.zeros(9)
p.output(0.0, s, {"tau": tau}); t2 = time.perf_counter()
p.update(0.0, s, {"tau": tau}); t3 = time.perf_counter()
p.advance(0.0, s, {"tau": tau}, 10); t4 = time.perf_counter()
p.hand.mass_matrix(p.hand.q0); t5 = time.perf_counter()
print(t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4)
"""


def start_up() -> list[float]:
    """Seconds for [import, first output, first update, first advance, first Hand query] in a
    fresh process (median of three processes)."""
    runs = []
    for _ in range(3):
        out = subprocess.run([sys.executable, "-c", START_SCRIPT], capture_output=True, text=True, check=True,
                             cwd=ROOT)
        runs.append([float(x) for x in out.stdout.split()])
    return [statistics.median(column) for column in zip(*runs)]


def main() -> None:
    plant, inputs, start = pinched_plant()
    core = bench_core(plant, inputs, start)
    adv10 = bench_advance(plant, inputs, start, 10)
    adv1000 = bench_advance(plant, inputs, start, 1000)
    slow = bench_update_output(plant, inputs, start)
    print(f"hand plant, dt = 0.1 ms, object pinched by thumb and forefinger; median of {RUNS} runs of "
          f"{STEPS_PER_RUN} steps")
    print(f"  bare C core (one call)      {core:7.3f} us/step")
    print(f"  advance, n = 10             {adv10:7.3f} us/step   x{adv10 / core:5.2f} core")
    print(f"  advance, n = 1000           {adv1000:7.3f} us/step   x{adv1000 / core:5.2f} core")
    print(f"  update + output per step    {slow:7.3f} us/step   x{slow / core:5.2f} core")
    print(f"  target (advance, n = 10)    {TARGET_US:7.3f} us/step   {'met' if adv10 <= TARGET_US else 'MISSED'}")
    print(f"  reference: MuJoCo ~{MUJOCO_US} us/step on the same hand -> advance n=10 is x{MUJOCO_US / adv10:.1f}"
          " faster")
    labels = ("import", "first output", "first update", "first advance", "first Hand.mass_matrix")
    print("start-up of a fresh process (median of 3):")
    times = start_up()
    for label, t in zip(labels, times):
        print(f"  {label:24s} {t * 1e3:8.1f} ms")
    print(f"  total                    {sum(times) * 1e3:8.1f} ms")


if __name__ == "__main__":
    main()
