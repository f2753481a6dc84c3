"""How robust the paper's three tasks are: the shipped diagrams over a wide random spread.

Draws N points (default 300, seed 2026) of ``hierhand.tasks.variations.SPREAD`` (``--spread
wide``: ``WIDE``, objects to 0.6 kg, mu_s 0.6-1.2, pushes of 1-5 N with a torque, gains
+-60 %, the suppresser +-30 %): object mass
0.15-0.45 kg, each side of the object x0.8-1.2, each link length x0.9-1.1, mu_s 0.6-1.4
(mu_d = 0.9 mu_s), contact stiffness and damping x0.5-2, the reflex's ki x0.5-2 and
safety ratio 0.45-0.75, the PD's kp and kd x0.7-1.4, the suppresser's S_a and S_b
x0.7-1.4, and a push of 1-4 N in any direction in the grasp task. Every point carries the
tasks onto its hand (``variations.carry``) and judges them (``hierhand.tasks.robustness``):
grasp, manipulation, re-grasp with the suppresser, and without it (where the forefinger
must never let go). A task's rate counts the points where its poses are reachable.

Prints the rates per task, beside them those of the paper-only configuration
(``hierhand.tasks.ablations.paper_only``), also over the points where the reflex can see slip (safety
ratio below mu_d: a sliding contact shows |f_t|/f_n = mu_d, so a safety ratio at or above
it never calls for more squeeze), the failures by reason and the first failed points, and
draws the failure map into OUT/robustness.png (default runs/robustness). ``--ablations``
runs each addition of ``hierhand.tasks.ablations`` switched off over the first
``--ablation-points`` points as well. Runs on all cores with a process pool.

    python benchmarks/robustness.py [--points 300] [--seed 2026] [--spread wide] [--workers 2] [-o DIR] [--ablations]
"""

from __future__ import annotations

import argparse
import collections
import json
import math
import os
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from hierhand.tasks.ablations import ABLATIONS, paper_only
from hierhand.tasks.robustness import TASKS, UNREACHABLE, judge
from hierhand.tasks.variations import SPREADS, Variation, sample

ROOT = Path(__file__).resolve().parents[1]
DIAGRAMS = ROOT / "diagrams"
NAMES = tuple(task.name for task in TASKS)


def _judge(args: tuple[Variation, dict]) -> tuple[dict[str, str], dict]:
    variation, extra = args
    margins: dict = {}
    return judge(variation, DIAGRAMS, extra, margins=margins), margins


def run(points: list[Variation], extra: dict, workers: int, margins: list | None = None) -> list[dict[str, str]]:
    """Each point's outcomes; ``margins``, when given, receives each point's threshold margins."""
    with ProcessPoolExecutor(workers) as pool:
        got = list(pool.map(_judge, [(p, extra) for p in points], chunksize=4))
    if margins is not None:
        margins.extend(m for _, m in got)
    return [outcomes for outcomes, _ in got]


def margin_spread(margins: list[dict]) -> None:
    """Per task with a threshold claim: its margin (safety ratio less the ratio it is judged
    by, plant rate) over the points where the object stayed held: least, 5 %, median."""
    for task in NAMES:
        values = np.array([m[task] for m in margins if m.get(task) is not None])
        if values.size:
            low, five, mid = np.min(values), np.quantile(values, 0.05), np.median(values)
            print(f"{task:22s} margin to the safety ratio over {values.size} points: least {low:+.3f}, "
                  f"5 % {five:+.3f}, median {mid:+.3f}")


def rate(points: list[Variation], rows: list[dict[str, str]], task: str, only_seeing_slip: bool = False) -> tuple[int, int]:
    """(succeeded, reachable) for a task."""
    picked = [r for p, r in zip(points, rows) if r[task] != UNREACHABLE and (p.sees_slip or not only_seeing_slip)]
    return sum(r[task] == "" for r in picked), len(picked)


def percent(ok: int, n: int) -> str:
    return f"{ok}/{n} ({100 * ok / max(n, 1):.1f} %)"


def report(points: list[Variation], rows: list[dict[str, str]], paper: list[dict[str, str]] | None = None) -> None:
    """Per task its rate, where the reflex sees slip, the failures by reason (and beside
    them the paper-only configuration's rate, ``paper``), then the first failed points."""
    for task in NAMES:
        ok, n = rate(points, rows, task)
        ok_slip, n_slip = rate(points, rows, task, only_seeing_slip=True)
        if paper is not None:
            print(f"{task:22s} paper only: {percent(*rate(points, paper, task))}")
        unreachable = sum(r[task] == UNREACHABLE for r in rows)
        reasons = collections.Counter(r[task] for r in rows if r[task] not in ("", UNREACHABLE))
        print(f"{task:22s} {percent(ok, n)} of the reachable points; {percent(ok_slip, n_slip)} where the reflex "
              f"sees slip; unreachable {unreachable}; " + (", ".join(f"{k}: {v}" for k, v in reasons.most_common())
                                                          or "no failures"))
    failed = [(i, p, r) for i, (p, r) in enumerate(zip(points, rows)) if any(v not in ("", UNREACHABLE) for v in r.values())]
    for i, p, r in failed[:10]:
        what = ", ".join(f"{t}: {v}" for t, v in r.items() if v not in ("", UNREACHABLE))
        shown = {k: round(v, 3) for k, v in p.as_dict().items() if isinstance(v, float)}
        push = math.hypot(*p.push), math.degrees(math.atan2(p.push[1], p.push[0]))
        print(f"  point {i}: {what}; {shown}, push {push[0]:.2f} N at {push[1]:.0f} deg")
    print(f"failure map: {len(failed)} of {len(points)} points fail some task")
    for quantity, (lo, hi) in (("mass", (0.15, 0.6)), ("mu_s", (0.6, 1.4)), ("safety_ratio", (0.45, 0.75))):
        edges = np.linspace(lo, hi, 4)
        cells = []
        for a, b in zip(edges[:-1], edges[1:]):
            inside = [r for p, r in zip(points, rows) if a <= getattr(p, quantity) < b or (b == hi and getattr(p, quantity) == b)]
            bad = sum(any(v not in ("", UNREACHABLE) for v in r.values()) for r in inside)
            cells.append(f"{a:.2f}-{b:.2f}: {bad}/{len(inside)}")
        print(f"  failing points by {quantity}: " + ", ".join(cells))


def plot(points: list[Variation], rows: list[dict[str, str]], path: Path) -> None:
    """One panel per task: the points over the two quantities its failures depend on most,
    failures marked by reason."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    axes_of = {
        "grasp": (lambda p: math.degrees(math.atan2(p.push[1], p.push[0])), "push direction (deg)",
                  lambda p: math.hypot(*p.push), "push (N)"),
        "manipulate": (lambda p: p.mass, "object mass (kg)", lambda p: p.stiffness, "contact stiffness (x)"),
        "regrasp": (lambda p: p.mass, "object mass (kg)", lambda p: p.mu_s, "mu_s"),
        "regrasp_unsuppressed": (lambda p: p.safety_ratio, "safety ratio", lambda p: p.mu_s, "mu_s"),
    }
    fig, axes = plt.subplots(2, 2, figsize=(12, 9))
    for ax, task in zip(axes.ravel(), NAMES):
        fx, xlabel, fy, ylabel = axes_of[task]
        reasons = sorted({r[task] for r in rows}, key=lambda w: (w != "", w))
        for n, why in enumerate(reasons):
            picked = [p for p, r in zip(points, rows) if r[task] == why]
            ax.scatter([fx(p) for p in picked], [fy(p) for p in picked], s=12 if why == "" else 36,
                       marker="o" if why == "" else "x", color="C2" if why == "" else f"C{(n + 2) % 10}",
                       label=f"{why or 'succeeded'} ({len(picked)})")
        if task == "regrasp_unsuppressed":
            mu = np.linspace(0.6, 1.4, 2)
            ax.plot(0.9 * mu, mu, "k--", lw=0.8, label="safety ratio = mu_d")
        ok, n = rate(points, rows, task)
        ax.set_title(f"{task}: {percent(ok, n)}")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize="small")
    fig.suptitle(f"the shipped task diagrams over {len(points)} random points of the spread "
                 "(benchmarks/robustness.py)")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=300)
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--spread", choices=sorted(SPREADS), default="shipped")
    parser.add_argument("--no-paper-only", action="store_true", help="skip the paper-only configuration's rates")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("-o", "--out", type=Path, default=ROOT / "runs" / "robustness")
    parser.add_argument("--no-plot", action="store_true")
    parser.add_argument("--ablations", action="store_true", help="also run each addition switched off")
    parser.add_argument("--ablation-points", type=int, default=100)
    args = parser.parse_args()
    points = sample(args.points, args.seed, SPREADS[args.spread])
    start = time.perf_counter()
    margins: list[dict] = []
    rows = run(points, {}, args.workers, margins)
    paper = None if args.no_paper_only else run(points, paper_only(), args.workers)
    print(f"{args.points} points of the {args.spread} spread, seed {args.seed}, {time.perf_counter() - start:.1f} s "
          f"on {args.workers} worker(s)")
    report(points, rows, paper)
    margin_spread(margins)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "rows.json").write_text(json.dumps([{"point": p.as_dict(), **r} for p, r in zip(points, rows)]))
    if not args.no_plot:
        plot(points, rows, args.out / "robustness.png")
        print(f"wrote {args.out / 'robustness.png'}")
    if args.ablations:
        few = points[:args.ablation_points]
        print(f"\neach addition switched off, over the first {len(few)} points (succeeded / reachable):")
        print(f"{'':40s}" + "".join(f"{t:>22s}" for t in NAMES))
        for name, extra in [("as shipped", {}), *((a.name, a.extra()) for a in ABLATIONS)]:
            got = rows[:len(few)] if name == "as shipped" else run(few, extra, args.workers)
            print(f"{name:40s}" + "".join(f"{percent(*rate(few, got, t)):>22s}" for t in NAMES))


if __name__ == "__main__":
    main()
