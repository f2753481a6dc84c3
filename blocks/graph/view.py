"""What a wiring picture shows: boxes with their ports and rates, wires, and frames.

A flat diagram is drawn block by block. A diagram with subsystems is drawn as its top
file wrote it: each subsystem one box, with its own ports (the subsystem's inputs and
outputs) and the rates of the blocks inside it, and the wires the top file writes
(``err.y -> ctrl.e``). Expanded, every block is a box and each subsystem a frame around
its blocks (nested frames for nested subsystems), with the flat connections.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from blocks.builder.diagram import Composite, Connection, Diagram
from blocks.engine.schedule import Schedule
from .rates import MIXED_COLOR, Rate, rate_colors, rate_line
from blocks.builder.api_args import diagram_argument

NOTE_CHARS = 34
"""The longest parameter note a box shows in full; a longer one shows its name only."""
MOST_NOTES = 4
DISABLED = "disabled"
"""The note of a block whose ``enabled`` parameter is false (the convention of blocks that
can be switched off, such as the hand's suppresser): it passes its input through or does
nothing, which changes what the diagram does while its wiring stays the same."""

SEVERAL_RATES = "subsystem of several rates"
"""The legend's entry for the colour of a subsystem box whose blocks run at different rates
(Simulink's yellow 'hybrid')."""


@dataclass
class Node:
    """A box: a block, or (collapsed) a subsystem."""

    name: str
    type_line: str
    rate_line: str
    colour: str
    inputs: list[str]
    outputs: list[str]
    feeds: dict[str, frozenset[str]]
    """Output -> the inputs it reads at the same hit (through the blocks inside, for a subsystem)."""
    group: str = ""
    """The innermost subsystem whose frame holds it (expanded), ``""`` for none."""
    notes: list[str] = field(default_factory=list)
    """Lines under its ports: the parameters the diagram gives it (a subsystem: the
    overrides its entry gives), ``disabled`` for a switched-off block, and for a
    subsystem the switched-off blocks inside (``suppress disabled``)."""
    disabled: bool = False


@dataclass(frozen=True)
class Frame:
    """A subsystem drawn around its blocks (expanded): ``members`` are the boxes inside,
    nested subsystems' too."""

    path: str
    label: str
    members: tuple[str, ...]
    depth: int


@dataclass
class Picture:
    name: str
    nodes: dict[str, Node]
    wires: list[Connection]
    legend: list[tuple[str, str]]
    frames: list[Frame] = field(default_factory=list)


def picture(diagram: Diagram, schedule: Schedule, expand: bool = False) -> Picture:
    """The picture of ``diagram``: its top level with subsystems as boxes, or ``expand``ed
    to every block, each subsystem a frame."""
    diagram_argument(diagram)
    rates = rate_colors(diagram, schedule)
    legend = list(rates.legend)
    nodes: dict[str, Node] = {}
    collapsed = {} if expand or diagram.root is None else \
        {path: diagram.subsystems[path] for path in diagram.root.subsystems}
    for name, spec in diagram.blocks.items():
        top = next((p for p in collapsed if name.startswith(p + ".")), None)
        if top is not None:
            if top not in nodes:
                nodes[top] = subsystem_node(diagram, schedule, rates, collapsed[top], legend)
            continue
        blk = spec.block
        off = is_disabled(spec.params)
        shown = {k: v for k, v in spec.params.items() if not (k == "enabled" and off)}
        nodes[name] = Node(name, spec.type_name, rate_line(schedule, rates, name), rates.colors[name],
                           list(blk.inputs), list(blk.outputs), {p: blk.reads(p) for p in blk.outputs},
                           group=innermost(diagram, name) if expand else "",
                           notes=([DISABLED] if off else []) + parameter_notes(shown), disabled=off)
    wires = list(diagram.root.wires) if collapsed else list(diagram.connections)
    for node in nodes.values():
        node.inputs += [c.dst_port for c in wires if c.dst_block == node.name and c.dst_port not in node.inputs]
        node.outputs += [c.src_port for c in wires if c.src_block == node.name and c.src_port not in node.outputs]
    frames = []
    if expand:
        for path, sub in diagram.subsystems.items():
            members = tuple(n for n in diagram.blocks if n.startswith(path + "."))
            frames.append(Frame(path, f"{path}: {sub.origin}", members, path.count(".")))
    return Picture(diagram.name, nodes, wires, legend, frames)


def is_disabled(params: dict) -> bool:
    """Whether a block's parameters switch it off (``enabled: false``)."""
    return params.get("enabled") is False


def parameter_notes(params: dict, most: int = MOST_NOTES) -> list[str]:
    """``key = value`` lines for the parameters a diagram gives (nested ones by their dotted
    path), a long value as ``key = ...``; past ``most`` lines, how many more there are."""
    lines = []
    for key, value in params.items():
        text = f"{key} = {value_text(value)}"
        lines.append(text if len(text) <= NOTE_CHARS else f"{key} = ...")
    if len(lines) > most:
        lines = lines[:most - 1] + [f"(+{len(lines) - most + 1} more parameters)"]
    return lines


def value_text(value) -> str:
    """A parameter's value as a diagram writes it: YAML's ``true``/``false``, lists in brackets."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(value_text(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {value_text(v)}" for k, v in value.items()) + "}"
    return str(value)


def innermost(diagram: Diagram, block: str) -> str:
    """The path of the innermost subsystem holding ``block`` (``""``: none)."""
    found = ""
    for path in diagram.subsystems:
        if block.startswith(path + ".") and len(path) > len(found):
            found = path
    return found


def subsystem_node(diagram: Diagram, schedule: Schedule, rates, sub: Composite,
                   legend: list[tuple[str, str]]) -> Node:
    """A subsystem as one box: its ports, the rates of its blocks, its feedthrough."""
    inside = [n for n in diagram.blocks if n.startswith(sub.path + ".")]
    distinct = sorted({rates.rates[n] for n in inside}, key=Rate.sort_key)
    if len(distinct) == 1:
        colour = rates.colors[inside[0]]
    else:
        colour = MIXED_COLOR
        if all(c != MIXED_COLOR for _, c in legend):
            legend.append((SEVERAL_RATES, MIXED_COLOR))
    line = ", ".join(rate.text(schedule) for rate in distinct)
    off = [sub.name_of(n) for n in inside if is_disabled(diagram.blocks[n].params)]
    return Node(sub.path, f"subsystem {sub.origin}", line, colour, list(sub.inputs), list(sub.outputs),
                {port: feeds_through(diagram, sub, port) for port in sub.outputs},
                notes=[f"{name} {DISABLED}" for name in off]
                + parameter_notes({k: v for k, v in sub.params.items()
                                   if not (k.endswith(".enabled") and k[:-len(".enabled")] in off)}))


def feeds_through(diagram: Diagram, sub: Composite, output: str) -> frozenset[str]:
    """The subsystem inputs that its output ``output`` reads at the same hit, through the
    feedthrough of the blocks inside."""
    entry = {target: name for name, port in sub.inputs.items() for target in port.signals}
    drivers: dict[tuple[str, str], list] = {}
    for c in diagram.connections:
        if not c.delay:
            drivers.setdefault((c.dst_block, c.dst_port), []).append(c)
    found: set[str] = set()
    seen: set[str] = set()
    stack = [sub.outputs[output].signals[0]]
    while stack:
        signal = stack.pop()
        if signal in seen:
            continue
        seen.add(signal)
        block, port = signal.rsplit(".", 1)
        for read in diagram.blocks[block].block.reads(port):
            target = f"{block}.{read}"
            if target in entry:
                found.add(entry[target])
                continue
            stack += [c.src for c in drivers.get((block, read), ()) if c.src_block.startswith(sub.path + ".")]
    return frozenset(found)
