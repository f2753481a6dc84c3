"""One hand per diagram: the blocks that model the hand take it from the plant (``hand: plant``).

``hand_of`` resolves a ``hand`` parameter: a ``HandPlant`` gives its hand, an FMU made by
``hierhand fmu export`` the hand rebuilt from its parameters, anything else is an error
naming what it got. In the shipped diagrams a ``--set`` on the plant reaches every block.
"""

from __future__ import annotations

import re
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

import blocks
from blocks import DiagramError
from hierhand.control.grasp_reflex import GraspReflex
from hierhand.fmu_export import export_plant_fmu
from hierhand.model import Hand, HandFileError, HandPlant, hand_of, load_hand
from hierhand.model.handfile import default_hand_dict

ROOT = Path(__file__).resolve().parents[3]
REGRASP = ROOT / "diagrams" / "regrasp.yaml"
HEAVY = {"plant.object.mass": 0.36, "plant.contact.mu_s": 1.1, "plant.contact.mu_d": 1.0,
         "plant.fingers.1.links.0.length": 0.041}


@pytest.fixture(scope="module")
def fmu(tmp_path_factory) -> Path:
    return export_plant_fmu(tmp_path_factory.mktemp("fmu") / "plant.fmu", fmi=2)


def without(path: Path, parameter: str, out: Path) -> Path:
    """A copy of an exported FMU whose parameter ``parameter`` is renamed (not a hierhand plant any more)."""
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(out, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                data = data.replace(f'name="{parameter}"'.encode(), b'name="renamed"')
            dst.writestr(item, data)
    return out


# -- the shipped diagrams: one hand ----------------------------------------------------------------


def test_every_block_of_a_diagram_models_the_plants_hand_after_overrides():
    d = blocks.load_diagram(REGRASP, overrides=HEAVY)
    plant, reflex, manip, support = (d.blocks[n].block for n in ("plant", "ctrl.reflex", "ctrl.manip", "support"))
    hand = plant.hand
    assert reflex.hand is hand and manip.hand is hand and support.hand is hand
    assert hand.params.object.mass == 0.36
    assert (hand.params.contact.mu_s, hand.params.contact.mu_d) == (1.1, 1.0)
    assert hand.params.fingers[1].links[0].length == 0.041
    assert hand.params.fingers[0] == Hand.default().params.fingers[0]  # the other fingers stay the default's

    # the reflex's tip Jacobians (inside its native output) are those of the longer forefinger
    changed = load_hand({"fingers": hand.params.to_dict()["fingers"]})
    assert not np.allclose(changed.tip_jacobians(changed.q0)[1], Hand.default().tip_jacobians(changed.q0)[1])
    inputs = {"q": hand.q0, "tip": hand.tip_poses(hand.q0).ravel(), "fn": np.array([2.0, 2.0, 0.0]),
              "ft": np.zeros(3), "normal": np.array([1.0, 0.0, -1.0, 0.0, 0.0, 0.0])}
    own = GraspReflex(hand=changed, grasp=["thumb", "fore"], ki=50, min_force=3.0)
    own.bind(0.001)
    state = reflex.initial_state()
    np.testing.assert_array_equal(reflex.output(0.0, state, inputs)["tau_g"], own.output(0.0, state, inputs)["tau_g"])

    # the PD's load feedforward and the support carry 0.36 kg
    normal = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 0.0]])
    tau_ff = manip.output(0.0, None, {"q": hand.q0, "qd": np.zeros(9), "fn": np.array([2.0, 2.0, 0.0]),
                                      "normal": normal.ravel(), "obj": hand.object_pose0})["tau_ff"]
    load = tau_ff - hand.bias(hand.q0, np.zeros(9))
    points = hand.tip_positions(hand.q0) + hand.tip_radius[:, None] * normal
    carried = sum(np.linalg.lstsq(hand.point_jacobian(hand.q0, f, points[f]).T, load[3 * f:3 * f + 3],
                                  rcond=None)[0] for f in (0, 1))
    np.testing.assert_allclose(carried, -0.36 * hand.gravity, rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(load[6:], 0.0)
    np.testing.assert_array_equal(support.output(0.0, None, {})["y"], [0.0, 0.36 * 9.81, 0.0])


def test_the_diagrams_record_the_plants_name_and_the_overridden_hand():
    d = blocks.load_diagram(REGRASP, overrides=HEAVY)
    params = d.parameters()
    assert params["ctrl.reflex"]["hand"] == params["ctrl.manip"]["hand"] == params["support"]["hand"] == "plant"
    assert params["plant"]["object"] == {"mass": 0.36}
    assert params["plant"]["fingers"][1]["links"][0]["length"] == 0.041
    assert params["plant"]["fingers"][2] == default_hand_dict()["fingers"][2]


@pytest.mark.parametrize("name", ["grasp", "manipulate", "regrasp", "regrasp_unsuppressed"])
def test_every_shipped_diagram_gives_its_hand_once(name):
    d = blocks.load_diagram(ROOT / "diagrams" / f"{name}.yaml")
    refs = {str(r) for r in d.references()}
    assert refs == {"ctrl.reflex.hand -> plant", "ctrl.manip.hand -> plant", "support.hand -> plant"}
    assert d.blocks["support"].type_name == "ObjectSupport"
    assert set(d.parameters()["ctrl.reflex"]) & {"gravity", "fingers", "object", "contact"} == set()


def test_a_bad_index_into_the_fingers_is_one_line_naming_the_set():
    with pytest.raises(DiagramError) as info:
        blocks.load_diagram(REGRASP, overrides={"plant.fingers.3.links.0.length": 0.041})
    assert [str(i) for i in info.value.issues] == [
        "--set plant.fingers.3.links.0.length=0.041: index 3 is out of range: 'plant.fingers' has 3 element(s) "
        "(hint: valid indices: 0 to 2)"]


def test_a_hand_reference_to_another_kind_of_block_names_it():
    with pytest.raises(DiagramError) as info:
        blocks.load_diagram(ROOT / "diagrams" / "grasp.yaml", overrides={"support.hand": "push"})
    (issue,) = info.value.issues
    assert issue.message == ("block 'support' (ObjectSupport): parameter 'hand': block 'push' is a Step; "
                             "expected a HandPlant or an FMU exported by 'hierhand fmu export'")


# -- hand_of -------------------------------------------------------------------------------------------


def test_hand_of_a_hand_or_a_plant():
    hand = load_hand({"object": {"mass": 0.5}})
    assert hand_of(hand) is hand
    assert hand_of(HandPlant.from_hand(hand)).params == hand.params


def test_hand_of_an_exported_fmu_is_the_hand_of_its_parameters(fmu):
    from blocks.fmu import FMU

    plain = hand_of(FMU(fmu))
    assert plain.params == Hand.default().params
    np.testing.assert_array_equal(plain.vector, Hand.default().vector)
    heavy = hand_of(FMU(fmu, start_values={"object.mass": 0.36, "fingers[2].links[1].length": 0.041}))
    fingers = Hand.default().params.to_dict()["fingers"]
    fingers[1]["links"][0]["length"] = 0.041
    assert heavy.params == load_hand({"object": {"mass": 0.36, "inertia": 1.25e-4}, "fingers": fingers}).params
    assert heavy.names == ("thumb", "fore", "middle")


def test_an_fmu_that_is_not_a_hierhand_plant_is_refused(fmu, tmp_path):
    from blocks.fmu import FMU

    other = FMU(without(fmu, "object.mass", tmp_path / "other.fmu"))
    with pytest.raises(ValueError, match=r"^parameter 'hand': the block is an FMU \(other.fmu\) without the "
                                         r"hand's parameters \(no object.mass\); expected a HandPlant, an FMU "
                                         r"exported by 'hierhand fmu export', or a Hand$"):
        hand_of(other)


def test_an_fmu_with_invalid_hand_parameters_names_them(fmu):
    from blocks.fmu import FMU

    with pytest.raises(HandFileError, match=r"plant.fmu(.|\n)*contact.mu_d"):
        hand_of(FMU(fmu, start_values={"contact.mu_d": 2.0}))


@pytest.mark.parametrize("source, message", [
    ("plant", "got the text 'plant' (a block's name is resolved only in a diagram)"),
    (None, "got a NoneType"),
    ({"object": {"mass": 0.3}}, "got a dict"),
])
def test_hand_of_anything_else_says_what_it_got(source, message):
    with pytest.raises(ValueError, match=f"^parameter 'hand': {re.escape(message)}; expected a HandPlant"):
        hand_of(source)


def test_the_fmu_diagram_models_the_fmus_hand(fmu):
    d = blocks.load_diagram(ROOT / "diagrams" / "regrasp_fmu.yaml",
                            overrides={"plant.path": str(fmu), "plant.start_values": {"object.mass": 0.36}})
    hand = d.blocks["ctrl.reflex"].block.hand
    assert d.blocks["ctrl.manip"].block.hand is hand and d.blocks["support"].block.hand is hand
    assert hand.params.object.mass == 0.36
    np.testing.assert_array_equal(d.blocks["support"].block.force, [0.0, 0.36 * 9.81, 0.0])


# -- validate ------------------------------------------------------------------------------------------


def validate(path: Path, cwd: Path) -> str:
    proc = subprocess.run([sys.executable, "-m", "hierhand", "validate", str(path)], capture_output=True,
                          text=True, cwd=cwd, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


def test_validate_shows_where_the_hand_comes_from_and_who_uses_it(tmp_path):
    out = validate(REGRASP, tmp_path)
    assert "references:\n  ctrl.reflex.hand -> plant\n  ctrl.manip.hand -> plant\n  support.hand -> plant\n" in out
    assert ("  plant: hand: the built-in default hand; referenced by ctrl.reflex.hand, ctrl.manip.hand, support.hand\n"
            in out)
    (tmp_path / "heavy.yaml").write_text("object: {mass: 0.36}\n")
    text = REGRASP.read_text().replace("plant:    {type: HandPlant, period: 0.1 ms}",
                                       "plant:    {type: HandPlant, period: 0.1 ms, params_file: heavy.yaml}")
    (tmp_path / "regrasp.yaml").write_text(text)
    (tmp_path / "controller.yaml").write_text((REGRASP.parent / "controller.yaml").read_text())
    out = validate(tmp_path / "regrasp.yaml", tmp_path)
    assert (f"  plant: params_file {tmp_path / 'heavy.yaml'}; hand: object from the diagram, the rest from the "
            "built-in default hand; referenced by ctrl.reflex.hand, ctrl.manip.hand, support.hand\n") in out
