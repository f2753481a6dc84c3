"""Re-grasp end to end: diagrams/regrasp.yaml, 1 s, loader + executor vs the bare C core of the plant.

The re-grasp diagram simulated for 1 s through the YAML loader and the executor, against
the bare C core of the plant over the same 0.1 ms steps.

Reports, as medians of --repeat runs after one warm-up run:

- full: ``blocks.load_diagram`` + ``blocks.simulate`` (ms per simulated second and the
  real-time factor, simulated / wall time);
- simulate only, the diagram loaded once;
- the bare C core (``hierhand._native.advance``): the same number of plant steps from the
  plant's initial state under constant pinching torques (gravity compensation plus an
  inward squeeze on thumb and forefinger tips and an upward share of the object's
  weight each, ``f_ext`` zero), called in chunks of 10 steps (as the executor does
  between 1 ms controller events) and in one call; the open-loop pinch drifts apart after
  about 0.4 s, so a third run ("pinch held") restarts from the initial state every 0.25 s
  to show the cost with the object held throughout;
- the split of the full run: the plant (bare core, chunked) against the rest
  (controllers, executor, loader, logging).

Targets (issue 15): at most 15 ms of wall time per simulated second through loader +
scheduler, and at most 4 ms per simulated second above the bare plant core (chunked).
Reference: MuJoCo stepping the same hand, controlled every 1 ms from Python, needs about
71 ms per simulated second on this machine type.

    python benchmarks/regrasp.py [--repeat 5] [--profile]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

import blocks
from hierhand import _native
from hierhand.layouts import OUTPUT

ROOT = Path(__file__).resolve().parent.parent
REGRASP = ROOT / "diagrams" / "regrasp.yaml"
CHUNK = 10  # plant steps between 1 ms controller events
SQUEEZE = 3.0  # N, inward on thumb and forefinger tips
TARGET_MS = 15.0
TARGET_ABOVE_CORE_MS = 4.0
MUJOCO_MS = 71.0
HOLD_STEPS = 2500  # the open-loop pinch holds about 0.4 s; restart every 0.25 s for the held variant

_CONTACT_COL = OUTPUT.CONTACT  # first column of plant.contact


def timed(fn, repeat: int) -> tuple[float, object]:
    """Median wall time of ``fn()`` over ``repeat`` runs, after one warm-up call."""
    result = fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def pinch_torques(hand, q) -> np.ndarray:
    """Gravity compensation at ``q`` plus J^T of the pinch forces at the tips' inner faces."""
    tips = hand.tip_positions(q)
    r = hand.tip_radius
    points = np.array([tips[0] + [r[0], 0.0], tips[1] - [r[1], 0.0], tips[2]])
    share = hand.params.object.mass * abs(hand.params.gravity[1]) / 2  # 1.47 N for the shipped hand
    forces = [[SQUEEZE, share], [-SQUEEZE, share], [0.0, 0.0]]
    return hand.static_torques(q, forces, points)


def core_runner(plant, n_steps: int, chunk: int, segment: int | None = None):
    """A callable running ``n_steps`` bare core steps from the plant's initial state in
    calls of ``chunk`` steps, restarting from the initial state every ``segment`` steps
    (default: never), and one doing the same while returning the contact flags per step.
    """
    hand = plant.hand
    model = plant._model  # the bound model: the core steps exactly what advance does
    start = plant.initial_state()
    tau = pinch_torques(hand, hand.q0)
    f_ext = np.zeros(3)
    segment = n_steps if segment is None else segment
    plan = []  # per segment, the steps of each core call
    for s0 in range(0, n_steps, segment):
        seg = min(segment, n_steps - s0)
        plan.append([chunk] * (seg // chunk) + ([seg % chunk] if seg % chunk else []))
    rows = {n: np.empty((n, OUTPUT.size)) for seg in plan for n in seg}
    state = start.copy()

    def once(record=None):
        k = 0
        for seg in plan:
            state[:] = start
            for n in seg:
                out = rows[n]
                code, _, _ = _native.advance(model, state, tau, f_ext, out)
                if code:
                    raise RuntimeError(f"bare core failed with code {code}")
                if record is not None:
                    record[k : k + n] = out[:, _CONTACT_COL : _CONTACT_COL + 3]
                k += n

    def contact() -> np.ndarray:
        """(3,) fraction of the steps each finger (thumb, fore, middle) ends in contact."""
        record = np.empty((n_steps, 3))
        once(record)
        return record.mean(axis=0)

    return once, sum(len(seg) for seg in plan), contact


def profile_simulate(diagram, t_end, top: int = 10) -> None:
    import cProfile
    import pstats

    prof = cProfile.Profile()
    prof.enable()
    blocks.simulate(diagram, t_end=t_end)
    prof.disable()
    print(f"cProfile of one simulate (top {top} by tottime; profiling inflates Python-side costs):")
    pstats.Stats(prof).sort_stats("tottime").print_stats(top)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="runs per measurement (median)")
    ap.add_argument("--profile", action="store_true", help="also cProfile one simulate (top 10 by tottime)")
    args = ap.parse_args()

    diagram = blocks.load_diagram(REGRASP)
    t_end = float(diagram.t_end)
    plant = diagram.blocks["plant"].block
    dt = plant.dt
    n_steps = round(t_end / dt)

    def full():
        d = blocks.load_diagram(REGRASP)
        return blocks.simulate(d)

    def simulate_only():
        return blocks.simulate(diagram)

    t_full, res = timed(full, args.repeat)
    t_sim, _ = timed(simulate_only, args.repeat)

    chunked, calls, contact_c = core_runner(plant, n_steps, CHUNK)
    t_kc, _ = timed(chunked, args.repeat)
    single, _, _ = core_runner(plant, n_steps, n_steps)
    t_k1, _ = timed(single, args.repeat)
    held, calls_h, contact_h = core_runner(plant, n_steps, CHUNK, HOLD_STEPS)
    t_kh, _ = timed(held, args.repeat)

    per = 1e3 / t_end  # seconds of wall time -> ms per simulated second
    ms_full, ms_sim, ms_kc, ms_k1, ms_kh = (x * per for x in (t_full, t_sim, t_kc, t_k1, t_kh))

    def line(label: str, ms: float) -> str:
        return f"  {label:38s} {ms:8.2f} ms per simulated s   real-time factor {1e3 / ms:6.1f}x"

    def share(c: np.ndarray) -> str:
        return "/".join(f"{x:.0%}" for x in c)

    print(f"re-grasp diagram ({REGRASP.relative_to(ROOT)}), {t_end:g} s simulated = {n_steps} plant steps of "
          f"{dt * 1e3:g} ms; median of {args.repeat} runs after a warm-up run")
    print(f"  run status: {res.status}")
    print(line("full (load + simulate)", ms_full))
    print(line("simulate only (diagram loaded once)", ms_sim))
    print(line(f"bare core, {calls} calls of {CHUNK} steps", ms_kc))
    print(line(f"bare core, 1 call of {n_steps} steps", ms_k1))
    print(line(f"bare core, {calls_h} calls, pinch held", ms_kh))
    print(f"    constant pinch torques (squeeze {SQUEEZE:g} N, f_ext 0) from the initial state: thumb/fore/middle in"
          f" contact {share(contact_c())} of the steps;")
    print(f"    the open-loop pinch is lost after ~0.4 s, so 'pinch held' restarts every {HOLD_STEPS * dt:g} s"
          f" ({share(contact_h())})")
    print(f"  ratio full / bare core: {ms_full / ms_kc:6.2f} (chunked)   {ms_full / ms_k1:6.2f} (one call)"
          f"   {ms_full / ms_kh:6.2f} (chunked, pinch held)")
    print(f"  ratio simulate only / bare core (chunked): {ms_sim / ms_kc:6.2f}")
    rest = ms_full - ms_kc
    print(f"  split of the full run, ms per simulated s: plant (bare core, chunked) {ms_kc:6.2f}"
          f" ({ms_kc / ms_full:.0%}), rest (controllers + executor) {rest:6.2f} ({rest / ms_full:.0%}),"
          f" of which load + schedule {ms_full - ms_sim:5.2f}")
    print(f"  reference: MuJoCo stepping the same hand, controlled every 1 ms from Python: ~{MUJOCO_MS:g} ms per"
          f" simulated s; full run / MuJoCo = {ms_full / MUJOCO_MS:.2f}")
    print(f"target: <= {TARGET_MS:g} ms per simulated second: {'met' if ms_full <= TARGET_MS else 'NOT met'}")
    print(f"target: <= {TARGET_ABOVE_CORE_MS:g} ms per simulated second above the bare core (chunked): "
          f"{'met' if rest <= TARGET_ABOVE_CORE_MS else 'NOT met'} ({rest:.2f} ms)")
    if args.profile:
        profile_simulate(diagram, t_end)


if __name__ == "__main__":
    main()
