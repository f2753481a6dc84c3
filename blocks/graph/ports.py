"""What the drawing and the DOT text show of a block: its ports in order, its label, and which wires feed through."""

from __future__ import annotations

from ..diagram import Connection, Diagram
from ..schedule import Schedule


def input_ports(diagram: Diagram, name: str) -> list[str]:
    """The block's input ports in declared order, then any wired port it does not declare."""
    ports = list(diagram.blocks[name].block.inputs)
    ports += [c.dst_port for c in diagram.connections if c.dst_block == name and c.dst_port not in ports]
    return list(dict.fromkeys(ports))


def output_ports(diagram: Diagram, name: str) -> list[str]:
    ports = list(diagram.blocks[name].block.outputs)
    ports += [c.src_port for c in diagram.connections if c.src_block == name and c.src_port not in ports]
    return list(dict.fromkeys(ports))


def is_feedthrough(diagram: Diagram, c: Connection) -> bool:
    """Whether the wire carries its value into an output of its target at the same hit."""
    if c.delay:
        return False
    block = diagram.blocks[c.dst_block].block
    return any(c.dst_port in block.reads(o) for o in block.outputs)


def block_label(diagram: Diagram, schedule: Schedule, name: str) -> str:
    return f"{name}\n{diagram.blocks[name].type_name}\n{schedule.rate_text(name)}"
