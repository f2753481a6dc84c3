"""The HandPlant block contract: ports, state, advance == update/output, errors."""

import re
from fractions import Fraction

import numpy as np
import pytest

from blocks.block import Block, BlockError
from hierhand.model import HandPlant

from .sim import DT, make_plant, pinch_torques


def test_ports_and_flags():
    plant = HandPlant()
    assert isinstance(plant, Block)
    assert plant.registered_name() == "HandPlant"
    assert plant.inputs == {"tau": 9, "f_ext": 3}
    assert plant.outputs == {
        "q": 9, "qd": 9, "tip": 9, "fn": 3, "ft": 3, "ratio": 3, "contact": 3, "obj": 3, "obj_vel": 3,
        "normal": 6,
    }
    assert np.array_equal(plant.input_defaults["f_ext"], np.zeros(3))
    assert plant.feedthrough is False and not plant.has_feedthrough()
    assert plant.has_fast_advance()
    assert set(HandPlant.parameters()) == {"gravity", "fingers", "object", "contact"}


def test_bind_needs_an_explicit_period():
    plant = HandPlant()
    with pytest.raises(ValueError, match="explicit period"):
        plant.bind(None)
    plant.bind(Fraction(1, 10000))
    assert plant.dt == 1e-4 and isinstance(plant.dt, float)


def test_initial_outputs_describe_the_initial_configuration():
    plant = make_plant()
    hand = plant.hand
    state = plant.initial_state()
    assert state.dtype == np.float64 and state.ndim == 1
    out = plant.output(0.0, state, {"tau": np.zeros(9)})
    assert np.array_equal(out["q"], hand.q0)
    assert np.array_equal(out["obj"], [0.0, 0.05, 0.0])
    assert np.allclose(out["tip"].reshape(3, 3), hand.tip_poses(hand.q0))
    assert out["contact"].tolist() == [0.0, 0.0, 0.0]


def test_outputs_are_fresh_arrays():
    plant = make_plant()
    state = plant.initial_state()
    inputs = {"tau": pinch_torques(plant.hand, 2.0, 1.0)}
    out = plant.output(0.0, state, inputs)
    before = {k: v.copy() for k, v in out.items()}
    out["q"][:] = 99.0
    out["obj"][:] = 99.0
    assert np.array_equal(plant.views(state).q, plant.hand.q0)
    state = plant.update(0.0, state, inputs)
    state, rows = plant.advance(DT, state, inputs, 5)
    out2 = plant.output(6 * DT, state, inputs)
    for k in before:
        if k not in ("q", "obj"):
            assert np.array_equal(out[k], before[k])
    rows_copy = {k: v.copy() for k, v in rows.items()}
    plant.advance(6 * DT, state, inputs, 5)
    assert all(np.array_equal(rows[k], rows_copy[k]) for k in rows)
    assert not np.shares_memory(out2["q"], state)


def test_unconnected_f_ext_is_zero():
    plant = make_plant()
    tau = pinch_torques(plant.hand, 2.0, 1.0)
    a, ra = plant.advance(0.0, plant.initial_state(), {"tau": tau}, 50)
    b, rb = plant.advance(0.0, plant.initial_state(), {"tau": tau, "f_ext": np.zeros(3)}, 50)
    assert np.array_equal(a, b)


def test_advance_equals_update_then_output_exactly():
    """Through contact onset, sticking and sliding (a squeeze too weak for the weight)."""
    plant = make_plant()
    hand = plant.hand
    mg2 = hand.params.object.mass * 9.81 / 2
    inputs_at = lambda k: {  # noqa: E731 - inputs change every 1 ms, as the reflex would
        "tau": pinch_torques(hand, 1.2 + 0.1 * k, mg2),
        "f_ext": np.array([0.02 * k, 0.0, 1e-4]),
    }
    fast = plant.initial_state()
    slow = fast.copy()
    fast_rows, slow_rows = [], []
    t = 0.0
    for k, n in enumerate([1, 10, 7, 10, 500, 10, 1000, 3]):
        inputs = inputs_at(k)
        fast, rows = plant.advance(t, fast, inputs, n)
        fast_rows.append(rows)
        for i in range(n):
            slow = plant.update(t + i * DT, slow, inputs)
            slow_rows.append(plant.output(t + (i + 1) * DT, slow, inputs))
        t += n * DT
    assert np.array_equal(fast, slow)
    for port in plant.outputs:
        a = np.concatenate([r[port] for r in fast_rows])
        b = np.array([r[port] for r in slow_rows])
        assert a.shape == b.shape == (1541, plant.outputs[port])
        assert np.array_equal(a, b), port
    contact = np.concatenate([r["contact"] for r in fast_rows])
    ratio = np.concatenate([r["ratio"] for r in fast_rows])
    assert contact[:, :2].all(axis=1).sum() > 1000  # the comparison covered real contact
    assert np.isclose(ratio[:, :2], hand.params.contact.mu_d).any()  # and sliding


def test_non_finite_state_names_the_quantity_and_time():
    plant = make_plant()
    state = plant.initial_state()
    plant.views(state).obj_vel[1] = np.nan
    with pytest.raises(BlockError, match=r"at t=0\.25 s: object velocity obj_vel\[1\] \(vy\)") as info:
        plant.update(0.25, state, {"tau": np.zeros(9)})
    assert info.value.port == "obj_vel"
    with pytest.raises(BlockError, match=r"at t=0\.25 s: object velocity obj_vel\[1\]"):
        plant.output(0.25, state, {"tau": np.zeros(9)})


def test_blow_up_in_advance_names_the_joint_and_the_step():
    plant = make_plant()
    tau = np.zeros(9)
    tau[4] = 1e306  # fore joint 2: the first step, the one at t = 0.01 s, overflows
    with pytest.raises(BlockError, match=r"in the step at t=0\.01 s: joint velocity qd\[[345]\] \(fore joint [123]\)") as info:
        plant.advance(0.01, plant.initial_state(), {"tau": tau}, 10)
    assert info.value.port == "qd"


def test_non_finite_input_is_reported_as_the_input():
    plant = make_plant()
    tau = np.zeros(9)
    tau[7] = np.inf
    with pytest.raises(BlockError, match=r"input torque tau\[7\] \(middle joint 2\)") as info:
        plant.advance(0.0, plant.initial_state(), {"tau": tau}, 10)
    assert info.value.port == "tau"


def test_penetration_deeper_than_the_tip_radius_is_an_error():
    """Soft contact and a hard squeeze push the fingertips into the object."""
    plant = make_plant(gravity=[0.0, 0.0], contact={"k_n": 10.0, "c_n": 0.0, "k_t": 10.0, "c_t": 0.0})
    tau = pinch_torques(plant.hand, 3.0, 0.0)
    with pytest.raises(BlockError, match=r"penetration deeper than the fingertip radius in the step at t=0\.\d+ s: the (thumb|fore) tip") as info:
        plant.advance(0.0, plant.initial_state(), {"tau": tau}, 5000)
    assert info.value.port == "contact"
    # the steps completed before the failing one come with the error, for the run's log
    t_fail = float(re.search(r"at t=([0-9.]+) s", str(info.value)).group(1))
    done = round(t_fail / plant.dt)  # rows for the good states up to the failing step's start
    assert 0 < done < 5000
    assert {name: rows.shape for name, rows in info.value.rows.items()} == \
        {name: (done, width) for name, width in plant.outputs.items()}
    assert all(np.isfinite(rows).all() for rows in info.value.rows.values())
    _, stepped = plant.advance(0.0, plant.initial_state(), {"tau": tau}, done)
    for name, rows in stepped.items():
        np.testing.assert_array_equal(info.value.rows[name], rows)


def test_object_placed_inside_a_fingertip_is_rejected_at_output():
    plant = make_plant(object={"pos": [-0.03, 0.05]})
    with pytest.raises(BlockError, match=r"at t=0 s: the thumb tip centre is inside the object"):
        plant.output(0.0, plant.initial_state(), {"tau": np.zeros(9)})


def test_state_of_the_wrong_shape_is_rejected():
    plant = make_plant()
    with pytest.raises(BlockError, match="initial_state"):
        plant.update(0.0, np.zeros(10), {"tau": np.zeros(9)})


def test_block_is_reusable_across_runs():
    plant = make_plant()
    tau = pinch_torques(plant.hand, 2.0, 1.0)
    a, _ = plant.advance(0.0, plant.initial_state(), {"tau": tau}, 200)
    b, _ = plant.advance(0.0, plant.initial_state(), {"tau": tau}, 200)
    assert np.array_equal(a, b)


def test_plant_from_a_loaded_hand_has_the_same_parameters(tmp_path):
    from hierhand.model import load_hand

    hand = load_hand({"object": {"mass": 0.2, "pos": [0.0, 0.07]}, "contact": {"mu_s": 0.8, "mu_d": 0.7}})
    plant = HandPlant.from_hand(hand)
    assert plant.hand.params == hand.params
    assert np.array_equal(plant.hand.body, hand.body)


def test_describe_says_where_the_hand_comes_from():
    assert HandPlant().describe() == "hand: the built-in default hand"
    assert HandPlant(object={"mass": 0.36}, contact={"mu_s": 1.1, "mu_d": 1.0}).describe() == \
        "hand: object, contact from the diagram, the rest from the built-in default hand"
    full = HandPlant().hand.params.to_dict()
    assert HandPlant.from_hand(HandPlant(**full).hand).describe() == "hand: all from the diagram"


def test_a_set_path_into_the_whole_sections_starts_from_the_default_hand():
    from hierhand.model.handfile import default_hand_dict

    assert HandPlant.param_default("fingers") == default_hand_dict()["fingers"]
    assert HandPlant.param_default("gravity") == [0.0, -9.81]
    # merged key by key: a partial object keeps deriving its inertia from its own mass
    assert HandPlant.param_default("object") is None and HandPlant.param_default("contact") is None
    assert HandPlant(object={"mass": 0.6}).hand.params.object.inertia == pytest.approx(0.6 * 0.005 / 12)


BLOW_UP = """\
name: blow-up
time: {t_end: 10 ms}
blocks:
  tau: {type: Step, period: 1 ms, params: {time: 0.002, before: [0, 0, 0, 0, 0, 0, 0, 0, 0],
                                           after: [0, 0, 0, 0, 0, 0, 0, 1.0e150, 0]}}
  plant: {type: HandPlant, period: 0.1 ms}
connections: [tau.y -> plant.tau]
log: [plant.q]
"""


def test_a_blow_up_inside_an_advance_span_is_reported_at_one_time():
    """From 2 ms the huge torque (on the middle finger, away from the object) overflows the
    state in the third step of the span (the
    step at 2.2 ms): the run's status and the plant's message name that one time, and the
    log reaches it."""
    from blocks import loads_diagram, simulate

    results = simulate(loads_diagram(BLOW_UP))
    times = re.findall(r"t=([0-9.e+-]+) s", results.status)
    assert times == ["0.0022", "0.0022"], results.status
    assert "in the step at t=0.0022 s" in results.status
    t, _ = results["plant.q"]
    assert t[-1] == pytest.approx(0.0022)
