"""The points a sweep has still to hand out, taken from the front in chunks.

``PointQueue`` serves one taker (the Dask dispatch). ``SharedQueue`` serves this process
and a forked local runner process at once (``local``): the position of the next point is
a counter in shared memory, moved under its lock, so every point is taken exactly once
whoever takes it.
"""

from __future__ import annotations

from typing import Any

from .points import Point

Item = tuple[str, Point]
"""A point with its hash."""


class PointQueue:
    """Points handed out once each, in order, to one taker."""

    def __init__(self, items: list[Item]):
        self.items = items
        self.next = 0

    def take(self, n: int) -> list[Item]:
        """Up to ``n`` points from the front (fewer at the end)."""
        first = self.next
        self.next = min(len(self.items), first + max(0, n))
        return self.items[first:self.next]

    def __len__(self) -> int:
        return len(self.items) - self.next


class SharedQueue:
    """Points handed out once each to this process and to processes forked from it after
    it was made (``context``: a multiprocessing context that can fork)."""

    def __init__(self, items: list[Item], context: Any):
        self.items = items
        self.position = context.Value("q", 0)

    def take_indices(self, n: int) -> range:
        """The indices of up to ``n`` points from the front."""
        with self.position.get_lock():
            first = self.position.value
            self.position.value = min(len(self.items), first + max(0, n))
            return range(first, self.position.value)

    def take(self, n: int) -> list[Item]:
        return [self.items[i] for i in self.take_indices(n)]

    def taken(self) -> int:
        """How many points have been handed out so far."""
        with self.position.get_lock():
            return self.position.value

    def __len__(self) -> int:
        return len(self.items) - self.taken()
