"""Stop ends a run through EndRun when its input turns non-zero: the run is complete, ends at
the block's next hit as the README's EndRun says, and run.json's ended_by names it; the
compiled and the Python executor end it alike."""

from __future__ import annotations

import numpy as np
import pytest

import blocks
from blocks.library import Stop

DIAGRAM = """
name: stop-at-threshold
time: {t_end: 1 s}
blocks:
  ramp:  {type: Ramp, period: 1 ms, params: {slope: [1.0, 2.0]}}
  over:  {type: Compare, params: {op: ">=", constant: [0.5, 0.3]}}
  stop:  {type: Stop}
connections: [ramp.y -> over.u, over.y -> stop.u]
log: [ramp.y]
"""


@pytest.mark.parametrize("compiled", [True, False])
def test_stop_ends_the_run_at_its_next_hit(compiled, monkeypatch):
    if not compiled:
        monkeypatch.setattr(blocks.engine.compiled, "usable_kernel", lambda *args: None)
    results = blocks.simulate(blocks.loads_diagram(DIAGRAM))
    assert results.complete
    ended = results.ended_by
    # element 1 reaches 0.3 at t = 0.15 s; the run ends at the block's next hit
    assert ended["block"] == "stop" and ended["type"] == "Stop" and ended["reason"] == "input element 1 is non-zero"
    assert ended["tick_time"] == pytest.approx(0.15) and ended["time"] == pytest.approx(0.151)
    t, y = results["ramp.y"]
    assert t[-1] == pytest.approx(0.151) and np.allclose(y[-1], [0.151, 0.302])


def test_a_scalar_input_says_input():
    assert Stop().inputs == {"u": None} and Stop().outputs == {}
    block = Stop()
    block.set_width(1)
    assert block.end_reason(0) == "input is non-zero"


def test_nan_counts_as_non_zero():
    block = Stop()
    block.set_width(2)
    block.bind(None)
    with pytest.raises(blocks.EndRun, match="element 0"):
        block.update(0.0, block.initial_state(), {"u": np.array([np.nan, 0.0])})
    state = block.initial_state()
    assert block.update(0.0, state, {"u": np.zeros(2)})[0] == 0.0
