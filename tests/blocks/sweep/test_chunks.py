"""Points per Dask task: one before any run has finished, then as many as fit the target
time, never more than a fair share of what is left, never zero and never past the end."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from blocks.sweep.chunks import TASKS_PER_WORKER, ChunkSizer


def test_first_tasks_hold_one_point():
    assert ChunkSizer(threads=2).size(1000) == 1


def test_short_runs_fill_the_target_time():
    sizer = ChunkSizer(threads=2, target_s=0.25)
    for _ in range(8):
        sizer.observe(0.03)
    assert sizer.size(1000) == 8  # 8 x 30 ms fits 0.25 s, 9 does not


def test_runs_longer_than_the_target_go_one_per_task():
    sizer = ChunkSizer(threads=2, target_s=0.25)
    sizer.observe(2.0)
    assert sizer.size(1000) == 1


def test_the_tail_is_shared_so_no_worker_waits_on_a_long_chunk():
    sizer = ChunkSizer(threads=2, target_s=0.25)
    sizer.observe(0.001)
    assert sizer.in_flight == 2 * TASKS_PER_WORKER
    assert sizer.size(12) == 3
    assert sizer.size(5) == 2
    assert sizer.size(3) == 1
    assert sizer.size(0) == 0


def test_the_typical_time_follows_recent_runs():
    sizer = ChunkSizer(threads=1, target_s=0.25)
    for _ in range(200):
        sizer.observe(1.0)  # the first runs load the kernels from disk, say
    for _ in range(64):
        sizer.observe(0.05)
    assert sizer.size(10_000) == 5


@given(threads=st.integers(0, 64), remaining=st.integers(0, 10_000),
       walls=st.lists(st.floats(0.0, 100.0), max_size=80))
def test_a_size_is_between_one_and_what_is_left(threads, remaining, walls):
    sizer = ChunkSizer(threads=threads)
    for w in walls:
        sizer.observe(w)
    size = sizer.size(remaining)
    assert (size == 0) if remaining == 0 else (1 <= size <= remaining)
