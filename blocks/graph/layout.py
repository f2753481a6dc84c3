"""Boxes in layers along the data flow (longest path over the feed-through wires), ordered against crossings."""

from __future__ import annotations

from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from blocks.builder.diagram import Connection
from .ports import input_ports, is_feedthrough, output_ports
from .view import Picture


@dataclass
class Layered:
    """Blocks in layers: ``layer`` per block, the wires that run back (``feedback``), and
    ``columns``: each layer's items top to bottom, blocks and, for a wire that passes a
    layer, a waypoint ``(connection index, layer)``."""

    layer: dict[str, int]
    feedback: list[Connection]
    columns: list[list] = field(default_factory=list)


def layered(picture: Picture, sweeps: int = 6) -> Layered:
    """Longest-path layers over the wires, the loops broken at wires without feedthrough
    (delayed ones last), then barycenter passes to order each layer against crossings."""
    order = {n: i for i, n in enumerate(picture.nodes)}
    dag = nx.DiGraph()
    dag.add_nodes_from(picture.nodes)
    conns = picture.wires
    ranked = sorted(range(len(conns)), key=lambda i: (0 if is_feedthrough(picture, conns[i])
                                                      else 2 if conns[i].delay else 1, i))
    for i in ranked:
        c = conns[i]
        if c.src_block == c.dst_block or dag.has_edge(c.src_block, c.dst_block):
            continue
        if not nx.has_path(dag, c.dst_block, c.src_block):
            dag.add_edge(c.src_block, c.dst_block)
    feedback = [c for c in conns if c.src_block == c.dst_block or not dag.has_edge(c.src_block, c.dst_block)]
    layer: dict[str, int] = {}
    for n in nx.lexicographical_topological_sort(dag, key=order.get):
        layer[n] = max((layer[p] + 1 for p in dag.predecessors(n)), default=0)
    # a block fed by nothing stands just before the first block it feeds
    for n in sorted(dag, key=lambda n: -order[n]):
        if dag.in_degree(n) == 0 and dag.out_degree(n):
            layer[n] = max(layer[n], min(layer[s] for s in dag.successors(n)) - 1)
    n_layers = max(layer.values(), default=-1) + 1
    columns: list[list] = [[] for _ in range(n_layers)]
    for n in sorted(picture.nodes, key=order.get):
        columns[layer[n]].append(n)
    fb = set(map(id, feedback))
    for i, c in enumerate(conns):
        if id(c) not in fb:
            for k in range(layer[c.src_block] + 1, layer[c.dst_block]):
                columns[k].append((i, k))
    result = Layered(layer, feedback, columns)
    order_layers(picture, result, sweeps)
    if picture.frames:
        group_columns(picture, result)
    return result


def group_of(picture: Picture, item) -> str:
    """The frame an item belongs to: a box's innermost subsystem, a waypoint's source's."""
    name = item if isinstance(item, str) else picture.wires[item[0]].src_block
    return picture.nodes[name].group


def group_columns(picture: Picture, lay: Layered) -> None:
    """Keep each frame's items together in every layer, frames in one order throughout
    (outside any frame first, then the subsystems as written, a nested one after its
    parent's own blocks), so that each frame is one band across the drawing."""
    rank = {"": 0, **{f.path: i + 1 for i, f in enumerate(picture.frames)}}
    for k, col in enumerate(lay.columns):
        lay.columns[k] = sorted(col, key=lambda item: rank[group_of(picture, item)])


def segments(picture: Picture, lay: Layered) -> list[tuple[object, int, object, int, int]]:
    """The forward wires between neighbouring layers: (left item, output row, right item,
    input row, layer of the left item), a wire through waypoints cut into its pieces."""
    fb = set(map(id, lay.feedback))
    out = []
    for i, c in enumerate(picture.wires):
        if id(c) in fb:
            continue
        a, b = lay.layer[c.src_block], lay.layer[c.dst_block]
        items = [c.src_block] + [(i, k) for k in range(a + 1, b)] + [c.dst_block]
        rows = ([output_ports(picture, c.src_block).index(c.src_port)] + [0] * (b - a - 1)
                + [input_ports(picture, c.dst_block).index(c.dst_port)])
        for k in range(len(items) - 1):
            out.append((items[k], rows[k], items[k + 1], rows[k + 1], a + k))
    return out


def crossings(picture: Picture, lay: Layered, segs=None) -> int:
    segs = segments(picture, lay) if segs is None else segs
    pos = {item: j for col in lay.columns for j, item in enumerate(col)}
    total = 0
    by_layer: dict[int, list] = {}
    for s in segs:
        by_layer.setdefault(s[4], []).append(((pos[s[0]], s[1]), (pos[s[2]], s[3])))
    for wires in by_layer.values():
        for i in range(len(wires)):
            for j in range(i + 1, len(wires)):
                (a0, b0), (a1, b1) = wires[i], wires[j]
                if (a0 < a1 and b0 > b1) or (a0 > a1 and b0 < b1):
                    total += 1
    return total


def order_layers(picture: Picture, lay: Layered, sweeps: int) -> None:
    """Barycenter sweeps, right then left, keeping the order with the fewest crossings."""
    segs = segments(picture, lay)

    def rank(item, row, n_rows):
        return pos[item] + (row + 1) / (n_rows + 2)

    def n_out(item):
        return len(output_ports(picture, item)) if isinstance(item, str) else 1

    def n_in(item):
        return len(input_ports(picture, item)) if isinstance(item, str) else 1

    best = [list(col) for col in lay.columns]
    best_count = crossings(picture, lay, segs)
    for sweep in range(sweeps):
        forward = sweep % 2 == 0
        layers = range(1, len(lay.columns)) if forward else range(len(lay.columns) - 2, -1, -1)
        for k in layers:
            pos = {item: j for col in lay.columns for j, item in enumerate(col)}
            sums: dict[object, list[float]] = {}
            for left, lrow, right, rrow, at in segs:
                if forward and at == k - 1:
                    sums.setdefault(right, []).append(rank(left, lrow, n_out(left)))
                elif not forward and at == k:
                    sums.setdefault(left, []).append(rank(right, rrow, n_in(right)))
            col = lay.columns[k]
            lay.columns[k] = sorted(col, key=lambda it: (np.mean(sums[it]) if it in sums else pos[it], pos[it]))
        count = crossings(picture, lay, segs)
        if count < best_count:
            best, best_count = [list(col) for col in lay.columns], count
    lay.columns = best
