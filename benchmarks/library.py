"""The library's signal blocks in a diagram, against a hand-written Python loop of the same
equations (issue 31: within 3x of it).

The diagram is a position servo made of new library blocks: a Pulse reference through a
RateLimiter, a PID with output limits and clamping anti-windup at 1 ms, a Sine
disturbance, a DeadZone actuator, and a plant of two DiscreteIntegrators with a Gain
for drag at 0.1 ms, measured through a Quantizer (an encoder) and a MovingAverage. The
loop computes the same thing tick by tick in Python floats, as the executor orders it
(outputs of the blocks that fire, then their updates); the benchmark checks that both give
the same position and prints microseconds per 0.1 ms tick for both, medians of several
runs, and the ratios.

    python benchmarks/library.py [--t-end 2] [--repeat 7]
"""

from __future__ import annotations

import argparse
import math

import numpy as np

import blocks
from scheduler import timed  # the benchmark beside this one: the median of repeated runs

TARGET_RATIO = 3.0
"""Issue 31: a diagram of the new blocks within this many times the hand-written loop."""

SERVO = """
name: library-servo
description: a position servo of library blocks, controller at 1 ms, plant at 0.1 ms
blocks:
  ref:   {type: Pulse, period: 1 ms, params: {amplitude: 1.0, period: 1.0, duty: 0.5}}
  slew:  {type: RateLimiter, period: 1 ms, params: {rising: 4.0, falling: -4.0}}
  err:   {type: Sum, params: {signs: "+-"}}
  pid:   {type: PID, period: 1 ms, params: {P: 8.0, I: 20.0, D: 0.4, N: 200, lower: -5, upper: 5,
                                            anti_windup: clamping}}
  dist:  {type: Sine, period: 1 ms, params: {amplitude: 0.3, frequency: 2.0}}
  force: {type: Sum, params: {signs: "++"}}
  act:   {type: DeadZone, params: {start: -0.05, end: 0.05}}
  drag:  {type: Gain, params: {k: 0.5}}
  acc:   {type: Sum, params: {signs: "+-"}}
  vel:   {type: DiscreteIntegrator, period: 0.1 ms}
  pos:   {type: DiscreteIntegrator, period: 0.1 ms}
  enc:   {type: Quantizer, params: {interval: 0.001}}
  avg:   {type: MovingAverage, period: 1 ms, params: {window: 4}}
connections:
  - ref.y -> slew.u
  - slew.y -> err.u0
  - avg.y -> err.u1
  - err.y -> pid.u
  - pid.y -> force.u0
  - dist.y -> force.u1
  - force.y -> act.u
  - act.y -> acc.u0
  - drag.y -> acc.u1
  - acc.y -> vel.u
  - vel.y -> drag.u
  - vel.y -> pos.u
  - pos.y -> enc.u
  - enc.y -> avg.u
log: [pos.y]
"""

TICKS_PER_SECOND = 10000
TICK = 1e-4
CONTROL = 10
"""Base ticks per controller hit (1 ms)."""


def rounded(x: float) -> float:
    """C's round: halves away from zero."""
    r = float(math.trunc(x))
    return r + math.copysign(1.0, x) if abs(x - r) >= 0.5 else r


def hand_loop(n_ticks: int) -> np.ndarray:
    """The servo's equations, tick by tick: the position at every 0.1 ms tick."""
    T, Tc = TICK, 1e-3
    P, I, D, N, lo, hi = 8.0, 20.0, 0.4, 200.0, -5.0, 5.0
    omega = 2.0 * math.pi * 2.0
    xv = xp = 0.0                      # integrator states (their outputs)
    slew_prev = 0.0                    # the rate limiter's previous output
    window = [0.0, 0.0, 0.0]           # the moving average's previous three inputs, oldest first
    xi = xf = 0.0                      # the PID's integrator and derivative filter
    act = 0.0                          # the actuator's held output
    out = np.empty(n_ticks + 1)
    for k in range(n_ticks + 1):
        t = k / TICKS_PER_SECOND  # as the executor computes it: k * tick, one rounding
        v, p = xv, xp
        q = 0.001 * rounded(p / 0.001)
        control = k % CONTROL == 0
        if control:
            phase = t / 1.0
            cycles = math.floor(phase + 1e-9)
            r = 1.0 if cycles >= 0.0 and phase - cycles < 0.5 - 1e-9 else 0.0
            rate = (r - slew_prev) / Tc
            s = Tc * 4.0 + slew_prev if rate > 4.0 else Tc * -4.0 + slew_prev if rate < -4.0 else r
            m = (window[0] + window[1] + window[2] + q) / 4.0
            e = s - m
            d = N * (D * e - xf)
            unlimited = P * e + xi + d
            y = min(max(unlimited, lo), hi)
            f = y + 0.3 * math.sin(omega * t)
            act = f - 0.05 if f > 0.05 else f + 0.05 if f < -0.05 else 0.0
        acc = act - 0.5 * v
        out[k] = p
        if k == n_ticks:
            break
        xv += T * acc
        xp += T * v
        if control:
            slew_prev = s
            window = [window[1], window[2], q]
            vi = I * e
            excess = unlimited - y
            if excess != 0.0 and excess * vi > 0.0:
                vi = 0.0
            xi += Tc * vi
            xf += Tc * d
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=2.0, help="simulated seconds per run")
    ap.add_argument("--repeat", type=int, default=7, help="runs per measurement (median)")
    args = ap.parse_args()
    n_ticks = round(args.t_end / TICK)

    def framework():
        return blocks.simulate(blocks.loads_diagram(SERVO, filename="servo"), t_end=args.t_end)

    def executor_only(diagram=blocks.loads_diagram(SERVO, filename="servo")):
        return blocks.simulate(diagram, t_end=args.t_end)

    t_hand, reference = timed(lambda: hand_loop(n_ticks), args.repeat)
    t_full, results = timed(framework, args.repeat)
    t_exec, _ = timed(executor_only, args.repeat)
    position = results["pos.y"][1][:, 0]
    err = float(np.max(np.abs(position - reference)))
    per = 1e6 / n_ticks
    print(f"library servo diagram, {args.t_end:g} s simulated = {n_ticks} base ticks of 0.1 ms, "
          f"median of {args.repeat}")
    print(f"hand-written loop          : {t_hand * per:7.3f} us/tick")
    print(f"blocks (load + simulate)   : {t_full * per:7.3f} us/tick   ratio to hand loop {t_full / t_hand:6.2f}")
    print(f"blocks (simulate only)     : {t_exec * per:7.3f} us/tick   ratio to hand loop {t_exec / t_hand:6.2f}")
    print(f"max |position difference| to the hand loop: {err:.2e} (of a travel of {np.ptp(reference):.3f})")
    print(f"target: <= {TARGET_RATIO:g}x the hand-written loop through loader + executor: "
          f"{'met' if t_full <= TARGET_RATIO * t_hand else 'NOT met'} ({t_full / t_hand:.2f}x)")


if __name__ == "__main__":
    main()
