"""Per-step cost of the hand plant at 0.1 ms with the object pinched by two fingers.

Reports, as medians over repeated runs that each start from the same pinched state:

- the bare compiled kernel (``advance_kernel`` called directly, rows preallocated);
- the block's ``advance`` with n = 10 (as the executor calls it between 1 ms controller
  events) and n = 1000, and the slow path (``update`` then ``output`` per step);
- their ratios to the bare kernel, and numba's cold-start compile time, measured in a
  subprocess with an empty NUMBA_CACHE_DIR (and a warm start from that cache).

Target: at most 1.5 us per step through ``advance``. Reference (shared notes): MuJoCo
about 6.5 us per step for this hand on this machine type.

    PYTHONPATH=. python benchmarks/plant.py
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from hierhand.model import HandPlant  # noqa: E402
from hierhand.model.kernel import advance_kernel  # noqa: E402
from hierhand.model.layout import N_OUTPUTS  # noqa: E402

DT = 1e-4
STEPS_PER_RUN = 2000  # 0.2 s simulated per timed run
RUNS = 7
TARGET_US = 1.5
MUJOCO_US = 6.5


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
    state, rows = plant.advance(0.0, plant.initial_state(), {"tau": tau}, 500)
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


def bench_kernel(plant, inputs, start) -> float:
    hand = plant.hand
    rows = np.empty((STEPS_PER_RUN, N_OUTPUTS))
    body = plant._body  # the bound parameters: the bare kernel sees exactly what advance does
    state = start.copy()

    def once():
        state[:] = start
        code, _, _ = advance_kernel(state, inputs["tau"], inputs["f_ext"], hand.fingers, body, hand.edges, rows)
        assert code == 0

    once()
    us = median_us_per_step(once)
    assert rows[-1, 36:38].tolist() == [1.0, 1.0], "contact lost during the kernel benchmark"
    return us


def bench_advance(plant, inputs, start, n: int) -> float:
    state = start.copy()
    calls = STEPS_PER_RUN // n
    last = {}

    def once():
        nonlocal state
        state[:] = start
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
    state = start.copy()

    def once():
        nonlocal state
        state[:] = start
        for i in range(STEPS_PER_RUN):
            state = plant.update(i * DT, state, inputs)
            plant.output((i + 1) * DT, state, inputs)

    once()
    return median_us_per_step(once)


COLD_SCRIPT = """
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


def compile_times() -> tuple[list[float], list[float]]:
    """(cold, warm) start times: [import, output, update, advance, Hand API] in seconds."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=str(ROOT))
        result = []
        for _ in range(2):
            out = subprocess.run(
                [sys.executable, "-c", COLD_SCRIPT], env=env, capture_output=True, text=True, check=True, cwd=ROOT
            )
            result.append([float(x) for x in out.stdout.split()])
    return result[0], result[1]


def main() -> None:
    plant, inputs, start = pinched_plant()
    kernel = bench_kernel(plant, inputs, start)
    adv10 = bench_advance(plant, inputs, start, 10)
    adv1000 = bench_advance(plant, inputs, start, 1000)
    slow = bench_update_output(plant, inputs, start)
    print(f"hand plant, dt = 0.1 ms, object pinched by thumb and forefinger; median of {RUNS} runs of {STEPS_PER_RUN} steps")
    print(f"  bare kernel                 {kernel:7.3f} us/step")
    print(f"  advance, n = 10             {adv10:7.3f} us/step   x{adv10 / kernel:5.2f} kernel")
    print(f"  advance, n = 1000           {adv1000:7.3f} us/step   x{adv1000 / kernel:5.2f} kernel")
    print(f"  update + output per step    {slow:7.3f} us/step   x{slow / kernel:5.2f} kernel")
    print(f"  target (advance)            {TARGET_US:7.3f} us/step   {'met' if max(adv10, adv1000) <= TARGET_US else 'MISSED'}")
    print(f"  reference: MuJoCo ~{MUJOCO_US} us/step (notes) -> advance n=10 is x{MUJOCO_US / adv10:.1f} faster")
    cold, warm = compile_times()
    labels = ("import", "first output", "first update", "first advance", "first Hand.mass_matrix")
    print("numba start-up (fresh NUMBA_CACHE_DIR, then the same cache again):")
    for label, c, w in zip(labels, cold, warm):
        print(f"  {label:24s} cold {c:7.2f} s   cached {w:6.2f} s")
    print(f"  total                    cold {sum(cold):7.2f} s   cached {sum(warm):6.2f} s")


if __name__ == "__main__":
    main()
