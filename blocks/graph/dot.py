"""The wiring as Graphviz DOT text: record-shaped blocks, port-to-port edges, rate colours and a
legend; expanded, each subsystem a cluster around its blocks."""

from __future__ import annotations

from blocks.builder.diagram import Diagram
from blocks.engine.schedule import Schedule
from .layout import layered
from .ports import input_ports, output_ports
from .rates import tint
from .view import Picture, picture


def dot_quoted(text: str) -> str:
    """``text`` as a DOT double-quoted string: backslashes and quotes escaped, line breaks
    as ``\\n``, so that a diagram's free-form name cannot break the DOT file."""
    escaped = text.replace("\\", "\\\\").replace('"', '\\"').replace("\r", "").replace("\n", "\\n")
    return f'"{escaped}"'


def record_text(text: str) -> str:
    """``text`` as a field of a record label: the record's own characters escaped."""
    out = []
    for ch in text.replace("\r", ""):
        if ch in '{}|<>"\\':
            out.append("\\" + ch)
        elif ch == "\n":
            out.append("\\n")
        else:
            out.append(ch)
    return "".join(out)


def port_id(direction: str, port: str) -> str:
    """The record field name of a port: ``in_q``, ``out_tau`` (odd characters as ``_``)."""
    return f"{direction}_" + "".join(ch if ch.isalnum() or ch == "_" else "_" for ch in port)


def record_label(pic: Picture, name: str) -> str:
    """``{{<in_a> a|...}|name\\ntype\\nrate|{<out_y> y|...}}`` (a side without ports left
    out): with ``rankdir=LR`` the outer braces lay the three parts side by side, the inner
    ones stack the ports."""
    def ports(direction, names):
        fields = "|".join(f"<{port_id(direction, p)}> {record_text(p)}" for p in names)
        return [f"{{{fields}}}"] if fields else []
    node = pic.nodes[name]
    middle = "\\n".join(record_text(t) for t in (name, node.type_line, node.rate_line, *node.notes))
    parts = ports("in", input_ports(pic, name)) + [middle] + ports("out", output_ports(pic, name))
    return "{" + "|".join(parts) + "}"


def to_dot(diagram: Diagram, schedule: Schedule, expand: bool = False) -> str:
    """Graphviz DOT text: blocks as records with their ports, wires port to port,
    coloured by rate, with a legend node of the rates; a subsystem one record of its
    ports, or with ``expand`` a cluster of its blocks."""
    pic = picture(diagram, schedule, expand)
    layout = layered(pic)
    lines = [f"digraph {dot_quoted(pic.name)} {{", "  rankdir=LR;", "  splines=true;", "  nodesep=0.4;",
             '  node [shape=record, fontname="Helvetica", fontsize=10, style=filled];',
             '  edge [fontname="Helvetica", fontsize=9, arrowsize=0.7];']
    lines += node_lines(pic, "", "  ")
    feedback = set(layout.feedback)
    for c in pic.wires:
        attrs = [f'color="{pic.nodes[c.src_block].colour}"']
        if c.delay:
            attrs += ["style=dashed", 'label="z\u207b\u00b9"']
        if c in feedback:
            attrs.append("constraint=false")
        attrs += [f"{end}={dot_quoted(f'[{select}]')}" for end, select in (("taillabel", c.src_select),
                                                                            ("headlabel", c.dst_select)) if select]
        lines.append(f"  {dot_quoted(c.src_block)}:{port_id('out', c.src_port)}:e -> "
                     f"{dot_quoted(c.dst_block)}:{port_id('in', c.dst_port)}:w [{', '.join(attrs)}];")
    rows = "".join(f'<tr><td bgcolor="{tint(colour, 0.35)}"><font color="{colour}">\u25a0</font> '
                   f"{html_text(label)}</td></tr>" for label, colour in pic.legend)
    legend_id = "rates (legend)"
    while legend_id in pic.nodes:
        legend_id += " "
    lines.append(f"  {dot_quoted(legend_id)} [shape=plaintext, style=solid, label=<<table border=\"0\" "
                 f'cellborder="1" cellspacing="0"><tr><td><b>rates</b></td></tr>{rows}</table>>];')
    lines.append("}")
    return "\n".join(lines) + "\n"


def node_lines(pic: Picture, group: str, indent: str) -> list[str]:
    """The records of the boxes in ``group`` (``""``: outside every frame), and each frame
    directly inside it as a cluster holding its own."""
    lines = []
    for name, node in pic.nodes.items():
        if node.group == group:
            label = record_label(pic, name)
            fill, style = ("gray93", ', style="filled,dashed"') if node.disabled else (tint(node.colour), "")
            lines.append(f'{indent}{dot_quoted(name)} [label="{label}", color="{node.colour}", '
                         f'fillcolor="{fill}", penwidth=1.6{style}];')
    for frame in pic.frames:
        parent = frame.path.rpartition(".")[0] if frame.depth else ""
        if parent == group:
            lines.append(f"{indent}subgraph {dot_quoted('cluster_' + frame.path)} {{")
            lines.append(f'{indent}  label={dot_quoted(frame.label)}; style="rounded,dashed"; color="gray45"; '
                         'fontname="Helvetica"; fontsize=9;')
            lines += node_lines(pic, frame.path, indent + "  ")
            lines.append(f"{indent}}}")
    return lines


def html_text(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
