"""The C core against the numba kernels it replaces, over the shipped tasks."""

from pathlib import Path

import numpy as np
import pytest

import blocks

DIAGRAMS = Path(__file__).resolve().parents[3] / "diagrams"


@pytest.mark.parametrize("task", ["regrasp", "regrasp_unsuppressed", "grasp", "manipulate"])
def test_c_core_equals_the_numba_kernels_over_a_shipped_task(task):
    REGRASP = DIAGRAMS / f"{task}.yaml"
    text = REGRASP.read_text()
    assert "type: HandPlant," in text
    numba_text = text.replace("type: HandPlant,", "type: 'python:tests.hierhand.model.numba_plant:NumbaHandPlant',")
    native = blocks.simulate(blocks.loads_diagram(text, str(REGRASP), REGRASP.parent))
    numba = blocks.simulate(blocks.loads_diagram(numba_text, str(REGRASP), REGRASP.parent, trust=True))
    assert native.complete and numba.complete
    for signal in ("plant.q", "plant.obj", "plant.fn"):
        t_c, c = native[signal]
        t_n, n = numba[signal]
        np.testing.assert_array_equal(t_c, t_n)
        relative = np.abs(c - n) / np.maximum(np.abs(n), 1e-300)
        assert relative.max() <= 1e-12, (signal, relative.max())
        print(task, signal, "max |C - numba|", np.abs(c - n).max(), "max relative", relative.max())
