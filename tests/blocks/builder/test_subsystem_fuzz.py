"""Random multirate diagrams run the same flat and with some of their blocks as a subsystem.

The loader fuzz test's random diagrams (``wired_document``: random topology, periods,
offsets, inherited rates, delays with initial values, feedthrough chains, decimated logs,
loops) are rewritten with a run of their blocks moved into a subsystem file, and, half
of the time, a run of those into a subsystem of that subsystem. Every wire across a
boundary goes through the subsystem's ports: an input that feeds several inner inputs
from one source (with its delay and initial value), an output per inner signal used
outside. The composed diagram must load exactly when the flat one does, plan the same
event programs and give the same samples, to the last bit, under the inner names
(``s.b3.y``); a flat diagram that the planner refuses is refused composed too.
"""

from __future__ import annotations

import re

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import blocks

from ..test_diagram_fuzz import FUZZ_SETTINGS, dump, short_t_end, wired_document


def parse(conn) -> tuple[str, str, int, object]:
    """(src, dst, delay, initial) of a connection as written in a document."""
    if isinstance(conn, str):
        src, _, dst = conn.partition("->")
        return src.strip(), dst.strip(), 0, None
    return conn["from"], conn["to"], conn.get("delay", 0), conn.get("initial")


def written(src: str, dst: str, delay: int, initial) -> object:
    if not delay:
        return f"{src} -> {dst}"
    out = {"from": src, "to": dst, "delay": delay}
    if initial is not None:
        out["initial"] = initial
    return out


def compose(doc: dict, moved: list[str], name: str, file: str, log_inside: list[bool]) -> tuple[dict, dict]:
    """``doc`` with the blocks ``moved`` (a run of them, in order) replaced by subsystem
    ``name`` read from ``file``; returns (the new doc, the subsystem's doc). The logged
    signals of moved blocks go into the subsystem's file where ``log_inside`` says so (one
    flag per log entry), else stay in ``doc`` by their path (``name.b3.y``)."""
    inner: dict = {"name": name, "blocks": {}, "connections": [], "inputs": {}, "outputs": {}}
    outer_blocks: dict = {}
    for block, spec in doc["blocks"].items():
        if block in moved:
            inner["blocks"][block] = spec
            outer_blocks.setdefault(name, {"diagram": file})
        else:
            outer_blocks[block] = spec
    inside = set(moved)

    def owner(endpoint: str) -> str:
        return endpoint.split(".")[0]

    inputs: dict[tuple, str] = {}
    outputs: dict[str, str] = {}

    def output_port(signal: str) -> str:
        if signal not in outputs:
            outputs[signal] = f"o{len(outputs)}"
            inner["outputs"][outputs[signal]] = signal
        return f"{name}.{outputs[signal]}"

    connections = []
    for conn in doc.get("connections", []):
        src, dst, delay, initial = parse(conn)
        if owner(src) in inside and owner(dst) in inside:
            inner["connections"].append(conn)
        elif owner(dst) in inside:
            key = (src, delay, repr(initial))
            if key not in inputs:
                inputs[key] = f"i{len(inputs)}"
                inner["inputs"][inputs[key]] = []
                connections.append(written(src, f"{name}.{inputs[key]}", delay, initial))
            inner["inputs"][inputs[key]].append(dst)
        elif owner(src) in inside:
            connections.append(written(output_port(src), dst, delay, initial))
        else:
            connections.append(conn)
    outer = {k: v for k, v in doc.items() if k not in ("blocks", "connections", "log", "inputs", "outputs")}
    outer["blocks"] = outer_blocks
    outer["connections"] = connections
    for port, targets in doc.get("inputs", {}).items():
        targets = [targets] if isinstance(targets, str) else targets
        keep = [t for t in targets if owner(t) not in inside]
        into = [t for t in targets if owner(t) in inside]
        if into:
            inner["inputs"][f"p_{port}"] = into
            keep.append(f"{name}.p_{port}")
        outer.setdefault("inputs", {})[port] = keep
    for port, source in doc.get("outputs", {}).items():
        outer.setdefault("outputs", {})[port] = output_port(source) if owner(source) in inside else source
    log = doc.get("log", [])
    if log == "all":
        outer["log"] = "all"
    else:
        outer["log"], inner["log"] = [], []
        for entry, put_inside in zip(log, log_inside + [False] * len(log)):
            signal = entry if isinstance(entry, str) else entry["signal"]
            if owner(signal) not in inside:
                outer["log"].append(entry)
            elif put_inside:
                inner["log"].append(entry)
            elif isinstance(entry, str):
                outer["log"].append(f"{name}.{entry}")
            else:
                outer["log"].append({**entry, "signal": f"{name}.{signal}"})
    return outer, {k: v for k, v in inner.items() if v or k in ("name", "blocks")}


def renamer(paths: dict[str, str]):
    """Text with every flat block name ``b3`` replaced by its path (``s.t.b3``)."""
    pattern = re.compile(r"(?<![\w.])(b\d+)\b")
    return lambda text: pattern.sub(lambda m: paths.get(m.group(1), m.group(1)), text)


def programs(diagram, t_end) -> list[str]:
    s = blocks.build_schedule(diagram, t_end)
    return [s.initial.describe()] + [p.describe() for p in s.programs] + [s.final.describe() if s.final else ""]


def loads_flat(doc: dict) -> bool:
    try:
        blocks.loads_diagram(dump(doc), filename="flat.yaml")
    except blocks.DiagramError:
        return False
    return True


@st.composite
def composed(draw, valid: bool = True):
    """A random diagram (one that loads, when ``valid``), the run of blocks to move into
    subsystem ``s``, the run of those to move on into ``t`` inside it (or None), and where
    the logged signals go."""
    doc = draw(wired_document(valid=True).filter(loads_flat) if valid else wired_document())
    names = list(doc["blocks"])
    nested = draw(st.booleans()) and len(names) >= 2
    start = draw(st.integers(min_value=0, max_value=len(names) - (2 if nested else 1)))
    stop = draw(st.integers(min_value=start + (2 if nested else 1), max_value=len(names)))
    inner_start = draw(st.integers(min_value=start, max_value=stop - 1))
    inner_stop = draw(st.integers(min_value=inner_start + 1, max_value=stop))
    flags = draw(st.lists(st.booleans(), min_size=8, max_size=8))
    return doc, names[start:stop], names[inner_start:inner_stop] if nested else None, flags


@settings(max_examples=200, **FUZZ_SETTINGS)
@given(case=composed(), ticks=st.integers(min_value=1, max_value=60))
def test_a_subsystem_runs_bit_identical_to_the_same_blocks_flat(case, ticks, tmp_path):
    check_composed(case, ticks, tmp_path)


@settings(max_examples=100, **FUZZ_SETTINGS)
@given(case=composed(valid=False), ticks=st.integers(min_value=1, max_value=20))
def test_a_diagram_refused_flat_is_refused_with_a_subsystem(case, ticks, tmp_path):
    check_composed(case, ticks, tmp_path)


def check_composed(case, ticks, tmp_path) -> None:
    doc, moved, nested, flags = case
    top, sub = compose(doc, moved, "s", "s.yaml", flags if not nested else [True] * 8)
    paths = {b: f"s.{b}" for b in moved}
    if nested:
        sub, inner = compose(sub, nested, "t", "t.yaml", flags[4:] + flags[:4])
        (tmp_path / "t.yaml").write_text(dump(inner), encoding="utf-8")
        paths.update({b: f"s.t.{b}" for b in nested})
    (tmp_path / "s.yaml").write_text(dump(sub), encoding="utf-8")
    (tmp_path / "top.yaml").write_text(dump(top), encoding="utf-8")
    rename = renamer(paths)
    try:
        flat = blocks.loads_diagram(dump(doc), filename="flat.yaml", base_dir=tmp_path)
    except blocks.DiagramError as flat_error:
        try:
            blocks.load_diagram(tmp_path / "top.yaml")
        except blocks.DiagramError as error:
            loops = ["algebraic loop" in str(e) for e in (flat_error, error)]
            assert loops[0] == loops[1], (str(flat_error), str(error))
            return
        raise AssertionError(f"the flat diagram fails ({flat_error}), the composed one loads")
    diagram = blocks.load_diagram(tmp_path / "top.yaml")
    assert list(diagram.blocks) == [rename(b) for b in flat.blocks]
    t_end = short_t_end(flat, ticks)
    if t_end is None:
        return
    assert programs(diagram, t_end) == [rename(p) for p in programs(flat, t_end)]
    a, b = blocks.simulate(flat, t_end=t_end), blocks.simulate(diagram, t_end=t_end)
    assert b.status == rename(a.status)
    assert set(b) == {rename(s) for s in a}
    for signal in a:
        (ta, va), (tb, vb) = a[signal], b[rename(signal)]
        assert np.array_equal(ta, tb) and np.array_equal(va, vb) and va.dtype == vb.dtype, signal


def test_the_rewriting_moves_wires_through_ports():
    doc = {"name": "x", "blocks": {"b0": {"type": "Step", "period": "1 ms", "params": {"time": 0.0}},
                                   "b1": {"type": "Gain", "params": {"k": 2.0}},
                                   "b2": {"type": "Gain", "params": {"k": 3.0}}},
           "connections": ["b0.y -> b1.u", "b1.y -> b2.u"], "log": ["b1.y", "b2.y"]}
    top, sub = compose(doc, ["b1"], "s", "s.yaml", [False, False])
    assert top["connections"] == ["b0.y -> s.i0", "s.o0 -> b2.u"]
    assert sub["inputs"] == {"i0": ["b1.u"]} and sub["outputs"] == {"o0": "b1.y"}
    assert top["log"] == ["s.b1.y", "b2.y"]
