"""What the drawing and the DOT text show of a box: its ports in order, and which wires feed through."""

from __future__ import annotations

from blocks.builder.diagram import Connection
from .view import Picture


def input_ports(picture: Picture, name: str) -> list[str]:
    """The box's input ports in declared order, then any wired port it does not declare."""
    return picture.nodes[name].inputs


def output_ports(picture: Picture, name: str) -> list[str]:
    return picture.nodes[name].outputs


def is_feedthrough(picture: Picture, c: Connection) -> bool:
    """Whether the wire carries its value into an output of its target at the same hit."""
    if c.delay:
        return False
    return any(c.dst_port in reads for reads in picture.nodes[c.dst_block].feeds.values())
