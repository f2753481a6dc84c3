"""The re-grasp task with the exported hand plant stepping through the FMU block's kernel.

diagrams/regrasp_fmu.yaml runs every block in C once the FMU has a kernel: the plant as
an FMI 2 or FMI 3 FMU at a 1 ms communication step between the compiled controllers. Its
results must be those of the FMU block's Python methods, every logged sample and time to
the last bit, and the C step must have handed nothing to Python but the first outputs
(which initialise the FMU).
"""

from __future__ import annotations

import collections
from pathlib import Path

import numpy as np
import pytest

import blocks
from blocks.fmu import FMU
from blocks.fmu import compiled_step as fmu_kernel
from hierhand.fmu_export import export_plant_fmu

pytest.importorskip("fmpy")

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def plants(tmp_path_factory) -> dict[int, Path]:
    folder = tmp_path_factory.mktemp("plants")
    return {fmi: export_plant_fmu(folder / f"plant{fmi}.fmu", fmi=fmi) for fmi in (2, 3)}


@pytest.mark.skipif(fmu_kernel.native() is None, reason="blocks._native is not built")
@pytest.mark.parametrize("fmi", [2, 3])
def test_regrasp_with_the_fmu_plant_is_bit_identical_through_the_kernel(plants, monkeypatch, fmi):
    d = blocks.load_diagram(ROOT / "diagrams" / "regrasp_fmu.yaml", overrides={"plant.path": str(plants[fmi])})
    with monkeypatch.context() as m:
        m.setattr(FMU, "kernel", lambda self: None)
        python = blocks.simulate(d)
    slow: collections.Counter = collections.Counter()
    call = fmu_kernel.KernelRun.__call__

    def counted(self, kind, t, status):
        slow[kind] += 1
        return call(self, kind, t, status)

    monkeypatch.setattr(fmu_kernel.KernelRun, "__call__", counted)
    compiled = blocks.simulate(d)
    assert compiled.complete and python.complete
    assert slow == {fmu_kernel.native()["kinds"]["output"]: 1}
    assert list(compiled) == list(python) and len(list(compiled)) == len(d.log)
    for name in python:
        t_c, v_c = compiled[name]
        t_p, v_p = python[name]
        assert np.array_equal(t_c, t_p) and np.array_equal(v_c, v_p), name
