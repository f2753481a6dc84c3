"""The hierhand blocks' compiled kernels equal their Python methods to the last bit.

The shipped re-grasp diagram is run for 200 ms by a small co-simulation here, through the
blocks' Python methods (closing the loop plant -> reflex, manipulation -> suppresser ->
plant, support -> plant and manipulation); at every hit each block's kernel, called
through ``blocks._native.call``, must give the same outputs, updates and advances, bit
for bit. The 200 ms cover the closing of the grasp, the hand-over at 0.1 s and the
middle finger's approach. Failures give the exceptions the Python methods raise.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import blocks
from blocks import _native as blocks_native
from blocks.block import BlockError
from hierhand import _native
from hierhand.control.inverse_kinematics import UnreachableError
from hierhand.layouts import OUTPUT, PLANT_STATUS

ROOT = Path(__file__).resolve().parents[2]
REGRASP = ROOT / "diagrams" / "regrasp.yaml"
call = blocks_native.call


@pytest.fixture(scope="module")
def diagram():
    return blocks.load_diagram(REGRASP)


def _blocks(diagram):
    return {name: spec.block for name, spec in diagram.blocks.items()}


def _inputs(block, given):
    """The block's inputs in its ``inputs`` order as contiguous float64 arrays (defaults
    where not given), and the same as the mapping the Python methods take."""
    values = {}
    for port in block.inputs:
        value = given.get(port, block.input_defaults.get(port) if block.input_defaults else None)
        values[port] = np.ascontiguousarray(value, dtype=np.float64)
    return [values[port] for port in block.inputs], values


def _row(block, outputs):
    """A block's Python outputs one after the other, in the order of ``outputs``."""
    return np.concatenate([np.asarray(outputs[port], dtype=np.float64).ravel() for port in block.outputs])


def _run_kernel(block):
    """The Kernel a run uses: the block's, bound to a fresh state where it has a bind (the
    plant's, whose run gets a scratch of its own)."""
    kernel = block.kernel()
    return kernel if kernel.bind is None else kernel.bind(block.initial_state())


def _width(block):
    return sum(block.outputs.values())


def _check_output(block, t, state, given):
    """The kernel's output equals ``block.output``; returns the Python outputs."""
    kernel = _run_kernel(block)
    listed, mapping = _inputs(block, given)
    expected = block.output(t, None if state is None else state.copy(), mapping)
    out = np.full(_width(block), np.nan)
    code, which = call("output", kernel.output, kernel.context, t, None if state is None else state.copy(), listed,
                       out)
    assert code == 0
    assert np.array_equal(out, _row(block, expected)), block.type_name
    return expected


def _check_update(block, t, state, given):
    """The kernel's update (in place) equals ``block.update``; returns the new state."""
    kernel = _run_kernel(block)
    listed, mapping = _inputs(block, given)
    expected = np.array(block.update(t, state.copy(), mapping), dtype=np.float64)
    mine = state.copy()
    code, which = call("update", kernel.update, kernel.context, t, mine, listed, None)
    assert code == 0
    assert np.array_equal(mine, expected), block.type_name
    return expected


def test_every_block_of_the_regrasp_diagram_has_a_kernel(diagram):
    b = _blocks(diagram)
    kernels = _native.kernels()
    assert set(kernels) == {"HandPlant.output", "HandPlant.update", "HandPlant.advance", "GraspReflex.output",
                            "GraspReflex.update", "ManipulationPD.output", "Suppresser.output", "Suppresser.update",
                            "ObjectSupport.output", "JointLowPass.output", "JointLowPass.update"}
    assert all(isinstance(a, int) and a != 0 for a in kernels.values())
    plant, reflex = b["plant"].kernel(), b["ctrl.reflex"].kernel()
    assert plant.output and plant.update and plant.advance and plant.bind and plant.nogil
    assert _run_kernel(b["plant"]).context and _run_kernel(b["plant"]).nogil
    assert reflex.output and reflex.update and not reflex.advance and reflex.nogil
    suppress = b["ctrl.suppress"].kernel()  # the shipped suppresser low-passes: it has a state
    assert suppress.output and suppress.update and not suppress.advance and suppress.nogil
    for name in ("ctrl.manip", "support"):
        k = b[name].kernel()
        assert k.output and not k.update and not k.advance and k.context and k.nogil


def test_blocks_not_bound_have_no_kernel():
    from hierhand.control.grasp_reflex import GraspReflex
    from hierhand.model import Hand, HandPlant

    assert HandPlant().kernel() is None
    assert GraspReflex(hand=Hand.default()).kernel() is None


def test_kernels_equal_the_python_methods_along_a_regrasp(diagram):
    b = _blocks(diagram)
    plant, reflex, manip, suppress, support = (b[n] for n in ("plant", "ctrl.reflex", "ctrl.manip", "ctrl.suppress", "support"))
    dt_plant, dt_reflex = float(plant.period), float(reflex.period)
    steps = round(dt_reflex / dt_plant)  # plant steps per reflex hit
    per_manip = round(float(manip.period) / dt_reflex)
    x, s, z = plant.initial_state(), reflex.initial_state(), suppress.initial_state()
    share = np.ones(3)
    checked_update = False
    for k in range(200):  # 200 ms in 1 ms hits
        t = k * dt_reflex
        y = _check_output(plant, t, x, {})
        if k % per_manip == 0:
            f_ext = _check_output(support, t, None, {})["y"]
            m = _check_output(manip, t, None, {"q": y["q"], "qd": y["qd"], "fn": y["fn"], "support": f_ext,
                                               "normal": y["normal"], "obj": y["obj"]})
        reflex_in = {"q": y["q"], "tip": y["tip"], "fn": y["fn"], "ft": y["ft"], "normal": y["normal"],
                     "share": share}
        g = _check_output(reflex, t, s, reflex_in)
        suppress_in = {"tau_g": g["tau_g"], "tau_m": m["tau_m"], "tau_ff": m["tau_ff"]}
        u = _check_output(suppress, t, z, suppress_in)
        s = _check_update(reflex, t, s, reflex_in)
        z = _check_update(suppress, t, z, suppress_in)
        share = u["share"].copy()
        plant_in = {"tau": u["tau"], "f_ext": f_ext}
        if k % 50 == 7:  # one update by itself now and then
            _check_update(plant, t, x, plant_in)
            checked_update = True
        # the plant's stretch to the next reflex hit: Python's advance against the kernel's
        listed, mapping = _inputs(plant, plant_in)
        kernel = _run_kernel(plant)
        rows = np.full((steps, OUTPUT.size), np.nan)
        mine = x.copy()
        code, done, which = call("advance", kernel.advance, kernel.context, t, mine, listed, rows, steps)
        x, out = plant.advance(t, x, mapping, steps)
        assert (code, done) == (0, steps)
        assert np.array_equal(mine, x)
        assert np.array_equal(rows, np.concatenate([out[p] for p in plant.outputs], axis=1))
    assert checked_update
    # the run got somewhere: the object was handed over and is held by the fingers
    assert s[0] > 0 and np.count_nonzero(y["contact"]) >= 2 and not np.any(f_ext)


def test_the_support_switches_off_at_until_in_both(diagram):
    support = _blocks(diagram)["support"]
    for t in (0.0, 0.0999999, support.until, np.nextafter(support.until, 0.0), 0.5, -1.0, np.inf):
        _check_output(support, t, None, {})


def test_the_suppresser_takes_any_torques(diagram):
    from hierhand.control.suppresser import Suppresser

    filtered = _blocks(diagram)["ctrl.suppress"]
    static = Suppresser(S_a=filtered.S_a, S_b=filtered.S_b, mode=filtered.mode)
    rng = np.random.default_rng(5)
    state = rng.normal(scale=0.05, size=9)
    for _ in range(20):
        tau_g, tau_m, tau_ff = rng.normal(scale=0.2, size=(3, 9))
        tau_g[rng.integers(9)] = 0.0
        _check_output(static, 0.0, None, {"tau_g": tau_g, "tau_m": tau_m, "tau_ff": tau_ff})
        _check_output(filtered, 0.0, state, {"tau_g": tau_g, "tau_m": tau_m, "tau_ff": tau_ff})
        state = _check_update(filtered, 0.0, state, {"tau_g": tau_g, "tau_m": tau_m, "tau_ff": tau_ff})
    _check_output(static, 0.0, None, {"tau_g": tau_g, "tau_m": tau_m})  # tau_ff at its default


def _kernel_error(block, code, which, t, phase):
    return _run_kernel(block).error(code, which, t, phase)


def test_a_non_finite_torque_fails_as_the_python_step_does(diagram):
    plant = _blocks(diagram)["plant"]
    kernel = _run_kernel(plant)
    x = plant.initial_state()
    tau = np.zeros(9)
    tau[4] = np.nan
    listed, mapping = _inputs(plant, {"tau": tau})
    for phase in ("update", "advance"):
        with pytest.raises(BlockError) as python:
            if phase == "update":
                plant.update(0.25, x.copy(), mapping)
            else:
                plant.advance(0.25, x.copy(), mapping, 3)
        if phase == "update":
            code, which = call("update", kernel.update, kernel.context, 0.25, x.copy(), listed, None)
            done = 0
        else:
            code, done, which = call("advance", kernel.advance, kernel.context, 0.25, x.copy(), listed,
                                     np.empty((3, OUTPUT.size)), 3)
        assert (code, which, done) == (PLANT_STATUS.ERR_TAU, 4, 0)
        error = kernel.error(code, which, 0.25, phase)
        assert isinstance(error, BlockError)
        assert str(error) == str(python.value) and error.port == python.value.port == "tau"
        assert "in the step at t=0.25 s" in str(error)


def test_a_blow_up_part_way_through_an_advance_keeps_the_rows_before_it(diagram):
    plant = _blocks(diagram)["plant"]
    kernel = _run_kernel(plant)
    x = plant.initial_state()
    tau = np.full(9, 1e150)  # finite, but the state leaves the doubles after a few steps
    listed, mapping = _inputs(plant, {"tau": tau})
    n, t0 = 20, 0.5
    with pytest.raises(BlockError) as python:
        plant.advance(t0, x.copy(), mapping, n)
    rows = np.full((n, OUTPUT.size), np.nan)
    mine = x.copy()
    code, done, which = call("advance", kernel.advance, kernel.context, t0, mine, listed, rows, n)
    assert code != 0 and 0 < done < n
    # the executor's failure time counts the rows completed, as HandPlant.advance does
    error = kernel.error(code, which, t0 + done * plant.dt, "advance")
    assert str(error) == str(python.value)
    expected = python.value.rows
    assert all(len(v) == done for v in expected.values())
    assert np.array_equal(rows[:done], np.concatenate([expected[p] for p in plant.outputs], axis=1))
    # and the state is the one the Python advance left (the bad one after the failing step)
    after = x.copy()
    with pytest.raises(BlockError):
        plant.advance(t0, after, mapping, n)
    assert np.array_equal(mine, after, equal_nan=True)


def test_a_bad_state_fails_in_the_output_as_in_python(diagram):
    plant = _blocks(diagram)["plant"]
    kernel = _run_kernel(plant)
    x = plant.initial_state()
    x[10] = np.inf  # qd[1]
    with pytest.raises(BlockError) as python:
        plant.output(0.125, x, {})
    code, which = call("output", kernel.output, kernel.context, 0.125, x, [np.zeros(9), np.zeros(3)],
                       np.empty(OUTPUT.size))
    assert code != 0
    assert str(kernel.error(code, which, 0.125, "output")) == str(python.value)


def test_coincident_contacts_fail_the_reflex_as_in_python(diagram):
    reflex = _blocks(diagram)["ctrl.reflex"]
    kernel = reflex.kernel()
    state = reflex.initial_state()
    # tip centres placed so that the contact points (centre plus radius along the normal) coincide
    tip = np.tile([0.03, 0.05, 1.0], 3)
    tip[0::3] -= reflex.hand.tip_radius
    given = {"q": np.zeros(9), "tip": tip, "fn": np.array([1.0, 1.0, 0.0]),
             "ft": np.zeros(3), "normal": np.tile([1.0, 0.0], 3)}
    listed, mapping = _inputs(reflex, given)
    for phase in ("output", "update"):
        with pytest.raises(ValueError) as python:
            getattr(reflex, phase)(0.0, state.copy(), mapping)
        mine = state.copy()
        if phase == "output":
            out = np.full(_width(reflex), 7.0)
            code, which = call("output", kernel.output, kernel.context, 0.0, mine, listed, out)
            assert np.all(out == 7.0)  # nothing written on failure
        else:
            code, which = call("update", kernel.update, kernel.context, 0.0, mine, listed, None)
        assert code != 0
        assert np.array_equal(mine, state)  # the state is left as it was
        error = kernel.error(code, which, 0.0, phase)
        assert type(error) is type(python.value) and str(error) == str(python.value)


def test_an_unreachable_target_fails_the_manipulation_as_in_python():
    d = blocks.load_diagram(REGRASP)
    manip = d.blocks["ctrl.manip"].block
    # the middle finger's targets a metre away, in the packed waypoints (which the kernel's
    # record copies) and in the trajectory the Python path names the error from
    manip._waypoints[2, :, 1] += 1.0
    manip.trajectories[2]._w[:, 1] += 1.0
    kernel = manip.kernel()
    given = {"q": manip.hand.q0.copy(), "qd": np.zeros(9), "fn": np.zeros(3), "normal": np.zeros(6),
             "obj": manip.hand.object_pose0}
    listed, mapping = _inputs(manip, given)
    with pytest.raises(UnreachableError) as python:
        manip.output(0.2, None, mapping)
    code, which = call("output", kernel.output, kernel.context, 0.2, None, listed, np.empty(27))
    assert code != 0 and which == 2
    error = kernel.error(code, which, 0.2, "output")
    assert type(error) is type(python.value) and str(error) == str(python.value)
