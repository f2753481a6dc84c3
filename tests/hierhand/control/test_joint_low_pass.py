"""JointLowPass, the small compiled block of the tutorial (docs/tutorials/c-kernel-block.md):
its step response is the closed form ``1 - a^k`` whichever way it runs (the C core, the
Python loop, an exported FMU), and its registration, record and checks are the C's."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, simulate_fmu

import blocks
from blocks.registry import resolve_type
from hierhand.control.joint_low_pass import JointLowPass
from hierhand.fmu_export import export_diagram_fmu

PERIOD = 1e-3
TIME_CONSTANT = 0.02
STEPS = 60

DIAGRAM = f"""\
name: low-pass-step
description: a unit step on every joint through the joint low-pass filter
time: {{t_end: {STEPS} ms}}
blocks:
  step: {{type: Constant, params: {{value: [1, 1, 1, 1, 1, 1, 1, 1, 1]}}}}
  filter: {{type: JointLowPass, period: 1 ms, params: {{time_constant: {TIME_CONSTANT}}}}}
connections:
  - step.y -> filter.u
outputs: {{y: filter.y}}
log: [filter.y]
"""


@pytest.fixture(scope="module")
def diagram_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("low_pass") / "low_pass.yaml"
    path.write_text(DIAGRAM, encoding="utf-8")
    return path


def closed_form(k: np.ndarray) -> np.ndarray:
    """The step response y_k = 1 - a^k, a = exp(-T / time_constant), on all nine joints."""
    a = math.exp(-PERIOD / TIME_CONSTANT)
    return np.repeat((1.0 - a ** k)[:, None], 9, axis=1)


@pytest.mark.parametrize("engine", ["native", "reference"])
def test_the_step_response_is_the_closed_form(diagram_file, engine):
    results = blocks.simulate(blocks.load_diagram(diagram_file), engine=engine)
    t, y = results["filter.y"]
    k = np.arange(STEPS + 1)
    np.testing.assert_allclose(t, k * PERIOD, rtol=0, atol=1e-15)
    np.testing.assert_allclose(y, closed_form(k), rtol=0, atol=1e-14)
    assert y[0].tolist() == [0.0] * 9 and 0.63 < y[20][0] < 0.64  # one time constant: 1 - 1/e


def test_the_c_core_and_the_python_methods_give_the_same_bits(diagram_file):
    native = blocks.simulate(blocks.load_diagram(diagram_file), engine="native")["filter.y"][1]
    reference = blocks.simulate(blocks.load_diagram(diagram_file), engine="reference")["filter.y"][1]
    np.testing.assert_array_equal(native, reference)


@pytest.mark.parametrize("fmi", [2, 3])
def test_an_exported_fmu_gives_the_native_bits_and_tunes_the_time_constant(diagram_file, fmi, tmp_path):
    diagram = blocks.load_diagram(diagram_file)
    native = blocks.simulate(diagram)["filter.y"][1]
    folder = extract(str(export_diagram_fmu(diagram, tmp_path / f"low_pass{fmi}.fmu", fmi)), tmp_path / "fmu")
    columns = [f"y[{i}]" for i in range(1, 10)]
    result = simulate_fmu(folder, output_interval=PERIOD, output=columns)
    np.testing.assert_array_equal(np.column_stack([result[c] for c in columns]), native)
    slower = simulate_fmu(folder, output_interval=PERIOD, output=columns,
                          start_values={"filter.time_constant": 2 * TIME_CONSTANT})
    a = math.exp(-PERIOD / (2 * TIME_CONSTANT))
    np.testing.assert_allclose(slower["y[1]"], 1.0 - a ** np.arange(STEPS + 1), rtol=0, atol=1e-14)


def test_it_is_a_registered_block_type_with_its_c_kernel():
    assert resolve_type("JointLowPass") is JointLowPass
    block = JointLowPass(time_constant=0.05)
    assert block.kernel() is None  # no period yet
    block.bind(PERIOD)
    kernel = block.kernel()
    assert kernel.output and kernel.update and kernel.nogil
    assert kernel.record.values.tolist() == [0.05, PERIOD]


@pytest.mark.parametrize("value, message", [
    (0.0, "parameter 'time_constant' must be a time > 0 in seconds, got 0.0"),
    (-1, "parameter 'time_constant' must be a time > 0 in seconds, got -1.0"),
    (float("inf"), "parameter 'time_constant' must be a time > 0 in seconds, got inf"),
    ("fast", "parameter 'time_constant' must be a time > 0 in seconds, got 'fast'"),
])
def test_a_bad_time_constant_is_refused_in_one_line(value, message):
    with pytest.raises(ValueError) as caught:
        JointLowPass(time_constant=value)
    assert str(caught.value) == message


def test_it_needs_a_period():
    with pytest.raises(ValueError, match="JointLowPass needs an explicit period"):
        JointLowPass().bind(None)
