"""Random diagrams of library blocks run the same compiled and in Python.

The diagrams of the loader's fuzz test (``wired_document``: random topology, rates,
offsets, delays with initial values, decimated logs, loops) that load and plan are run
twice: with the library's kernels, and with the compiled side switched off. Both give
the same status, the same sample times and the same values (to round-off: a matrix
Gain or state-space block's products are summed in another order in C).
"""

from __future__ import annotations

import numpy as np
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

import blocks
import blocks.compiled

from .test_diagram_fuzz import FUZZ_SETTINGS, short_t_end, wired_document


def run(diagram, t_end, compiled: bool, monkeypatch):
    with monkeypatch.context() as m:
        if not compiled:
            m.setattr(blocks.compiled, "NativeRunner", None)
        return blocks.simulate(diagram, t_end=t_end)


@settings(max_examples=500, **FUZZ_SETTINGS)
@given(doc=wired_document(), ticks=st.integers(min_value=1, max_value=60))
def test_random_diagrams_give_the_same_results_compiled_and_in_python(doc, ticks, tmp_path, monkeypatch):
    text = yaml.safe_dump(doc, sort_keys=False)
    try:
        diagram = blocks.loads_diagram(text, filename="random.yaml", base_dir=tmp_path)
    except blocks.DiagramError:
        return
    t_end = short_t_end(diagram, ticks)
    if t_end is None:
        return
    try:
        compiled = run(diagram, t_end, True, monkeypatch)
    except blocks.DiagramError:
        return
    python = run(diagram, t_end, False, monkeypatch)
    assert compiled.status == python.status
    assert set(compiled) == set(python)
    for name in compiled:
        (tc, vc), (tp, vp) = compiled[name], python[name]
        assert np.array_equal(tc, tp), name
        scale = max(1.0, float(np.max(np.abs(vp), initial=0.0)))
        np.testing.assert_allclose(vc, vp, rtol=1e-12, atol=1e-12 * scale, err_msg=name)
