"""Width inference: polymorphic ports (declared width None) take the width of what they connect to.

A block has one inferred width for all of its polymorphic ports. The rule is a sweep
over the connections in file order, repeated until nothing changes: a connection with
a known width on one side and an unknown one on the other gives that width to the
unknown side's block. With conflicting neighbours the first assignment wins, so the
order matters for which width mismatch gets reported, and it is kept exactly.

Repeating the sweep costs a pass per block on a chain written bottom-up, which is
quadratic. Instead each scan is an event at (pass, connection index), processed in that
order from a heap: a block that gets its width at (p, i) makes its connection j worth
scanning at (p, j) when j comes later in the sweep, else at (p + 1, j). Every scan that
could assign something is thus made at the same moment as in the repeated sweep, with
the same widths known, in O(E log E) for E connections.

A connection that names elements carries as many values as its source selection picks
(``c.y[0:3]``: 3, known once c.y's width is; ``c.y[1]``: 1 at once), which a whole
destination takes as its width; it never gives its source a width, and a destination
that names elements (``g.u[0]``) takes none from it: its width comes from elsewhere.
"""

from __future__ import annotations

import heapq
from typing import TYPE_CHECKING, Callable, Sequence

from blocks.builder.elements import count

if TYPE_CHECKING:
    from blocks.builder.diagram import Connection

PortWidth = Callable[[str, str, str], "int | None"]
"""Declared width of ``(block, 'inputs' | 'outputs', port)``; None for a polymorphic port."""


def propagate_widths(declared: PortWidth, connections: Sequence[Connection]) -> dict[str, int]:
    """The width each block with polymorphic ports takes from its connections (if any)."""
    inferred: dict[str, int] = {}

    def width(block: str, kind: str, port: str) -> int | None:
        w = declared(block, kind, port)
        return w if w is not None else inferred.get(block)

    touching: dict[str, list[int]] = {}
    for i, c in enumerate(connections):
        touching.setdefault(c.src_block, []).append(i)
        touching.setdefault(c.dst_block, []).append(i)
    scans = [(0, i) for i in range(len(connections))]  # sorted, so already a heap
    while scans:
        sweep, i = heapq.heappop(scans)
        c = connections[i]
        ws, wd = width(c.src_block, "outputs", c.src_port), width(c.dst_block, "inputs", c.dst_port)
        if c.src_select is not None:
            ws = count(c.src_select, ws)
        if c.dst_select is not None:
            continue
        if ws is not None and wd is None:
            block, w = c.dst_block, ws
        elif wd is not None and ws is None and c.src_select is None:
            block, w = c.src_block, wd
        else:
            continue
        inferred[block] = w
        for j in touching[block]:
            heapq.heappush(scans, (sweep if j > i else sweep + 1, j))
    return inferred
