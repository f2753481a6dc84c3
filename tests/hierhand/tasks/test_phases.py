"""Phases of a hand task read from its diagram's blocks (``hierhand.tasks.phases``)."""

from __future__ import annotations

from importlib.metadata import entry_points
from pathlib import Path

import numpy as np

import blocks
from blocks.plot.markers import ENTRY_POINT_GROUP, markers
from hierhand.model import load_hand
from hierhand.tasks.phases import phase_at, task_phases

ROOT = Path(__file__).resolve().parents[3]


def test_regrasp_phases_from_the_diagram():
    diagram = blocks.load_diagram(ROOT / "diagrams" / "regrasp.yaml")
    info = {"block_types": {n: s.type_name for n, s in diagram.blocks.items()}, "parameters": diagram.parameters()}
    hand = load_hand(info["parameters"]["plant"])  # as run.json keeps them
    phases = task_phases(info, hand)
    assert phase_at(phases, 0.05) == "object on its support (released at 0.1 s)"
    assert phase_at(phases, 0.12) == "support released"
    assert phase_at(phases, 0.2) == "middle finger moving in (0.15-0.35 s)"
    assert phase_at(phases, 0.36) == "middle finger in place"
    assert phase_at(phases, 0.5) == "forefinger withdrawing (0.46-0.76 s)"
    assert phase_at(phases, 0.9) == "forefinger withdrawn"
    # with the contacts of the run: a withdrawal that did not let go says so
    assert (phase_at(phases, 0.9, lambda f: f != "middle")
            == "forefinger told to withdraw (by 0.76 s) but still in contact")
    assert phase_at(phases, 0.36, lambda f: f != "middle") == "middle finger moved in (by 0.35 s) but not in contact"


def test_manipulation_and_grasp_phases():
    info = {"block_types": {"manip": "ManipulationPD", "push": "Step", "support": "ObjectSupport"},
            "parameters": {"manip": {"trajectories": {
                "thumb": {"waypoints": [[0.3, -0.03, 0.06, 0.0], [0.8, -0.025, 0.065, 0.0]]},
                "fore": {"waypoints": [[0.3, 0.03, 0.06, 3.0], [0.8, 0.035, 0.065, 3.0]]}}},
                "push": {"time": 0.5}, "support": {"until": 0.1}}}
    moved = lambda t: np.array([0.0, 0.06, 0.0]) if t < 0.5 else np.array([0.005, 0.065, 0.0])  # noqa: E731
    phases = task_phases(info, object_pose=moved)
    assert phase_at(phases, 0.4) == "thumb and forefinger moving the object (0.3-0.8 s)"
    assert phase_at(phases, 0.9) == "thumb and forefinger done moving the object"
    assert phase_at(phases, 0.2) == "support released"
    assert task_phases({}) == []


def test_the_hand_registers_its_phases_as_plot_markers():
    """``hierhand plot`` marks a task's phases: the support, then each finger's trajectory
    from its first to its last waypoint."""
    installed = {ep.name: ep.value for ep in entry_points(group=ENTRY_POINT_GROUP)}
    assert installed == {"task_phases": "hierhand.tasks.phases:task_phases"}
    diagram = blocks.load_diagram(ROOT / "diagrams" / "regrasp.yaml")
    parameters = diagram.parameters()
    found, notes = markers({"block_types": {n: s.type_name for n, s in diagram.blocks.items()},
                            "parameters": parameters})
    assert notes == []
    spans = [(0.0, parameters["support"]["until"])]
    for finger in ("middle", "fore"):
        waypoints = parameters["ctrl.manip"]["trajectories"][finger]["waypoints"]
        spans.append((waypoints[0][0], waypoints[-1][0]))
    assert [(m.start, m.end) for m in found] == spans
    assert found[0].during == "object on its support (released at 0.1 s)"
