"""``hierhand blocks``' description of a type: its ports with their units and elements."""

from __future__ import annotations

from blocks import Block
from blocks.typeinfo import describe_type


class Plain(Block):
    def __init__(self):
        self.inputs = {"u": 1}
        self.outputs = {"y": 2}


class Described(Block):
    def __init__(self):
        self.inputs = {"u": 3, "bias": 1}
        self.input_defaults = {"bias": 0.0}
        self.outputs = {"pose": 3, "flags": 2, "bare": 2}

    def port_units(self, port):
        return {"u": "N m", "bias": "N m", "pose": ["m", "m", "rad"], "flags": "1"}.get(port)

    def element_labels(self, port):
        return {"u": ["a.1", "a.2", "b.1"], "pose": ["x", "y", "theta"]}.get(port)


def test_ports_without_units_or_names_stay_on_one_line():
    text = describe_type(Plain)
    assert "  inputs: u[1]\n  outputs: y[2]\n" in text


def test_each_port_shows_its_unit_and_element_names():
    lines = describe_type(Described).splitlines()
    start = lines.index("  inputs (optional: bias):")
    assert lines[start:start + 7] == [
        "  inputs (optional: bias):",
        "    u[3]      N m; elements a.1, a.2, b.1",
        "    bias[1]   N m",
        "  outputs:",
        "    pose[3]   x (m), y (m), theta (rad)",
        "    flags[2]  1 (dimensionless)",
        "    bare[2]",
    ]
