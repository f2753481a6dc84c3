"""The hand's hierarchical controller as one shipped subsystem (``diagrams/controller.yaml``)
that the task diagrams use, the plant and the object's support outside it.

The oracle is the flat diagram written out by hand from the two files (``inlined``): the
controller's blocks put in place of its entry, with the entry's parameters and binding
applied and the wires through its ports drawn to the blocks behind them. Each task must
plan and run exactly as that flat diagram does, to the last bit.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
import yaml

import blocks

ROOT = Path(__file__).resolve().parents[3]
DIAGRAMS = ROOT / "diagrams"
CONTROLLER = DIAGRAMS / "controller.yaml"
TASKS = ("grasp", "manipulate", "regrasp", "regrasp_unsuppressed")
SUBSYSTEM = "ctrl"


def _flat(text: str) -> str:
    """Names of the controller's blocks as the flat diagram has them: ``ctrl_reflex.tau_g``
    for ``ctrl.reflex.tau_g``."""
    return text.replace(f"{SUBSYSTEM}.", f"{SUBSYSTEM}_")


def inlined(task: Path) -> dict:
    """The task diagram with its controller entry replaced by the controller's blocks."""
    top = yaml.safe_load(task.read_text(encoding="utf-8"))
    entry = top["blocks"][SUBSYSTEM]
    sub = yaml.safe_load((task.parent / entry["diagram"]).read_text(encoding="utf-8"))
    bind = entry.get("bind", {})
    flat_blocks = {}
    for name, spec in top["blocks"].items():
        if name != SUBSYSTEM:
            flat_blocks[name] = spec
            continue
        for inner, inner_spec in sub["blocks"].items():
            spec = copy.deepcopy(inner_spec)
            params = spec.setdefault("params", {})
            for key, value in params.items():
                if key == "hand":
                    params[key] = bind[value]
            for key, value in entry.get("params", {}).items():
                block, _, param = key.partition(".")
                if block == inner:
                    params[param] = value
            flat_blocks[f"{SUBSYSTEM}_{inner}"] = spec

    def inner_end(endpoint: str) -> str:
        return f"{SUBSYSTEM}_{endpoint}"

    wires = [f"{inner_end(a)} -> {inner_end(b)}" for a, b in (c.split(" -> ") for c in sub["connections"])]
    for connection in top["connections"]:
        src, dst = connection.split(" -> ")
        if src.startswith(f"{SUBSYSTEM}."):
            src = inner_end(sub["outputs"][src.split(".")[1]])
        if dst.startswith(f"{SUBSYSTEM}."):
            targets = sub["inputs"][dst.split(".")[1]]
            for target in [targets] if isinstance(targets, str) else targets:
                wires.append(f"{src} -> {inner_end(target)}")
            continue
        wires.append(f"{src} -> {dst}")
    log = list(top.get("log", [])) + [inner_end(signal) for signal in sub.get("log", [])]
    return {"name": top["name"], "time": top["time"], "blocks": flat_blocks, "connections": wires, "log": log}


def flat_diagram(task: str, tmp_path: Path) -> blocks.Diagram:
    path = tmp_path / f"{task}_flat.yaml"
    path.write_text(yaml.safe_dump(inlined(DIAGRAMS / f"{task}.yaml"), sort_keys=False), encoding="utf-8")
    return blocks.load_diagram(path)


def assert_same(flat: blocks.Results, composed: blocks.Results) -> None:
    assert {_flat(s) for s in composed} == set(flat)
    for signal in composed:
        (ta, va), (tb, vb) = composed[signal], flat[_flat(signal)]
        assert np.array_equal(ta, tb) and np.array_equal(va, vb), signal


@pytest.mark.parametrize("task", TASKS)
def test_every_task_with_the_controller_subsystem_runs_as_its_flat_diagram(task, tmp_path):
    composed = blocks.load_diagram(DIAGRAMS / f"{task}.yaml")
    assert {n for n in composed.blocks if n.startswith(f"{SUBSYSTEM}.")} == {"ctrl.reflex", "ctrl.manip",
                                                                             "ctrl.suppress"}
    flat = flat_diagram(task, tmp_path)
    a, b = blocks.build_schedule(flat, flat.t_end), blocks.build_schedule(composed, composed.t_end)
    assert [p.describe() for p in [a.initial, *a.programs]] == \
        [_flat(p.describe()) for p in [b.initial, *b.programs]]
    results = blocks.simulate(composed)
    assert results.complete
    assert_same(blocks.simulate(flat), results)


def test_the_tasks_differ_in_what_they_give_the_controller():
    given = {task: yaml.safe_load((DIAGRAMS / f"{task}.yaml").read_text())["blocks"][SUBSYSTEM] for task in TASKS}
    assert all(entry["diagram"] == "controller.yaml" and entry["bind"] == {"plant": "plant"}
               for entry in given.values())
    params = {task: entry.get("params", {}) for task, entry in given.items()}
    assert params["grasp"] == {}  # the controller file's own values
    assert set(params["manipulate"]) == {"manip.trajectories"}
    assert params["regrasp_unsuppressed"] == {**params["regrasp"], "suppress.enabled": False}


def test_the_plant_given_once_reaches_the_controllers_inside(tmp_path):
    heavy = {"plant.object.mass": 0.36}
    composed = blocks.load_diagram(DIAGRAMS / "regrasp.yaml", overrides=heavy)
    plant = composed.blocks["plant"].block
    assert all(composed.blocks[n].block.hand is plant.hand for n in ("ctrl.reflex", "ctrl.manip", "support"))
    flat_path = tmp_path / "regrasp_flat.yaml"
    flat_path.write_text(yaml.safe_dump(inlined(DIAGRAMS / "regrasp.yaml"), sort_keys=False), encoding="utf-8")
    short = "50 ms"
    assert_same(blocks.simulate(blocks.load_diagram(flat_path, overrides=heavy), t_end=short),
                blocks.simulate(composed, t_end=short))


def test_the_controller_validates_on_its_own_with_a_stand_in_plant():
    d = blocks.load_diagram(CONTROLLER)
    assert d.open_issue() is not None
    assert {n: p.width for n, p in d.inputs.items()} == {"q": 9, "qd": 9, "tip": 9, "fn": 3, "ft": 3, "normal": 6,
                                                        "obj": 3, "support": 3}
    q, tau = d.inputs["q"], d.outputs["tau"]
    assert q.signals == ("reflex.q", "manip.q") and q.units == "rad" and q.labels[:2] == ("thumb.1", "thumb.2")
    assert tau.units == "N m" and tau.width == 9


def test_the_controller_on_a_plant_without_a_support(tmp_path):
    """The support input may stay unconnected (the PD then carries the whole load): the
    controller on a heavier hand of another name, with nothing but the plant."""
    (tmp_path / "controller.yaml").write_text(CONTROLLER.read_text(encoding="utf-8"), encoding="utf-8")
    path = tmp_path / "other.yaml"
    path.write_text("""
time: {t_end: 0.3 s}
blocks:
  hand: {type: HandPlant, period: 0.1 ms, params: {object: {mass: 0.2}}}
  brain: {diagram: controller.yaml, bind: {plant: hand}}
connections:
  - hand.q -> brain.q
  - hand.qd -> brain.qd
  - hand.tip -> brain.tip
  - hand.fn -> brain.fn
  - hand.ft -> brain.ft
  - hand.normal -> brain.normal
  - hand.obj -> brain.obj
  - brain.tau -> hand.tau
log: [hand.contact, hand.obj]
""", encoding="utf-8")
    d = blocks.load_diagram(path)
    assert d.blocks["brain.manip"].block.hand is d.blocks["hand"].block.hand
    run = blocks.simulate(d)
    assert run.complete
    t, contact = run["hand.contact"]
    _, obj = run["hand.obj"]
    assert contact[-1, :2].all()  # thumb and forefinger hold the object from the start, unsupported
    assert obj[0, 1] - obj[-1, 1] < 0.005


def test_a_binding_to_a_block_that_is_no_plant_is_a_load_error(tmp_path):
    text = (DIAGRAMS / "regrasp.yaml").read_text(encoding="utf-8").replace("bind: {plant: plant}",
                                                                        "bind: {plant: wrong}")
    text = text.replace("  plant:    {type: HandPlant, period: 0.1 ms}\n",
                        "  plant:    {type: HandPlant, period: 0.1 ms}\n  wrong: {type: Constant, params: {value: 1.0}}\n")
    path = tmp_path / "composed.yaml"
    path.write_text(text, encoding="utf-8")
    (tmp_path / "controller.yaml").write_text(CONTROLLER.read_text(encoding="utf-8"))
    with pytest.raises(blocks.DiagramError) as info:
        blocks.load_diagram(path)
    messages = {i.message for i in info.value.issues}
    assert "block 'ctrl.reflex' (GraspReflex): parameter 'hand': block 'wrong' is a Constant; expected a HandPlant " \
           "or an FMU exported by 'hierhand fmu export'" in messages
