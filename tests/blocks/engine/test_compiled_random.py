"""Random diagrams of library blocks run the same compiled and in Python, in either interpreter.

The diagrams of the loader's fuzz test (``wired_document``: random topology, rates,
offsets, delays with initial values, decimated logs, loops) that load and plan are run
three ways: with the library's kernels in the C core, the same in the reference loop,
and with every block through its Python methods, as callback ops of the table (which
call the same kernels). All three give the same status and the same samples to the last
bit: one table, the same kernels, only the executors' own work differs.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import blocks
import blocks.engine.compiled

from ..test_diagram_fuzz import FUZZ_SETTINGS, wired_document
from .test_reference_loop import loaded


def run(diagram, t_end, compiled: bool, monkeypatch, engine: str = "native"):
    with monkeypatch.context() as m:
        if not compiled:
            m.setattr(blocks.engine.compiled, "usable_kernel", lambda *args: None)
        return blocks.simulate(diagram, t_end=t_end, engine=engine)


@settings(max_examples=500, **FUZZ_SETTINGS)
@given(doc=wired_document(), ticks=st.integers(min_value=1, max_value=60))
def test_random_diagrams_give_the_same_results_compiled_and_in_python(doc, ticks, tmp_path, monkeypatch):
    if (found := loaded(doc, ticks, tmp_path)) is None:
        return
    diagram, t_end = found
    try:
        compiled = run(diagram, t_end, True, monkeypatch)
    except blocks.DiagramError:
        return
    reference = run(diagram, t_end, True, monkeypatch, engine="reference")
    assert compiled.status == reference.status and list(compiled) == list(reference)
    for name in compiled:
        assert np.array_equal(compiled[name][0], reference[name][0]), name
        assert np.array_equal(compiled[name][1], reference[name][1]), name
    python = run(diagram, t_end, False, monkeypatch)
    assert compiled.status == python.status and list(compiled) == list(python)
    for name in compiled:
        assert np.array_equal(compiled[name][0], python[name][0]), name
        assert np.array_equal(compiled[name][1], python[name][1]), name
