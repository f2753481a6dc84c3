"""What sets the re-grasp's separation time: the withdrawal schedule and S_b, measured.

The forefinger lets go when its manipulation torque has grown enough for the suppresser
and the PD to take it over from the reflex, which happens a fixed part of the way into its
withdrawal. So the separation time follows the withdrawal schedule one for one and moves
a little with ``S_b``; it is a consequence of the task script, not a prediction of the
model. These runs show the relation (``report.md``'s table).
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Callable

import blocks

from .summaries import TaskBlocks, regrasp_events

SHIFTS = (-0.05, 0.0, 0.05, 0.1)
"""Seconds by which the forefinger's withdrawal is moved."""
S_B_SCALES = (0.8, 1.0, 1.2)
"""Factors on the suppresser's S_b."""


RUNS = len(SHIFTS) * len(S_B_SCALES)
"""How many runs ``separation_relation`` makes."""


def separation_relation(diagram: Path, done: Callable[[], None] = lambda: None) -> list[dict]:
    """One row per run of the re-grasp ``diagram``: the withdrawal start, S_b, and when the
    forefinger separated (None if it did not). ``done`` is called after each run."""
    loaded = blocks.load_diagram(diagram)
    b, base = TaskBlocks.of_diagram(loaded), loaded.parameters()
    fore = base[b.block("manip")]["trajectories"]["fore"]
    s_b = base[b.block("suppress")]["S_b"]
    rows = []
    for shift in SHIFTS:
        for scale in S_B_SCALES:
            moved = copy.deepcopy(fore)
            moved["waypoints"] = [[w[0] + shift, *w[1:]] for w in fore["waypoints"]]
            overrides = {b.resolve("manip.trajectories.fore"): moved, b.resolve("suppress.S_b"): s_b * scale}
            results = blocks.simulate(blocks.load_diagram(diagram, overrides=overrides))
            rows.append({"withdrawal_start_s": moved["waypoints"][0][0], "S_b": s_b * scale,
                         "fore_separation_time_s": regrasp_events(results, b)["fore_separation_time_s"]})
            done()
    return rows
