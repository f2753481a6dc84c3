"""No silent NaN: the first output value that is not finite fails the run, in both engines,
naming block, port, element and time; what came before is kept; an option lets it go on."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import blocks
from blocks import Block, loads_diagram, simulate
from blocks.cli import PROGRAM
from blocks.cli.program import main
from blocks.engine.finite import NonFiniteOutput

REPO = Path(__file__).resolve().parents[3]
TOY = REPO / "diagrams" / "toy.yaml"
DEFS = "python:tests.blocks.engine.test_finite"
ENGINES = ("native", "reference")


class Blowup(Block):
    """y = [1, t, 2]; from ``t_bad`` on, element ``bad`` is ``value``. Elements named x, y, z
    when ``named``; ``fast`` gives it an advance of its own (a closed form)."""

    def __init__(self, t_bad: float = 0.5, bad: int = 1, value: float = math.nan, named: bool = True):
        self.t_bad, self.bad, self.value, self.named = t_bad, bad, value, named
        self.inputs, self.outputs = {}, {"y": 3}
        self.feedthrough = False

    def element_labels(self, port):
        return ["x", "y", "z"] if self.named else None

    def initial_state(self):
        return np.zeros(1)

    def output(self, t, state, inputs):
        y = np.array([1.0, t, 2.0])
        if t >= self.t_bad - 1e-12:
            y[self.bad] = self.value
        return {"y": y}

    def update(self, t, state, inputs):
        return state + 1.0


class FastBlowup(Blowup):
    """The same outputs, n hits at a time."""

    def advance(self, t, state, inputs, n):
        times = t + float(self.period) * np.arange(1, n + 1)
        rows = np.stack([self.output(s, state, inputs)["y"] for s in times])
        return state + n, {"y": rows}


def diagram(kind: str = "Blowup", log: str = "src.y, gain.y", **params) -> blocks.Diagram:
    text = f"""
name: blowup
time: {{t_end: 1 s}}
blocks:
  src: {{type: "{DEFS}:{kind}", period: 0.1 s, params: {params!r}}}
  gain: {{type: Gain, params: {{k: 2.0}}}}
connections:
  - src.y -> gain.u
log: [{log}]
"""
    return loads_diagram(text.replace("'", '"'), filename="blowup.yaml", trust=True)


def both(d: blocks.Diagram, **options) -> list[blocks.Results]:
    runs = [simulate(d, engine=engine, **options) for engine in ENGINES]
    for name in runs[0]:
        for other in runs[1:]:
            np.testing.assert_array_equal(runs[0][name][0], other[name][0])
            np.testing.assert_array_equal(runs[0][name][1], other[name][1])
    assert len({r.status for r in runs}) == 1, [r.status for r in runs]
    return runs


def test_the_toy_that_diverges_fails_where_its_output_overflows():
    """plant.A = 10: x grows tenfold per 0.1 ms until it overflows; the run fails at the
    first infinite output, the finite rows before it kept."""
    d = blocks.load_diagram(TOY, overrides={"plant.A": [[10.0]]})
    for r in both(d):
        assert not r.complete
        t, y = r["plant.y"]
        assert np.all(np.isfinite(y)) and abs(y[-1, 0]) > np.finfo(float).max / 20
        t_fail = round(t[-1] + 1e-4, 10)
        assert r.status.startswith(f"failed at t={t_fail:.9g} s: block 'plant' (DiscreteStateSpace), signal "
                                   "plant.y advance: y[0] = inf is not finite"), r.status
        assert r.info["t_stop"] == pytest.approx(t_fail)


def test_a_python_blocks_nan_names_its_element_by_label_and_time():
    for r in both(diagram()):
        assert r.status.startswith("failed at t=0.5 s: block 'src' (Blowup), signal src.y output: "
                                   "y[y] (element 1) = nan is not finite"), r.status
        t, y = r["src.y"]
        assert t[-1] == pytest.approx(0.4) and np.all(np.isfinite(y))
        assert r["gain.y"][0][-1] == pytest.approx(0.4)


def test_an_advance_stops_at_the_row_that_is_not_finite():
    d = diagram("FastBlowup", log="src.y", t_bad=0.7, bad=2, value=-math.inf, named=False)
    assert blocks.build_schedule(d, d.t_end).advanced == {"src"}
    for r in both(d):
        assert r.status.startswith("failed at t=0.7 s: block 'src' (FastBlowup), signal src.y advance: "
                                   "y[2] = -inf is not finite"), r.status
        assert r["src.y"][0][-1] == pytest.approx(0.6)
        np.testing.assert_allclose(r["src.y"][1][-1], [1.0, 0.6, 2.0])


def test_a_library_kernels_infinity_fails_at_t_0(tmp_path):
    text = """
name: log0
time: {t_end: 10 ms}
blocks:
  zero: {type: Constant, params: {value: 0.0}}
  log:  {type: Math, params: {function: log}}
connections: [zero.y -> log.u]
log: [log.y]
"""
    for r in both(loads_diagram(text, filename="log0.yaml")):
        assert r.status.startswith("failed at t=0 s: block 'log' (Math), signal log.y output: y[0] = -inf"), r.status


def test_the_check_turned_off_lets_the_values_through():
    for r in both(diagram(), check_finite=False):
        assert r.complete
        assert np.isnan(r["src.y"][1][-1, 1]) and np.isnan(r["gain.y"][1][-1, 1])


def test_raise_on_failure_carries_the_error_with_port_and_element():
    with pytest.raises(blocks.SimulationError) as caught:
        simulate(diagram(), raise_on_failure=True)
    assert caught.value.block == "src" and caught.value.port == "y" and caught.value.time == pytest.approx(0.5)


def test_the_error_names_port_element_label_and_value():
    e = NonFiniteOutput("q", 4, "fore.1", math.nan)
    assert (e.port, e.element, e.label) == ("q", 4, "fore.1") and math.isnan(e.value)
    assert str(e).startswith("q[fore.1] (element 4) = nan is not finite (hint: ")


def test_the_command_exits_1_and_saves_the_run_marked_incomplete(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(PROGRAM, ["run", str(TOY), "--set", "plant.A=[[10.0]]", "-o", str(out), "-q"]) == 1
    err = capsys.readouterr().err
    assert "block 'plant' (DiscreteStateSpace), signal plant.y advance: y[0] = inf is not finite" in err
    assert "partial results (marked incomplete)" in err
    info = json.loads((out / "run.json").read_text())
    assert info["status"].startswith("failed at t=") and info["t_stop"] == pytest.approx(0.0313)
    saved = blocks.Results.load(out)
    assert len(saved["plant.y"][0]) == 313
    assert main(PROGRAM, ["run", str(TOY), "--set", "plant.A=[[10.0]]", "-o", str(out), "-q",
                          "--allow-nonfinite"]) == 0
    assert json.loads((out / "run.json").read_text())["status"] == "complete"
