"""The hand blocks' units and element names: in run.json, in 'hierhand blocks'."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import blocks
from hierhand.control.grasp_reflex import GraspReflex
from hierhand.control.manipulation_pd import ManipulationPD
from hierhand.control.suppresser import Suppresser
from hierhand.model.handfile import default_hand_dict
from hierhand.model.plant import HandPlant
from hierhand.model.support import ObjectSupport

REPO = Path(__file__).resolve().parents[3]
JOINTS = [f"{f}.{j}" for f in ("thumb", "fore", "middle") for j in (1, 2, 3)]


def test_every_port_of_the_hand_blocks_has_a_unit_and_fitting_element_names():
    plant = HandPlant()
    for block in (plant, GraspReflex(plant), ManipulationPD(plant), Suppresser(), ObjectSupport(plant)):
        for port, width in (*block.inputs.items(), *block.outputs.items()):
            units = block.port_units(port)
            labels = block.element_labels(port)
            assert isinstance(units, str) or len(units) == width, (type(block).__name__, port)
            assert labels is not None and len(labels) == width == len(set(labels)), (type(block).__name__, port)
    assert plant.element_labels("q") == JOINTS and plant.port_units("q") == "rad"
    assert plant.port_units("qd") == "rad/s" and plant.port_units("tau") == "N m"
    assert plant.element_labels("fn") == ["thumb", "fore", "middle"] and plant.port_units("ft") == "N"
    assert plant.element_labels("tip")[:3] == ["thumb.x", "thumb.y", "thumb.phi"]
    assert plant.port_units("tip") == ["m", "m", "rad"] * 3
    assert plant.element_labels("obj") == ["x", "y", "theta"] and plant.port_units("obj") == ["m", "m", "rad"]
    assert plant.port_units("ratio") == "1" and plant.port_units("nope") is None
    assert Suppresser().element_labels("share") == ["f1", "f2", "f3"]  # it does not know the hand


def test_finger_names_follow_the_hand():
    fingers = default_hand_dict()["fingers"]
    for f, name in zip(fingers, ("a", "b", "c")):
        f["name"] = name
    plant = HandPlant(fingers=fingers)
    assert plant.element_labels("q")[:4] == ["a.1", "a.2", "a.3", "b.1"]
    assert GraspReflex(plant, grasp=["a", "b"]).element_labels("force") == ["a", "b", "c"]


def test_a_run_records_the_units_of_its_signals(tmp_path):
    d = blocks.load_diagram(REPO / "diagrams" / "regrasp.yaml")
    r = blocks.simulate(d, t_end="20 ms")
    r.save(tmp_path)
    again = blocks.Results.load(tmp_path)
    assert again.unit("plant.q") == "rad" and again.element_labels("plant.q") == JOINTS
    assert again.unit("ctrl.reflex.tau_g") == "N m" and again.unit("ctrl.reflex.force") == "N"
    assert again.units("plant.obj") == ["m", "m", "rad"]
    assert again.unit("ctrl.suppress.share") == "1"


def test_hierhand_blocks_lists_units_beside_the_ports(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "hierhand", "blocks", "HandPlant"], capture_output=True,
                          text=True, cwd=tmp_path, timeout=120)
    assert proc.returncode == 0, proc.stderr
    lines = [line.strip() for line in proc.stdout.splitlines()]
    assert f"q[9]        rad; elements {', '.join(JOINTS)}" in lines
    assert "obj[3]      x (m), y (m), theta (rad)" in lines
    assert "fn[3]       N; elements thumb, fore, middle" in lines
