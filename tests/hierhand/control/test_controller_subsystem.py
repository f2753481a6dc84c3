"""The hand's controller blocks composed as one subsystem, the plant outside it.

``tests/hierhand/diagrams/controller.yaml`` holds the grasp reflex, manipulation PD,
suppresser and object support, with the plant's signals as its inputs and the joint
torques (and the support's force) as its outputs; its blocks refer to the plant through
the reference ``plant``, which the including diagram binds. ``regrasp_composed.yaml`` is
``diagrams/regrasp.yaml`` written with it, and gives the same samples to the last bit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import blocks

ROOT = Path(__file__).resolve().parents[3]
HERE = ROOT / "tests" / "hierhand" / "diagrams"
REGRASP = ROOT / "diagrams" / "regrasp.yaml"
COMPOSED = HERE / "regrasp_composed.yaml"
CONTROLLERS = ("reflex", "manip", "suppress", "support")


def inner(signal: str) -> str:
    """``reflex.tau_g`` as the composed diagram names it: ``ctrl.reflex.tau_g``."""
    return f"ctrl.{signal}" if signal.split(".")[0] in CONTROLLERS else signal


def assert_same(flat: blocks.Results, composed: blocks.Results) -> None:
    assert {inner(s) for s in flat} == set(composed)
    for signal in flat:
        (ta, va), (tb, vb) = flat[signal], composed[inner(signal)]
        assert np.array_equal(ta, tb) and np.array_equal(va, vb), signal


@pytest.fixture(scope="module")
def runs():
    return blocks.simulate(blocks.load_diagram(REGRASP)), blocks.simulate(blocks.load_diagram(COMPOSED))


def test_the_regrasp_with_its_controller_as_a_subsystem_is_bit_identical(runs):
    assert_same(*runs)
    assert runs[1].complete


def test_the_composed_regrasp_plans_as_the_flat_one():
    flat, composed = blocks.load_diagram(REGRASP), blocks.load_diagram(COMPOSED)
    assert list(flat.blocks) == ["plant", *CONTROLLERS]
    assert list(composed.blocks) == ["plant", *(f"ctrl.{n}" for n in CONTROLLERS)]
    a, b = blocks.build_schedule(flat, flat.t_end), blocks.build_schedule(composed, composed.t_end)

    def text(program) -> str:
        out = program.describe()
        for name in CONTROLLERS:
            out = out.replace(f" {name}", f" ctrl.{name}")
        return out

    assert [text(p) for p in [a.initial, *a.programs]] == [p.describe() for p in [b.initial, *b.programs]]
    assert a.advanced == b.advanced == {"plant"}
    assert {str(r) for r in composed.references()} == {"ctrl.reflex.hand -> plant", "ctrl.manip.hand -> plant",
                                                       "ctrl.support.hand -> plant"}


def test_the_plant_given_once_reaches_the_controllers_inside():
    heavy = {"plant.object.mass": 0.36}
    composed = blocks.load_diagram(COMPOSED, overrides=heavy)
    plant = composed.blocks["plant"].block
    assert all(composed.blocks[f"ctrl.{n}"].block.hand is plant.hand for n in ("reflex", "manip", "support"))
    short = "50 ms"
    assert_same(blocks.simulate(blocks.load_diagram(REGRASP, overrides=heavy), t_end=short),
                blocks.simulate(composed, t_end=short))


def test_the_controller_validates_on_its_own_with_a_stand_in_plant():
    d = blocks.load_diagram(HERE / "controller.yaml")
    assert d.open_issue() is not None
    assert {n: p.width for n, p in d.inputs.items()} == {"q": 9, "qd": 9, "tip": 9, "fn": 3, "ft": 3, "normal": 6, "obj": 3}
    q, tau = d.inputs["q"], d.outputs["tau"]
    assert q.signals == ("reflex.q", "manip.q") and q.units == "rad" and q.labels[:2] == ("thumb.1", "thumb.2")
    assert tau.units == "N m" and tau.width == 9


def test_a_binding_to_a_block_that_is_no_plant_is_a_load_error(tmp_path):
    text = COMPOSED.read_text(encoding="utf-8").replace("bind: {plant: plant}", "bind: {plant: wrong}")
    text = text.replace("  plant: {type: HandPlant, period: 0.1 ms}\n",
                        "  plant: {type: HandPlant, period: 0.1 ms}\n  wrong: {type: Constant, params: {value: 1.0}}\n")
    path = tmp_path / "composed.yaml"
    path.write_text(text, encoding="utf-8")
    (tmp_path / "controller.yaml").write_text((HERE / "controller.yaml").read_text(encoding="utf-8"))
    with pytest.raises(blocks.DiagramError) as info:
        blocks.load_diagram(path)
    messages = {i.message for i in info.value.issues}
    assert "block 'ctrl.reflex' (GraspReflex): parameter 'hand': block 'wrong' is a Constant; expected a HandPlant " \
           "or an FMU exported by 'hierhand fmu export'" in messages
