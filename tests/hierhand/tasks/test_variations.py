"""The tasks carried onto varied hands: the same task, relative to the object's faces."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import blocks
from hierhand.control.inverse_kinematics import UnreachableError
from hierhand.model import load_hand
from hierhand.tasks.summaries import TaskBlocks, rigid_target
from hierhand.tasks.variations import SPREAD, Variation, carry, sample

DIAGRAMS = Path(__file__).resolve().parents[3] / "diagrams"
SAME = Variation(mass=0.3, size=(1.0, 1.0), links=(1.0,) * 9, mu_s=1.0, stiffness=1.0, damping=1.0, ki=1.0,
                 safety_ratio=0.6, kp=1.0, kd=1.0, S_a=1.0, S_b=1.0, push=(0.0, -2.0))
"""The shipped hand, gains and push, as a variation."""


def parameters(task: str) -> dict:
    """A task diagram's parameters, keyed by role (``manip``, ``reflex``, ...) as well as by
    block name."""
    diagram = blocks.load_diagram(DIAGRAMS / f"{task}.yaml")
    by_role = TaskBlocks.of_diagram(diagram)
    values = diagram.parameters()
    return {**values, **{role: values[getattr(by_role, role)] for role in ("manip", "reflex", "suppress")},
            "roles": by_role}


def carried(base: dict, v: Variation, moves_object: bool = False) -> dict:
    """``carry``'s overrides, keyed by role."""
    roles = base["roles"]
    names = {roles.block(role): role for role in ("plant", "manip", "reflex", "suppress")}
    out = {}
    for key, value in carry(base, v, moves_object, roles).items():
        block, _, rest = key.rpartition(".")
        out[f"{names[block]}.{rest}" if block in names else key] = value
    return out


def hand_of(overrides: dict, base: dict):
    sections = dict(base["plant"])
    for key, value in overrides.items():
        if key.startswith("plant."):
            sections[key.split(".", 1)[1]] = value
    return load_hand(sections)


@pytest.mark.parametrize("task, moves", [("grasp", False), ("manipulate", True), ("regrasp", False)])
def test_the_shipped_point_carries_onto_itself(task, moves):
    base = parameters(task)
    overrides = carried(base, SAME, moves)
    hand = hand_of(overrides, base)
    np.testing.assert_allclose(hand.q0, load_hand(base["plant"]).q0, atol=1e-9)
    for name, spec in overrides.get("manip.trajectories", {}).items():  # the diagram's waypoints are rounded
        np.testing.assert_allclose(spec["waypoints"], base["manip"]["trajectories"][name]["waypoints"], atol=5e-5)
    assert overrides["manip.kp"] == base["manip"]["kp"] and overrides["suppress.S_b"] == base["suppress"]["S_b"]


def test_a_larger_object_keeps_each_tip_s_gap_to_its_face():
    base = parameters("regrasp")
    bigger = dataclasses.replace(SAME, size=(1.2, 0.8))
    overrides = carried(base, bigger)
    old, new = load_hand(base["plant"]), hand_of(overrides, base)
    gap = lambda hand, f: abs(hand.tip_positions(hand.q0)[f, 0] - hand.object_pose0[0]) - hand.params.object.size[0] / 2
    for f in (0, 1):  # thumb and forefinger beside the left and right faces
        assert gap(new, f) == pytest.approx(gap(old, f), abs=1e-12)
    # the middle finger's target on the right face: the same gap, its height scaled with the face
    old_end = base["manip"]["trajectories"]["middle"]["waypoints"][-1]
    new_end = overrides["manip.trajectories"]["middle"]["waypoints"][-1]
    assert new_end[1] - 0.03 == pytest.approx(old_end[1] - 0.025, abs=1e-12)
    assert new_end[2] - 0.05 == pytest.approx((old_end[2] - 0.05) * 0.8, abs=1e-12)


def test_a_manipulation_keeps_its_rigid_motion_of_the_object():
    base = parameters("manipulate")
    varied = dataclasses.replace(SAME, size=(0.85, 1.15), links=(1.05, 0.95, 1.0, 0.92, 1.08, 1.0, 1.0, 1.0, 1.0))
    overrides = carried(base, varied, moves_object=True)

    def motion(trajectories, hand):
        first = np.array([trajectories[f]["waypoints"][0][1:3] for f in ("thumb", "fore")])
        last = np.array([trajectories[f]["waypoints"][-1][1:3] for f in ("thumb", "fore")])
        return rigid_target(first, last, hand.object_pose0) - hand.object_pose0

    np.testing.assert_allclose(motion(overrides["manip.trajectories"], hand_of(overrides, base)),
                               motion(base["manip"]["trajectories"], load_hand(base["plant"])), atol=1e-12)


def test_a_hand_that_cannot_reach_the_task_is_said_so():
    short = dataclasses.replace(SAME, links=(0.6,) * 9)
    with pytest.raises(UnreachableError, match="thumb: unreachable"):
        carried(parameters("grasp"), short)


def test_the_push_and_the_gains_follow_the_variation():
    varied = dataclasses.replace(SAME, kp=1.3, kd=0.8, ki=2.0, S_a=0.7, S_b=1.4, safety_ratio=0.5, push=(3.0, 1.0))
    base = parameters("grasp")
    overrides = carried(base, varied)
    assert overrides["push.after"][:2] == [3.0, 1.0]
    assert overrides["manip.kp"] == pytest.approx(1.3 * base["manip"]["kp"])
    assert overrides["reflex.ki"] == pytest.approx(2.0 * base["reflex"]["ki"])
    assert overrides["suppress.S_b"] == pytest.approx(1.4 * base["suppress"]["S_b"])
    assert overrides["reflex.safety_ratio"] == 0.5


def test_the_sample_is_fixed_by_its_seed_and_stays_in_the_spread():
    points = sample(200, 7)
    assert points == sample(200, 7) and points != sample(200, 8)
    for p in points:
        assert SPREAD["mass"][0] <= p.mass <= SPREAD["mass"][1]
        assert all(SPREAD["links"][0] <= x <= SPREAD["links"][1] for x in p.links)
        assert SPREAD["push"][0] <= math.hypot(*p.push) <= SPREAD["push"][1]
        assert SPREAD["kp"][0] <= p.kp <= SPREAD["kp"][1]
    angles = [math.atan2(p.push[1], p.push[0]) for p in points]
    assert min(angles) < -2.5 and max(angles) > 2.5  # pushes from every direction
    assert 0.03 < np.mean([not p.sees_slip for p in points]) < 0.2


def test_the_wide_spread_adds_heavier_objects_and_a_torque_with_the_push_and_leaves_the_old_points_alone():
    from hierhand.tasks.variations import WIDE

    wide = sample(100, 7, WIDE)
    assert max(p.mass for p in wide) > SPREAD["mass"][1]  # heavier than the shipped spread holds
    assert all(WIDE["torque"][0] <= p.torque <= WIDE["torque"][1] for p in wide)
    assert min(p.torque for p in wide) < 0 < max(p.torque for p in wide)
    assert all(p.torque == 0.0 for p in sample(20, 7))  # the shipped spread draws no torque ...
    assert [p.mass for p in sample(20, 7)] == [p.mass for p in sample(20, 7, SPREAD)]  # ... and the same points
    overrides = carried(parameters("grasp"), dataclasses.replace(SAME, push=(1.0, 2.0), torque=0.03))
    assert overrides["push.after"] == [1.0, 2.0, 0.03]  # the push's torque reaches the object
