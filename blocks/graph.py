"""The wiring of a diagram as DOT text or a rendered SVG/PNG (networkx + matplotlib)."""

from __future__ import annotations

from pathlib import Path

import networkx as nx

from .diagram import Diagram
from .schedule import Schedule


def block_label(diagram: Diagram, schedule: Schedule, name: str) -> str:
    return f"{name}\n{diagram.blocks[name].type_name}\n{schedule.rate_text(name)}"


def dot_quoted(text: str) -> str:
    """``text`` as a DOT double-quoted string: backslashes and quotes escaped, line breaks
    as ``\\n``, so that a diagram's free-form name cannot break the DOT file."""
    escaped = text.replace("\\", "\\\\").replace('"', '\\"').replace("\r", "").replace("\n", "\\n")
    return f'"{escaped}"'


def to_dot(diagram: Diagram, schedule: Schedule) -> str:
    """Graphviz DOT text: blocks as boxes with type and rate, wires labelled with ports."""
    lines = [f"digraph {dot_quoted(diagram.name)} {{", "  rankdir=LR;", '  node [shape=box, fontname="Helvetica"];']
    for name in diagram.blocks:
        label = block_label(diagram, schedule, name).replace("\n", "\\n")
        lines.append(f'  "{name}" [label="{label}"];')
    for c in diagram.connections:
        style = ", style=dashed" if c.delay else ""
        label = f"{c.src_port} → {c.dst_port}" + (" (z⁻¹)" if c.delay else "")
        lines.append(f'  "{c.src_block}" -> "{c.dst_block}" [label="{label}"{style}];')
    lines.append("}")
    return "\n".join(lines) + "\n"


def layered_positions(diagram: Diagram) -> dict[str, tuple[float, float]]:
    """Left-to-right layers by longest path, ignoring the edges that close feedback loops."""
    graph = nx.DiGraph()
    graph.add_nodes_from(diagram.blocks)
    for c in diagram.connections:
        graph.add_edge(c.src_block, c.dst_block)
    order = {n: i for i, n in enumerate(diagram.blocks)}
    dag = nx.DiGraph()
    dag.add_nodes_from(graph)
    visited: set[str] = set()
    for root in sorted(graph, key=lambda n: (graph.in_degree(n) > 0, order[n])):
        if root in visited:
            continue
        for u, v, kind in nx.dfs_labeled_edges(graph, root):
            if kind == "forward" and u != v:
                dag.add_edge(u, v)
        visited |= nx.descendants(graph, root) | {root}
    layer = {}
    for n in nx.topological_sort(dag):
        layer[n] = max((layer[p] + 1 for p in dag.predecessors(n)), default=0)
    columns: dict[int, list[str]] = {}
    for n in sorted(layer, key=order.get):
        columns.setdefault(layer[n], []).append(n)
    return {n: (float(x), -float(i) + (len(col) - 1) / 2) for x, col in columns.items()
            for i, n in enumerate(col)}


def render(diagram: Diagram, schedule: Schedule, path: str | Path) -> Path:
    """Draw the diagram to an SVG or PNG file (format from the suffix)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(path)
    pos = layered_positions(diagram)
    width = max(x for x, _ in pos.values()) + 1
    height = max(abs(y) for _, y in pos.values()) * 2 + 1
    fig, ax = plt.subplots(figsize=(2.6 * width + 1, 1.6 * height + 1))
    boxes = {name: ax.text(x, y, block_label(diagram, schedule, name), ha="center", va="center",
                           fontsize=8, bbox=dict(boxstyle="round,pad=0.4", fc="#eef3fb", ec="#3a5a8c"))
             for name, (x, y) in pos.items()}
    for c in diagram.connections:
        (x0, y0), (x1, y1) = pos[c.src_block], pos[c.dst_block]
        forward = x1 > x0
        ax.annotate("", xy=(0.0, 0.5) if forward else (0.5, 1.0), xycoords=boxes[c.dst_block],
                    xytext=(1.0, 0.5) if forward else (0.5, 1.0), textcoords=boxes[c.src_block],
                    arrowprops=dict(arrowstyle="-|>", color="0.3", shrinkA=4, shrinkB=4,
                                    linestyle="--" if c.delay else "-",
                                    connectionstyle="arc3,rad=0" if forward else "arc3,rad=0.3"))
        ax.text((x0 + x1) / 2, (y0 + y1) / 2 + (0.06 if forward else 0.2 + 0.15 * abs(x1 - x0)), f"{c.src_port}→{c.dst_port}",
                fontsize=7, ha="center", color="0.25")
    ax.set_xlim(-0.6, width - 0.4)
    ys = [y for _, y in pos.values()]
    ax.set_ylim(min(ys) - 0.8, max(ys) + 0.8)
    ax.set_axis_off()
    ax.set_title(diagram.name)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
    return path
