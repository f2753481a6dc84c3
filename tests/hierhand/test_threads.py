"""The hand's diagrams run in several threads at once, each as it runs alone.

The hand's kernels run with the GIL released (``nogil``); the plant's scratch is its run's
own (``HandPlant.kernel``'s bind builds a context per run), and the controllers only
read their contexts. So runs in two threads at once must give every logged sample and
time of a serial run, bit for bit: two equal hands (diagrams/regrasp.yaml twice), one
diagram object simulated in both threads, two different hands (one with a heavier
object), and the plant as an FMU (diagrams/regrasp_fmu.yaml, whose kernel keeps the GIL
since it calls back into Python). Equality is asserted here, never timing.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import blocks
from hierhand import _native

ROOT = Path(__file__).resolve().parents[2]
REGRASP = ROOT / "diagrams" / "regrasp.yaml"
REGRASP_FMU = ROOT / "diagrams" / "regrasp_fmu.yaml"
HEAVIER = {"plant.object.mass": 0.33}
ROUNDS = 5


def assert_same(a, b) -> None:
    assert a.complete and b.complete, (a.status, b.status)
    assert list(a) == list(b)
    for name in a:
        assert np.array_equal(a[name][0], b[name][0]) and np.array_equal(a[name][1], b[name][1]), name


def run(path: Path, overrides=None) -> blocks.Results:
    return blocks.simulate(blocks.load_diagram(path, overrides=overrides))


def in_threads_as_serial(jobs, serial) -> None:
    """Each of ``jobs`` (callables) in a thread of its own, all at once, ROUNDS times: job i
    gives ``serial[i]``'s samples every time."""
    with ThreadPoolExecutor(len(jobs)) as pool:
        for _ in range(ROUNDS):
            futures = [pool.submit(job) for job in jobs]
            for future, expected in zip(futures, serial):
                assert_same(future.result(), expected)


def test_two_equal_hands_at_once_give_the_serial_samples():
    serial = run(REGRASP)
    in_threads_as_serial([lambda: run(REGRASP)] * 2, [serial] * 2)


def test_one_diagram_simulated_in_two_threads_at_once_gives_the_serial_samples():
    """Both runs step the one plant block's model, each with its own scratch."""
    d = blocks.load_diagram(REGRASP)
    serial = blocks.simulate(d)
    in_threads_as_serial([lambda: blocks.simulate(d)] * 2, [serial] * 2)


def test_two_different_hands_at_once_give_their_serial_samples():
    serial = [run(REGRASP), run(REGRASP, HEAVIER)]
    assert not np.array_equal(serial[0]["plant.obj"][1], serial[1]["plant.obj"][1])
    in_threads_as_serial([lambda: run(REGRASP), lambda: run(REGRASP, HEAVIER)], serial)


def test_the_fmu_plant_in_two_threads_at_once_gives_the_serial_samples(tmp_path):
    pytest.importorskip("fmpy")
    from hierhand.fmu_export import export_plant_fmu

    exported = {"plant.path": str(export_plant_fmu(tmp_path / "plant.fmu", fmi=2))}  # a clone has no fmu/
    serial = run(REGRASP_FMU, exported)
    in_threads_as_serial([lambda: run(REGRASP_FMU, exported)] * 2, [serial] * 2)


def test_a_run_steps_with_a_scratch_of_its_own():
    d = blocks.load_diagram(REGRASP)
    plant = d.blocks["plant"].block
    kernel = plant.kernel()
    assert kernel.nogil and kernel.bind is not None
    first, second = (kernel.bind(plant.initial_state()) for _ in range(2))
    assert first.nogil and first.context and second.context and first.context != second.context
    assert isinstance(first.owners[0], _native.Context)
    rec = plant.kernel_record()
    unbound = rec.values.copy()
    unbound[0] = 0.0
    with pytest.raises(ValueError, match="needs a positive period"):
        _native.Context(rec.kind, unbound)
