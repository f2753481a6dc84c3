"""How many points one Dask task runs: enough that a task's own cost is small against its
work, few enough that every worker stays busy to the last point.

A Dask task costs a few milliseconds of messages and bookkeeping, on the workers and in
the scheduler, and on a machine whose cores all run workers that time comes out of the
runs: one 30 ms re-grasp point per task made every run about 10 % slower. So a task runs
as many points as fit in ``TASK_TARGET_S``, judged from the wall times of the runs
finished so far, but never more than an equal share of what is left (guided
self-scheduling), so the last tasks are small and no worker idles while another finishes
a long chunk. The first tasks, before any run has finished, hold one point each.
"""

from __future__ import annotations

import math
import statistics
from collections import deque
from dataclasses import dataclass, field

TASK_TARGET_S = 0.25
"""Seconds of runs one task aims at; its overhead of a few milliseconds is then ~1 %."""

TASKS_PER_WORKER = 2
"""Tasks kept in flight per worker thread: one running, one waiting, so none idles between tasks."""

RECENT_RUNS = 64
"""How many of the latest run times judge the typical run time."""


@dataclass
class ChunkSizer:
    """Chooses the number of points of the next task from the run times seen so far."""

    threads: int
    target_s: float = TASK_TARGET_S
    recent: deque = field(default_factory=lambda: deque(maxlen=RECENT_RUNS))

    @property
    def in_flight(self) -> int:
        """How many tasks to keep submitted at once."""
        return TASKS_PER_WORKER * max(1, self.threads)

    def observe(self, wall_s: float) -> None:
        """Take note of one finished run's wall time."""
        self.recent.append(wall_s)

    def size(self, remaining: int) -> int:
        """Points for the next task, out of ``remaining`` still to submit."""
        if remaining <= 0:
            return 0
        if not self.recent:
            return 1
        typical = statistics.median(self.recent)
        by_time = int(min(self.target_s / typical, remaining)) if typical > 0 else remaining
        fair_share = math.ceil(remaining / self.in_flight)
        return max(1, min(by_time, fair_share, remaining))
