"""Which of the project's additions each task needs: a search over the ablations on a spread.

Starting from the shipped set of additions to the paper's mechanism
(``hierhand.tasks.ablations.MECHANISMS``), each task on its own drops, one at a time in the
table's order, every addition without which its success rate over the points falls by no
more than ``--tolerance`` points (backward elimination); what is left is the smallest set
found for that task. The points are drawn from a spread (``--spread shipped`` or ``wide``,
``hierhand.tasks.variations``), not taken at the shipped point.

Prints, and writes as markdown to OUT/additions.md, the table addition x task: each cell is
the task's success rate over the points with that addition switched off alone (from the
shipped set), marked "needed" where the search kept it; then the rates as shipped, of the
paper-only configuration and of each task's smallest set. Runs with a process pool.

    python benchmarks/additions.py [--points 12] [--seed 2026] [--spread wide] [--workers 2] [-o DIR]
"""

from __future__ import annotations

import argparse
import json
import os
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from hierhand.tasks.ablations import MECHANISMS, smallest_set, switched_off
from hierhand.tasks.robustness import TASKS, UNREACHABLE, judge
from hierhand.tasks.variations import SPREADS, Variation, sample

ROOT = Path(__file__).resolve().parents[1]
DIAGRAMS = ROOT / "diagrams"
NAMES = tuple(task.name for task in TASKS)


def _judge(args: tuple[Variation, dict, str]) -> str:
    variation, extra, task = args
    return judge(variation, DIAGRAMS, extra, tasks=tuple(t for t in TASKS if t.name == task))[task]


class Rates:
    """Success rates of one task over the points for sets of additions switched off, each
    set run once (cached by the set)."""

    def __init__(self, points: list[Variation], pool: ProcessPoolExecutor):
        self.points, self.pool, self.seen = points, pool, {}

    def outcomes(self, task: str, off: frozenset[str]) -> list[str]:
        key = (task, off)
        if key not in self.seen:
            extra = switched_off([a for a in MECHANISMS if a.name in off])
            self.seen[key] = list(self.pool.map(_judge, [(p, extra, task) for p in self.points]))
        return self.seen[key]

    def rate(self, task: str, off: frozenset[str]) -> tuple[int, int]:
        """(succeeded, reachable)."""
        got = [r for r in self.outcomes(task, off) if r != UNREACHABLE]
        return sum(r == "" for r in got), len(got)


def cell(ok_n: tuple[int, int]) -> str:
    ok, n = ok_n
    return f"{ok}/{n} ({100 * ok / max(n, 1):.0f} %)"


def table(rates: Rates, needed: dict[str, frozenset[str]]) -> str:
    everything = frozenset(a.name for a in MECHANISMS)
    lines = ["| configuration | " + " | ".join(NAMES) + " |", "|---|" + "---|" * len(NAMES),
             "| as shipped (every addition) | " + " | ".join(cell(rates.rate(t, frozenset())) for t in NAMES) + " |",
             "| paper only (no addition) | " + " | ".join(cell(rates.rate(t, everything)) for t in NAMES) + " |"]
    for addition in MECHANISMS:
        cells = [cell(rates.rate(t, frozenset({addition.name}))) + (" **needed**" if addition.name in needed[t] else "")
                 for t in NAMES]
        lines.append(f"| without {addition.name} | " + " | ".join(cells) + " |")
    lines.append("| each task's smallest set | " + " | ".join(
        cell(rates.rate(t, everything - needed[t])) for t in NAMES) + " |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=12)
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--spread", choices=sorted(SPREADS), default="wide")
    parser.add_argument("--tolerance", type=int, default=0, help="successes a dropped addition may cost")
    parser.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1))
    parser.add_argument("-o", "--out", type=Path, default=ROOT / "runs" / "additions")
    args = parser.parse_args()
    points = sample(args.points, args.seed, SPREADS[args.spread])
    with ProcessPoolExecutor(args.workers) as pool:
        rates = Rates(points, pool)
        needed = {t: smallest_set(lambda off, t=t: rates.rate(t, off)[0], args.tolerance) for t in NAMES}
        text = (f"{args.points} points of the {args.spread} spread, seed {args.seed}; tolerance {args.tolerance}\n\n"
                + table(rates, needed) + "\n\n" + "\n".join(
                    f"- {t}: {', '.join(a.name for a in MECHANISMS if a.name in needed[t]) or 'none'}" for t in NAMES))
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "additions.md").write_text(text + "\n", encoding="utf-8")
    (args.out / "needed.json").write_text(json.dumps({t: sorted(v) for t, v in needed.items()}, indent=1))


if __name__ == "__main__":
    main()
