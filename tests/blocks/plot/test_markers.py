"""Event markers: the framework's Step times, sources registered from Python, one marker
per event, and a broken source left out with its reason instead of breaking the plot (the
hand's phases through the blocks.plot.markers entry point: tests/hierhand/tasks/test_phases.py)."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

import blocks
import blocks.plot.markers as plot_markers
from blocks.plot.markers import Marker, markers, register_markers, unregister_markers


def info_of(diagram) -> dict:
    """What run.json records of the diagram's blocks."""
    return {"block_types": {n: s.type_name for n, s in diagram.blocks.items()}, "parameters": diagram.parameters()}


STEPS = """
blocks:
  a: {type: Step, period: 1 ms, params: {time: 0.25}}
  b: {type: Step, period: 1 ms, params: {time: 0.1, before: 1.0, after: 0.0}}
  g: {type: Gain, params: {k: 2.0}}
connections: [a.y -> g.u]
log: [g.y]
"""


@pytest.fixture
def no_installed(monkeypatch):
    monkeypatch.setattr(plot_markers, "load_group", lambda group, refuse: ({}, {}))


def test_each_step_is_an_instant(no_installed):
    found, notes = markers(info_of(blocks.loads_diagram(STEPS)))
    assert found == [Marker(0.1, 0.1, "", "b: step at 0.1 s"), Marker(0.25, 0.25, "", "a: step at 0.25 s")]
    assert notes == [] and found[0].instant and found[0].label == "b: step at 0.1 s"


@dataclass(frozen=True)
class Phase:
    """Shaped like a marker, as an application's own records may be."""

    start: float
    end: float
    during: str
    after: str


def test_registered_sources_add_markers_and_repeats_are_one(no_installed):
    def phases(info):
        return [Phase(0.0, 0.2, "warming up", "warm"), Phase(0.25, 0.25, "", "a: step at 0.25 s")]

    register_markers("test-phases", phases)
    try:
        found, _ = markers(info_of(blocks.loads_diagram(STEPS)))
    finally:
        unregister_markers("test-phases")
    assert [(m.start, m.end, m.label) for m in found] == [
        (0.0, 0.2, "warming up"), (0.1, 0.1, "b: step at 0.1 s"), (0.25, 0.25, "a: step at 0.25 s")]


def test_a_broken_source_is_left_out_with_its_reason(no_installed):
    register_markers("broken", lambda info: 1 / 0)
    register_markers("shapeless", lambda info: [object()])
    try:
        found, notes = markers(info_of(blocks.loads_diagram(STEPS)))
    finally:
        unregister_markers("broken")
        unregister_markers("shapeless")
    assert len(found) == 2
    assert notes[0] == "markers 'broken' left out: ZeroDivisionError: division by zero"
    assert notes[1].startswith("markers 'shapeless' left out: ValueError")
