"""The additions beyond the paper as named switches: the paper-only configuration and the search."""

from __future__ import annotations

import math

import pytest

from hierhand.control.grasp_reflex import GraspReflex
from hierhand.model import load_hand
from hierhand.tasks.ablations import ABLATIONS, ALL, MECHANISMS, paper_only, smallest_set, switched_off


def test_the_paper_only_configuration_switches_every_mechanism_off_and_keeps_the_modelling_choices():
    extra = paper_only()
    for ablation in ABLATIONS:
        for task in ablation.tasks:
            present = all(extra[task].get(key) == value for key, value in ablation.overrides.items())
            assert present == ablation.mechanism, (ablation.name, task)
    kept = paper_only(keep=[MECHANISMS[0].name])
    assert all(key not in kept[task] for key in MECHANISMS[0].overrides for task in ALL)
    with pytest.raises(KeyError, match="no addition called"):
        paper_only(keep=["a wish"])


def test_each_switch_is_declared_once():
    keys = [key for a in ABLATIONS for key in a.overrides]
    assert len(keys) == len(set(keys))  # no two additions set the same parameter
    assert len({a.name for a in ABLATIONS}) == len(ABLATIONS)


def test_backward_elimination_keeps_exactly_the_additions_a_task_fails_without():
    needed = {MECHANISMS[1].name, MECHANISMS[4].name}

    def succeeds(off: frozenset[str]) -> float:
        return float(not (off & needed))

    assert smallest_set(succeeds) == needed
    # a rate that each dropped addition lowers by one success: kept unless the tolerance allows it
    assert smallest_set(lambda off: 10.0 - len(off)) == {a.name for a in MECHANISMS}
    assert smallest_set(lambda off: 10.0 - len(off), tolerance=2) == {a.name for a in MECHANISMS[2:]}
    assert switched_off([])["grasp"] == {}


def _hand(mass: float, mu_s: float):
    return load_hand({"object": {"mass": mass}, "contact": {"mu_s": mu_s, "mu_d": 0.9 * mu_s}})


def test_the_squeeze_follows_the_object_s_weight_above_the_floor():
    for mass in (0.15, 0.3, 0.6):
        hand = _hand(mass, 1.0)
        reflex = GraspReflex(hand=hand, min_force=1.0, squeeze_from_weight=True)
        # two fingers carry m g by friction at the ratio target: each m g / (2 ratio_target)
        carried = 2 * reflex.min_force * reflex.ratio_target
        assert carried == pytest.approx(max(mass * 9.81, 2 * 1.0 * reflex.ratio_target))
        assert GraspReflex(hand=hand, min_force=1.0).min_force == 1.0  # switched off: the floor alone


def test_the_ratio_target_stays_below_sliding_friction():
    for mu_s in (0.6, 0.8, 1.2):
        hand = _hand(0.3, mu_s)
        capped = GraspReflex(hand=hand, safety_ratio=0.6, friction_cap=True)
        plain = GraspReflex(hand=hand, safety_ratio=0.6)
        assert capped.ratio_target < hand.params.contact.mu_d  # a sliding contact (at mu_d) asks for more squeeze
        assert capped.ratio_target <= plain.ratio_target
        assert math.isclose(capped.ratio_target, plain.ratio_target) == (0.6 <= 0.9 * hand.params.contact.mu_d)


def test_aiming_at_the_tip_s_own_depth_lifts_a_heavy_object_less_than_aiming_fn_over_k_n_deep():
    """A 0.57 kg object on soft contacts (k x0.6) held by a soft PD (kp x0.5) at the safety
    ratio 0.46: the squeeze grows with the weight, and a PD aimed fn / k_n deep pushes the
    fingers past where they sit; aimed at a multiple of the tip's own depth it does less."""
    from pathlib import Path

    import numpy as np

    import blocks
    from hierhand.tasks.summaries import TaskBlocks
    from hierhand.tasks.variations import Variation, carry

    path = Path(__file__).resolve().parents[3] / "diagrams" / "manipulate.yaml"
    heavy = Variation(mass=0.57, size=(1.0, 1.0), links=(1.0,) * 9, mu_s=1.0, stiffness=0.6, damping=1.0, ki=1.0,
                      safety_ratio=0.46, kp=0.5, kd=1.0, S_a=1.0, S_b=1.0, push=(0.0, -2.0))
    diagram = blocks.load_diagram(path)
    roles = TaskBlocks.of_diagram(diagram)
    lifts = {}
    for aim in (3.0, None):
        overrides = carry(diagram.parameters(), heavy, True, roles)
        overrides[roles.resolve("manip.contact_aim")] = aim
        t, obj = blocks.simulate(blocks.load_diagram(path, overrides=overrides), t_end=0.3)["plant.obj"]
        lifts[aim] = obj[-1, 1] - obj[0, 1]
    assert lifts[3.0] < 0.6 * lifts[None]


def test_catching_up_on_a_shortfall_holds_a_light_object_that_a_sudden_push_takes_out_of_integral_control():
    """0.16 kg on slippery contacts (mu_s 0.63), a slow reflex (ki x0.5) and a soft PD (kp x0.5),
    pushed down by 4 N: the integral loop alone builds the squeeze too late."""
    from pathlib import Path

    from hierhand.tasks.robustness import TASKS, judge
    from hierhand.tasks.variations import Variation

    light = Variation(mass=0.158, size=(0.89, 1.0), links=(1.0,) * 9, mu_s=0.63, stiffness=0.89, damping=1.23,
                      ki=0.49, safety_ratio=0.70, kp=0.53, kd=1.06, S_a=0.8, S_b=1.23, push=(0.81, -3.96),
                      torque=0.0175)
    diagrams = Path(__file__).resolve().parents[3] / "diagrams"
    grasp = (TASKS[0],)
    assert judge(light, diagrams, tasks=grasp)["grasp"] == ""
    assert judge(light, diagrams, {"grasp": {"reflex.catch_up": 0.0}}, tasks=grasp)["grasp"] == "dropped"
