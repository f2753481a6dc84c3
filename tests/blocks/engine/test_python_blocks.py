"""Python blocks as ops of the table (blocks/engine/python_blocks.py, and its fast twin in
blocks/csrc/native_python_blocks.c): what a block gets and what it may return, the same in both engines.

- An input array a block keeps is never changed afterwards: a changed value comes in a
  new array (the C host overwrites one in place only when nobody else holds it).
- Outputs may be any float64 arrays of the port's shape (views with strides, read-only
  or broadcast ones) and are checked at every call: one that goes bad later fails the run
  there, with the message of the first call's check.
"""

from __future__ import annotations

import numpy as np
import pytest

from blocks import Block, loads_diagram, simulate
from blocks.registry import block_types


class Ramp2(Block):
    """y = [t, 2t] at odd milliseconds, as a strided view of a larger array; [t, t] at even
    ones, as a read-only broadcast of one value; float32 from ``bad_at`` on."""

    type_name = "TestRamp2"
    time_varying = True

    def __init__(self, bad_at=None):
        self.bad_at = bad_at
        self.outputs = {"y": 2}

    def output(self, t, state, inputs):
        if self.bad_at is not None and t >= self.bad_at:
            return {"y": np.array([t, 2 * t], dtype=np.float32)}
        if round(t * 1000) % 2:
            return {"y": np.array([t, 0.0, 2 * t, 0.0])[::2]}
        return {"y": np.broadcast_to(np.array([t]), (2,))}


class Keeper(Block):
    """Keeps every input array it is given (in its state): ``kept`` is the sum of what those
    arrays hold now, ``given`` the sum of what they held when given, added up in the same
    order; the two are equal to the bit unless a kept array was changed."""

    type_name = "TestKeeper"

    def __init__(self):
        self.inputs, self.outputs, self.feedthrough = {"u": 2}, {"kept": 1, "given": 1}, False

    def initial_state(self):
        return [[], 0.0]

    def output(self, t, state, inputs):
        kept, given = state
        total = 0.0
        for a in kept:
            total += float(a.sum())
        return {"kept": np.array([total]), "given": np.array([given])}

    def update(self, t, state, inputs):
        kept, given = state
        return [kept + [inputs["u"]], given + float(inputs["u"].sum())]


@pytest.fixture(autouse=True)
def registered(monkeypatch):
    for cls in (Ramp2, Keeper):
        monkeypatch.setitem(block_types(), cls.type_name, cls)


TEXT = """
time: {t_end: 6 ms}
blocks:
  r: {type: TestRamp2, period: 1 ms, params: {bad_at: %s}}
  k: {type: TestKeeper, period: 1 ms}
connections: [r.y -> k.u]
log: [r.y, k.kept, k.given]
"""


@pytest.mark.parametrize("engine", ["native", "reference"])
def test_kept_inputs_keep_their_values_and_any_float64_output_array_is_taken(engine):
    r = simulate(loads_diagram(TEXT % "null", filename="keep.yaml"), engine=engine)
    assert r.complete, r.status
    t, y = r["r.y"]
    odd = np.round(t * 1000) % 2 == 1
    np.testing.assert_array_equal(y, np.stack([t, np.where(odd, 2 * t, t)], axis=1))
    (t_k, kept), (_, given) = r["k.kept"], r["k.given"]
    assert len(t_k) == 7 and given[-1, 0] > 0.02
    np.testing.assert_array_equal(kept, given)


@pytest.mark.parametrize("engine", ["native", "reference"])
def test_an_output_that_goes_bad_after_good_ones_fails_the_run_there(engine):
    r = simulate(loads_diagram(TEXT % 0.003, filename="bad.yaml"), engine=engine)
    assert r.status == ("failed at t=0.003 s: block 'r' (TestRamp2), signal r.y output: output 'y' must be a "
                        "float64 array of shape (2,), got shape (2,) float32"), r.status
    np.testing.assert_array_equal(r["r.y"][0], [0.0, 0.001, 0.002])
