"""The reference loop (``engine="reference"``) is the statement of what a run means: the C
core must give the same samples, to the last bit, on any diagram.

Random multirate diagrams of the test blocks (``compiled_blocks.py``: leaky integrators
with kernels and advances, gains, a Python source, a Python block with per-port
feedthrough that may end the run, a compiled block that ends the run from its kernel, a
Python block advanced in closed form that fails part-way) with random periods, offsets,
delays with initial values, decimated logs and end times run three ways: the C core, the
reference loop, and the C core with every block through its Python methods (the test
blocks' twins compute the same arithmetic, so that too is bit-identical). The shipped
diagrams run both ways as well.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import Phase, find, given, settings
from hypothesis import strategies as st

import blocks
import blocks.engine.compiled
from blocks import load_diagram, loads_diagram, simulate

from ..compiled_blocks import register
from ..test_diagram_fuzz import FUZZ_SETTINGS, dump, short_t_end

ROOT = Path(__file__).resolve().parents[3]
PERIODS = ["0.1 ms", "0.2 ms", "0.5 ms", "1 ms", "2 ms"]


@pytest.fixture(autouse=True)
def registered(library, monkeypatch):
    register(library, monkeypatch)


def assert_same(a, b) -> None:
    assert a.status == b.status
    assert a.ended_by == b.ended_by and a.info["t_stop"] == b.info["t_stop"]
    assert list(a) == list(b)
    for name in a:
        (ta, va), (tb, vb) = a[name], b[name]
        assert np.array_equal(ta, tb), name
        assert np.array_equal(va, vb), name


def block_spec(draw, kind: str) -> dict:
    period = draw(st.sampled_from(PERIODS))
    spec: dict = {"type": kind, "period": period}
    if draw(st.integers(0, 4)) == 0 and period in ("1 ms", "2 ms"):
        spec["offset"] = draw(st.sampled_from(["0.1 ms", "0.3 ms", "0.5 ms"]))
    compiled = draw(st.booleans())
    if kind == "TestLeak":
        spec["params"] = {"a": draw(st.sampled_from([0.5, 0.9, 0.99])), "b": draw(st.sampled_from([0.1, 1.0])),
                          "x0": draw(st.sampled_from([0.0, 1.5])), "compiled": compiled,
                          "limit": draw(st.sampled_from([1e9, 1e9, 2.0]))}
    elif kind == "TestScale":
        spec["params"] = {"k": draw(st.sampled_from([-0.5, 0.25, 2.0])), "compiled": compiled}
        if draw(st.booleans()):
            del spec["period"]  # inherited
    elif kind == "TestMix":
        spec["params"] = {"stop_at": draw(st.sampled_from([None, None, 0.004, 0.0077]))}
    elif kind == "TestStopper":
        spec["params"] = {"stop": draw(st.sampled_from([2, 5, 1000])), "compiled": compiled}
    elif kind == "TestCapped":
        spec["params"] = {"limit": draw(st.sampled_from([1e9, 3.0]))}
    return spec


INPUTS = {"TestLeak": ["u"], "TestScale": ["u"], "TestWave": [], "TestMix": ["a", "b"], "TestStopper": ["u"],
          "TestCapped": ["u"]}


@st.composite
def mixed_document(draw) -> dict:
    kinds = draw(st.lists(st.sampled_from(list(INPUTS)), min_size=1, max_size=7))
    names = [f"b{i}" for i in range(len(kinds))]
    specs = {name: block_spec(draw, kind) for name, kind in zip(names, kinds)}
    connections = []
    for name, kind in zip(names, kinds):
        for port in INPUTS[kind]:
            if kind == "TestStopper" and draw(st.booleans()):
                continue  # its input has a default
            source = draw(st.sampled_from(names))
            if draw(st.integers(0, 3)) == 0:
                wire = {"from": f"{source}.y", "to": f"{name}.{port}", "delay": 1}
                if draw(st.booleans()):
                    wire["initial"] = draw(st.sampled_from([0.5, [1.0, -2.0]]))
                connections.append(wire)
            else:
                connections.append(f"{source}.y -> {name}.{port}")
    log = []
    for name, kind in zip(names, kinds):
        ports = ["y", "sum"] if kind == "TestLeak" else ["y"]
        for port in ports:
            if draw(st.integers(0, 3)):
                decimate = draw(st.integers(1, 3))
                log.append(f"{name}.{port}" if decimate == 1 else {"signal": f"{name}.{port}", "decimate": decimate})
    return {"blocks": specs, "connections": connections, "log": log}


def three_ways(diagram, t_end, monkeypatch):
    native = simulate(diagram, t_end=t_end, engine="native")
    reference = simulate(diagram, t_end=t_end, engine="reference")
    with monkeypatch.context() as m:
        m.setattr(blocks.engine.compiled, "usable_kernel", lambda *args: None)
        python = simulate(diagram, t_end=t_end, engine="native")
    return native, reference, python


def loaded(doc: dict, ticks: int, base_dir=None):
    """A random document's diagram and an end time about ``ticks`` base ticks away; None
    if it does not load or plan (a random diagram may well not)."""
    try:
        diagram = loads_diagram(dump(doc), filename="random.yaml", base_dir=base_dir)
    except blocks.DiagramError:
        return None
    t_end = short_t_end(diagram, ticks)
    return None if t_end is None else (diagram, t_end)


@settings(max_examples=300, **FUZZ_SETTINGS)
@given(doc=mixed_document(), ticks=st.integers(min_value=1, max_value=150))
def test_random_mixed_diagrams_give_the_same_samples_in_the_core_and_the_reference_loop(doc, ticks, monkeypatch):
    if (found := loaded(doc, ticks)) is None:
        return
    diagram, t_end = found
    try:
        native, reference, python = three_ways(diagram, t_end, monkeypatch)
    except blocks.DiagramError:
        return
    assert_same(native, reference)
    assert_same(native, python)


def kinds_of_run(example) -> set[str]:
    """What a random diagram's run does: 'ended' early by a block, 'failed' part-way,
    'advanced' a block over spans (nothing, if it does not load)."""
    if (found := loaded(*example)) is None:
        return set()
    diagram, t_end = found
    r = simulate(diagram, t_end=t_end)
    kinds = {"ended"} if r.ended_by else {"failed"} if r.status.startswith("failed") else set()
    return kinds | ({"advanced"} if blocks.build_schedule(diagram, t_end).advanced else set())


@pytest.mark.parametrize("kind", ["ended", "failed", "advanced"])
def test_the_random_diagrams_include_runs_that_end_early_fail_and_advance(kind):
    """The comparison above is only as good as its diagrams: they must end runs early,
    fail part-way and advance blocks over spans."""
    find(st.tuples(mixed_document(), st.integers(min_value=1, max_value=150)), lambda ex: kind in kinds_of_run(ex),
         settings=settings(max_examples=2000, database=None, phases=[Phase.generate]))


RUNNABLE = sorted(p.stem for p in (ROOT / "diagrams").glob("*.yaml")
                  if "inputs" not in yaml.safe_load(p.read_text(encoding="utf-8")))
"""The shipped diagrams that run by themselves (not the subsystems the others include)."""


@pytest.mark.parametrize("name", RUNNABLE)
def test_the_shipped_diagrams_give_the_same_samples_both_ways(name):
    path = ROOT / "diagrams" / f"{name}.yaml"
    if name == "regrasp_fmu" and not (ROOT / "fmu" / "HandPlant_fmi2.fmu").is_file():
        pytest.skip("no exported FMU (hierhand fmu export)")
    diagram = load_diagram(path)
    assert_same(simulate(diagram, engine="native"), simulate(diagram, engine="reference"))


UNCOMPILED = """
time: {t_end: 20 ms}
blocks:
  wave: {type: TestWave, period: 1 ms}
  leak: {type: TestLeak, period: 2 ms, params: {a: 0.9, b: 0.5}}
connections: [wave.y -> leak.u]
log: [leak.y, leak.sum]
"""


def test_without_the_compiled_extension_python_blocks_run_in_the_reference_loop(monkeypatch):
    """An uncompiled checkout: no kernel can be called and the C core is not there, so the
    reference loop runs every block through its Python methods (the test blocks' give their
    kernels' samples); a library block, defined by its C kernel alone, says at its first hit
    that it needs the extension; asking for the C core says what is missing."""
    diagram = loads_diagram(UNCOMPILED, filename="uncompiled.yaml")
    toy = load_diagram(ROOT / "diagrams" / "toy.yaml")
    compiled = simulate(diagram)
    with monkeypatch.context() as m:
        m.setattr(blocks.engine.compiled, "native", lambda: None)
        python = simulate(diagram)
        library = simulate(toy)
        with pytest.raises(ValueError, match="engine 'native' needs the compiled extension blocks._native"):
            simulate(diagram, engine="native")
    assert python.complete and python.info["t_stop"] is None
    assert_same(python, compiled)
    assert library.status.startswith("failed at t=0 s")
    assert "runs its compiled kernel, and the extension blocks._native is missing" in library.status


def test_a_run_whose_tick_times_are_not_exact_in_double_runs_in_the_reference_loop():
    """7.000000000001 s is 7000000000001 / 10^12 s: at tick 2000, k * num passes 2^53, so
    the C core's double arithmetic could round a tick time where the integers do not; such
    a run goes to the reference loop, and the Step switches at its exact time."""
    diagram = loads_diagram("""
time: {t_end: 14000.000000002 s}
blocks:
  c: {type: Step, period: 7.000000000001 s, params: {time: 7000.000000001}}
log: [c.y]
""", filename="long.yaml")
    r = simulate(diagram)
    t, y = r["c.y"]
    assert r.complete and len(t) == 2001 and t[-1] == 14000.000000002
    assert y[1000, 0] == 1.0 and y[999, 0] == 0.0
    with pytest.raises(ValueError, match="not exact in double, so only engine 'reference' runs it"):
        simulate(diagram, engine="native")
