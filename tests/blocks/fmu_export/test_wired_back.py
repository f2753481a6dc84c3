"""A subsystem exported as an FMU and wired back into its diagram runs as the subsystem did.

The loader fuzz test's random diagrams (mixed rates and offsets, chains of blocks with and
without feedthrough, loops broken by delays) have a run of their blocks moved into a
subsystem (the subsystem fuzz test's ``compose``), which is exported as an FMU and wired
back in its place with no annotation: the FMU block orders the exchange by the
dependencies its ModelStructure declares, as the diagram's evaluation order does. Every
signal outside the FMU, and each inner output (all are FMU outputs), equals the flat
diagram's (its held samples), bit for bit, and to 1e-12 where the subsystem holds a
state-space block (whose closed-form advance a communication step may cut in two).

So that the blocks moved can stand alone as they run in the diagram, both diagrams give
them a rate of their own (an FMU has no inherited rates) and a scalar gain the diagonal
matrix of its width (an exported diagram's inputs give no width to infer), and drop the
delay of a wire across the boundary (it would count the FMU's hits, not the inner
block's). Left out: a stateful block outside that inherits its rate from the FMU (it then
fires at the FMU's step), and a loop that closes only through rates that never fire
together (an FMU's dependencies hold at every step, so with the FMU it is a loop).
"""

from __future__ import annotations

import copy

import numpy as np
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

import blocks
from blocks.fmu_export import export_fmu

from ..builder.test_subsystem_fuzz import compose, loads_flat, parse
from ..test_diagram_fuzz import FUZZ_SETTINGS, GOOD_PERIODS, dump, short_t_end, wired_document


@st.composite
def wired_back(draw):
    """A random diagram that loads, and the run of its blocks to export as the FMU ``s``."""
    doc = draw(wired_document(valid=True).filter(loads_flat))
    names = list(doc["blocks"])
    start = draw(st.integers(min_value=0, max_value=len(names) - 1))
    stop = draw(st.integers(min_value=start + 1, max_value=len(names)))
    periods = draw(st.lists(st.sampled_from(GOOD_PERIODS), min_size=len(names), max_size=len(names)))
    fmi = draw(st.sampled_from([2, 3]))
    return doc, names[start:stop], periods, fmi


def standalone(doc: dict, moved: list[str], periods: list[str]) -> dict | None:
    """``doc`` with the blocks to move made to stand alone as they run in it: a rate of
    their own (an FMU has no inherited rates) and a scalar gain as the diagonal matrix of
    its width (the exported diagram's inputs give no width to infer); None if it no longer
    loads."""
    try:
        flat = blocks.loads_diagram(dump(doc), filename="flat.yaml")
    except blocks.DiagramError:
        return None
    specs = copy.deepcopy(doc["blocks"])
    for b, period in zip(doc["blocks"], periods):
        spec = specs[b]
        if b not in moved:
            continue
        if spec["type"] != "Constant" and "period" not in spec:
            spec["period"] = period
        k = spec.get("params", {}).get("k")
        if spec["type"] == "Gain" and isinstance(k, float):
            spec["params"]["k"] = (k * np.eye(flat.width(f"{b}.y"))).tolist()
    changed = {**doc, "blocks": specs, "log": "all",
               "connections": [undelayed(c, moved) for c in doc["connections"]]}
    return changed if loads_flat(changed) else None


def undelayed(conn, moved: list[str]):
    """A connection without its delay where it crosses the subsystem's boundary (a delay
    counts its destination's hits, and the FMU's are not the inner block's)."""
    src, dst, delay, _ = parse(conn)
    if delay and (src.split(".")[0] in moved) != (dst.split(".")[0] in moved):
        return f"{src} -> {dst}"
    return conn


def held(t: np.ndarray, values: np.ndarray, at: np.ndarray) -> np.ndarray:
    """``values`` sampled at ``t`` held at the times ``at`` (each at or after the first sample)."""
    return values[np.searchsorted(t, at + 1e-12, side="right") - 1]


CUT_ADVANCES = ("DiscreteStateSpace", "DiscreteTransferFunction")
"""Blocks whose closed-form advance over several hits a communication step may cut in two."""


def same(mine: np.ndarray, theirs: np.ndarray, signal: str, exact: bool) -> None:
    if exact:
        np.testing.assert_array_equal(mine, theirs, err_msg=signal)
    scale = max(1.0, float(np.abs(theirs).max(initial=0.0)))
    np.testing.assert_allclose(mine, theirs, rtol=1e-12, atol=1e-12 * scale, err_msg=signal)


def wired(case, ticks, tmp_path) -> bool:
    """Run ``case`` flat and with its subsystem as an FMU and compare; whether it ran both."""
    doc, moved, periods, fmi = case
    doc = standalone(doc, moved, periods)
    if doc is None:
        return False
    top, sub = compose(doc, moved, "s", "s.yaml", [])
    wires = [parse(c) for c in top["connections"]]
    sub.pop("log", None)
    try:
        flat = blocks.loads_diagram(dump(doc), filename="flat.yaml", base_dir=tmp_path)
        for b in moved:   # every inner output an FMU output, to compare
            for port in flat.blocks[b].block.outputs:
                sub.setdefault("outputs", {})[f"x_{b}_{port}"] = f"{b}.{port}"
        inner = blocks.loads_diagram(dump(sub), filename="s.yaml", base_dir=tmp_path)
        path = export_fmu(inner, tmp_path / f"s{fmi}_{abs(hash(dump(sub)))}.fmu", fmi)
    except blocks.DiagramError:
        return False  # a subsystem that cannot stand alone (an inherited rate from outside), or be exported
    top["blocks"]["s"] = {"type": "FMU", "params": {"path": str(path)}}
    try:
        outer = blocks.loads_diagram(dump(top), filename="top.yaml", base_dir=tmp_path)
        blocks.build_schedule(outer, None)
    except blocks.DiagramError as error:
        assert "algebraic loop" in str(error), str(error)
        return False
    fed = {dst.split(".")[0] for src, dst, _, _ in wires if src.startswith("s.")}
    if any(outer.blocks[n].period is None and outer.blocks[n].block.is_stateful() for n in fed):
        return False
    t_end = short_t_end(flat, ticks)
    if t_end is None:
        return False
    a, b = blocks.simulate(flat, t_end=t_end), blocks.simulate(outer, t_end=t_end)
    if not (a.complete and b.complete):
        return False
    exact = not any(doc["blocks"][n]["type"] in CUT_ADVANCES for n in moved)
    for signal in b:
        tb, vb = b[signal]
        ta, va = a[sub["outputs"][signal[2:]] if signal.startswith("s.") else signal]
        keep = tb >= ta[0] - 1e-12
        same(vb[keep], held(ta, va, tb[keep]), signal, exact)
    return True


@settings(max_examples=40, **FUZZ_SETTINGS)
@given(case=wired_back(), ticks=st.integers(min_value=5, max_value=40))
def test_a_subsystem_wired_back_as_an_fmu_runs_as_the_same_blocks_flat(case, ticks, tmp_path):
    wired(case, ticks, tmp_path)


def test_a_feedthrough_chain_through_the_fmu_is_compared(tmp_path):
    """The property compares (not skips) a chain that feeds through the FMU at each tick."""
    doc = {"name": "chain", "blocks": {"b0": {"type": "Ramp", "period": "1 ms", "params": {"slope": 1.0}},
                                       "b1": {"type": "Gain", "params": {"k": 2.0}},
                                       "b2": {"type": "Gain", "params": {"k": 3.0}}},
           "connections": ["b0.y -> b1.u", "b1.y -> b2.u"], "log": "all"}
    for fmi in (2, 3):
        assert wired((doc, ["b1"], ["1 ms"] * 3, fmi), 40, tmp_path)


def test_a_loop_through_declared_dependencies_is_a_load_error_naming_its_ports(tmp_path):
    """A gain whose output feeds its own input through the FMU: the ModelStructure says the
    FMU's output reads its input, so the loop is algebraic, named port by port with its
    remedies; 'feedthrough: false' on the FMU (the Jacobi exchange) breaks it."""
    sub = {"name": "g", "blocks": {"g": {"type": "Gain", "period": "1 ms", "params": {"k": [[0.5]]}}},
           "inputs": {"u": "g.u"}, "outputs": {"y": "g.y"}}
    inner = blocks.loads_diagram(yaml.safe_dump(sub), filename="g.yaml", base_dir=tmp_path)
    path = export_fmu(inner, tmp_path / "g.fmu", 2)

    def looped(params: str) -> str:
        return f"""
time: {{t_end: 5 ms}}
blocks:
  src: {{type: Step, period: 1 ms, params: {{time: 0.002}}}}
  add: {{type: Sum, params: {{signs: "++"}}}}
  fmu: {{type: FMU, params: {{path: "{path}"{params}}}}}
connections: [src.y -> add.u0, fmu.y -> add.u1, add.y -> fmu.u]
log: [fmu.y]
"""
    try:
        blocks.build_schedule(blocks.loads_diagram(looped(""), filename="loop.yaml"), None)
    except blocks.DiagramError as error:
        text = str(error)
    else:
        raise AssertionError("a loop through the FMU's declared dependencies loaded")
    assert "algebraic loop: add.y -> fmu.u -> fmu.y -> add.u1 -> add.y" in text
    assert "delay: 1" in text and "feedthrough: false" in text and "'fmu'" in text
    jacobi = blocks.simulate(blocks.loads_diagram(looped(", feedthrough: false"), filename="loop.yaml"))
    np.testing.assert_array_equal(jacobi["fmu.y"][1][:, 0], [0.0, 0.0, 0.0, 0.5, 0.75, 0.875])
