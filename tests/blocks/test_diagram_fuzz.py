"""Fuzzing the diagram loader: any input gives a Diagram or a DiagramError, nothing else.

Three sources of input: arbitrary text, text stitched from YAML and diagram fragments,
and mutations of the shipped toy diagram; plus structured diagram-shaped documents
built from the block library with random (valid and invalid) parameters, periods,
connections and log entries. Whenever a Diagram comes back, a short simulation must
give Results (or a DiagramError), and every reported issue must point inside the file.
"""

from __future__ import annotations

import copy
from fractions import Fraction
from pathlib import Path

import numpy as np
import yaml
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import blocks
import blocks.library
from blocks.library import LIBRARY

FILENAME = "fuzz.yaml"
TOY_TEXT = (Path(__file__).resolve().parents[2] / "diagrams" / "toy.yaml").read_text(encoding="utf-8")

FUZZ_SETTINGS = dict(derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                           HealthCheck.too_slow,
                                                           HealthCheck.filter_too_much])


def dump(doc: object) -> str:
    """``doc`` as YAML text in its own key order, written by libyaml's emitter where PyYAML
    has it: the pure-Python one took half of an example's time."""
    return yaml.dump(doc, Dumper=getattr(yaml, "CSafeDumper", yaml.SafeDumper), sort_keys=False)


def check_issues(err: blocks.DiagramError, text: str) -> None:
    """A DiagramError carries at least one issue, each printable and located inside the file."""
    assert err.issues, "a DiagramError without issues"
    n_lines = text.count("\n") + 1
    for issue in err.issues:
        assert isinstance(issue, blocks.Issue)
        assert issue.message
        printed = str(issue)
        assert printed.startswith(issue.file)
        if issue.file == FILENAME and issue.line is not None:
            assert 1 <= issue.line <= n_lines + 1, (issue, n_lines)


def load_or_error(text: str, base_dir: Path):
    """The loader's answer: a Diagram, or None after a well-formed DiagramError."""
    try:
        diagram = blocks.loads_diagram(text, filename=FILENAME, base_dir=base_dir)
    except blocks.DiagramError as err:
        check_issues(err, text)
        return None
    assert isinstance(diagram, blocks.Diagram)
    return diagram


def short_t_end(diagram: blocks.Diagram, ticks: int) -> Fraction | None:
    """A t_end of ``ticks`` base ticks, or None if the diagram cannot even be planned."""
    try:
        schedule = blocks.build_schedule(diagram, None)
    except blocks.DiagramError:
        return None
    return schedule.base_tick * ticks


def simulate_briefly(diagram: blocks.Diagram, text: str, ticks: int) -> None:
    t_end = short_t_end(diagram, ticks)
    if t_end is None:
        return
    try:
        results = blocks.simulate(diagram, t_end=t_end)
    except blocks.DiagramError as err:
        check_issues(err, text)
        return
    assert isinstance(results, blocks.Results)
    assert results.status == "complete" or results.status.startswith("failed at t="), results.status
    logged = {e.signal for e in diagram.log}
    assert set(results) == logged
    for name in results:
        t, v = results[name]
        assert v.ndim == 2 and v.shape == (len(t), diagram.width(name))
        assert np.all(np.diff(t) > 0)
        if len(t):
            assert 0 <= t[0] and t[-1] <= float(t_end) * (1 + 1e-12)


# -- (a) text --------------------------------------------------------------------------------

FRAGMENTS = [
    "name: ", "description: ", "version: 1", "version: 2", "time:", "t_end:", "time: {t_end: 1 ms}",
    "blocks:", "connections:", "log:", "log: all", "type:", "period:", "offset:", "params:",
    "params_file:", "delay:", "initial:", "from:", "to:", "signal:", "decimate:",
    "Gain", "Sum", "Constant", "Step", "Ramp", "UnitDelay", "ZeroOrderHold", "Saturation",
    "DiscreteStateSpace", "DiscreteTransferFunction", "python:os:system", "Gian",
    "a", "b", "c", "a.y", "b.u", "b.u0", "c.u1", "a.y -> b.u", "b.y -> a.u", "->", " -> ",
    "k: 2", "value: 1", "signs: '+-'", "A: [[1]]", "B: [[1]]", "C: [[1]]", "D: [[0]]",
    "num: [1]", "den: [1, -0.5]", "method: zoh", "time: 0.001",
    ":", ": ", "- ", "-", "[", "]", "{", "}", ",", "'", '"', "#", "?", "|", ">", "&x ", "*x", "<<: ",
    "!!binary ", "!!set ", "!!python/object:os.system ", "!custom ", "---\n", "...\n", "%YAML 1.1\n",
    "0", "1", "-1", "2.5", "1e-3", "1e400", ".nan", ".inf", "-.inf", "null", "~", "true", "0x10",
    "1 ms", "0.1 ms", "100 us", "10 ms", "0.5 s", "1ms", "fast", "0 s", "-1 ms", "3 ms", "1 ns",
    "\n", "\n", "\n", "  ", "    ", "\t", " ",
]

fragment_text = st.lists(st.sampled_from(FRAGMENTS), min_size=1, max_size=60).map("".join)


@settings(max_examples=300, **FUZZ_SETTINGS)
@given(text=st.text(max_size=300))
@example(text="- x\n")
def test_any_text_gives_diagram_or_diagram_error(text, tmp_path):
    diagram = load_or_error(text, tmp_path)
    if diagram is not None:
        simulate_briefly(diagram, text, 3)


@settings(max_examples=400, **FUZZ_SETTINGS)
@given(text=fragment_text, ticks=st.integers(min_value=1, max_value=20))
def test_yaml_fragments_give_diagram_or_diagram_error(text, ticks, tmp_path):
    diagram = load_or_error(text, tmp_path)
    if diagram is not None:
        simulate_briefly(diagram, text, ticks)


@st.composite
def mutated_toy(draw) -> str:
    """The toy diagram after a few random edits: insertions, deletions, line swaps, replacements."""
    text = TOY_TEXT
    for _ in range(draw(st.integers(min_value=1, max_value=4))):
        kind = draw(st.sampled_from(["insert", "delete", "swap", "replace", "dup"]))
        lines = text.splitlines(keepends=True)
        if kind == "insert":
            pos = draw(st.integers(min_value=0, max_value=len(text)))
            text = text[:pos] + draw(st.sampled_from(FRAGMENTS)) + text[pos:]
        elif kind == "delete":
            pos = draw(st.integers(min_value=0, max_value=max(len(text) - 1, 0)))
            n = draw(st.integers(min_value=1, max_value=12))
            text = text[:pos] + text[pos + n:]
        elif kind == "swap" and len(lines) > 1:
            i = draw(st.integers(min_value=0, max_value=len(lines) - 1))
            j = draw(st.integers(min_value=0, max_value=len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
            text = "".join(lines)
        elif kind == "replace":
            old = draw(st.sampled_from(["1 ms", "10 ms", "0.1 ms", "1 s", "5.0", "0.999", "+-", "++",
                                        "plant", "err", "u0", "u1", "y", "Gain", "Sum", "->", ":",
                                        "[[", "]]", "{", "}"]))
            new = draw(st.sampled_from(FRAGMENTS))
            text = text.replace(old, new, draw(st.integers(min_value=1, max_value=3)))
        elif kind == "dup" and lines:
            i = draw(st.integers(min_value=0, max_value=len(lines) - 1))
            lines.insert(i, lines[i])
            text = "".join(lines)
    return text


@settings(max_examples=300, **FUZZ_SETTINGS)
@given(text=mutated_toy(), ticks=st.integers(min_value=1, max_value=30))
def test_mutated_toy_gives_diagram_or_diagram_error(text, ticks, tmp_path):
    diagram = load_or_error(text, tmp_path)
    if diagram is not None:
        simulate_briefly(diagram, text, ticks)


def test_unmutated_toy_loads_and_runs(tmp_path):
    diagram = load_or_error(TOY_TEXT, tmp_path)
    assert diagram is not None
    simulate_briefly(diagram, TOY_TEXT, 25)


# -- (b) structured diagram-shaped documents ------------------------------------------------

TYPE_NAMES = [cls.registered_name() for cls in LIBRARY]
BAD_TYPES = ["Gian", "python:os:system", "python:nope", "", 3, None, ["Gain"]]
PERIODS = ["0.1 ms", "1 ms", "2 ms", "10 ms", "100 us", "0.5 s", 0.001, 0.002, "1e-3", 1,
           "3 ms", "0.3 ms", "fast", 0, "0 s", -1, "-1 ms", None, [1], "1 ms ms", 1e400, "nan",
           "1e5000 s", "1e-5000 s"]
OFFSETS = ["0 ms", "0.5 ms", "1 ms", "1 s", "-1 ms", "x", 0, None, "1e-5000 s"]
T_ENDS = ["1 ms", "10 ms", "1.5 ms", "0.5 s", 0, -1, "soon", None, 0.01]
NAMES = ["a", "b", "c", "d", "gain", "_x", "x1"]
BAD_NAMES = ["1x", "a.b", "", "a b", 5]
PORTS = ["y", "u", "u0", "u1", "u2", "q"]

numbers = st.one_of(st.integers(min_value=-5, max_value=5),
                    st.floats(min_value=-10, max_value=10, allow_nan=False),
                    st.sampled_from([0.0, 1.0, -1.0, 0.5, 0.999, 1e-4]))
param_values = st.one_of(
    numbers,
    st.lists(numbers, min_size=0, max_size=3),
    st.lists(st.lists(numbers, min_size=1, max_size=3), min_size=1, max_size=3),
    st.sampled_from(["+-", "++", "+", "-", "+-+", "*", "", "zoh", "tustin", "euler", "abc"]),
    st.none(), st.booleans(),
    st.sampled_from([[[0.5]], [[1.0]], [[0.0]], [[1, 0], [0, 1]], [1, -0.5], [1], [0, 0]]),
    st.just(float("inf")), st.just(float("nan")), st.just(10**18),
)


@st.composite
def block_spec(draw, names: list) -> object:
    if draw(st.integers(min_value=0, max_value=15)) == 0:
        return draw(st.sampled_from([None, 3, "Gain", ["type", "Gain"]]))
    if draw(st.integers(min_value=0, max_value=8)) == 0:
        type_name = draw(st.sampled_from(BAD_TYPES))
        cls = None
    else:
        cls = draw(st.sampled_from(LIBRARY))
        type_name = cls.registered_name()
    spec: dict = {"type": type_name}
    if draw(st.booleans()):
        spec["period"] = draw(st.sampled_from(PERIODS))
    if draw(st.integers(min_value=0, max_value=4)) == 0:
        spec["offset"] = draw(st.sampled_from(OFFSETS))
    declared = list(cls.parameters()) if cls is not None else ["k", "value"]
    keys = draw(st.lists(st.sampled_from(declared + ["bogus", "k", "x0"]), unique=True, max_size=5))
    if keys or draw(st.booleans()):
        spec["params"] = {k: draw(param_values) for k in keys}
    if draw(st.integers(min_value=0, max_value=10)) == 0:
        spec["params_file"] = draw(st.sampled_from(["params.yaml", "missing.yaml", "bad.yaml", 7]))
    if draw(st.integers(min_value=0, max_value=10)) == 0:
        spec[draw(st.sampled_from(["colour", "typo", "perod"]))] = 1
    if draw(st.integers(min_value=0, max_value=10)) == 0:
        spec.pop("type")
    return spec


@st.composite
def endpoint(draw, names: list) -> object:
    if draw(st.integers(min_value=0, max_value=12)) == 0:
        return draw(st.sampled_from(["a", "a.", ".y", "a.y.z", 3, None, "a y", ["a", "y"]]))
    block = draw(st.sampled_from(names + ["zz"])) if names else "zz"
    return f"{block}.{draw(st.sampled_from(PORTS))}"


@st.composite
def connection(draw, names: list) -> object:
    kind = draw(st.integers(min_value=0, max_value=9))
    if kind <= 5:
        src, dst = draw(endpoint(names)), draw(endpoint(names))
        return f"{src} -> {dst}" if isinstance(src, str) and isinstance(dst, str) else f"{src}->{dst}"
    if kind <= 8:
        conn: dict = {"from": draw(endpoint(names)), "to": draw(endpoint(names))}
        if draw(st.booleans()):
            conn["delay"] = draw(st.sampled_from([0, 1, 1, 2, True, "1", None]))
        if draw(st.integers(min_value=0, max_value=3)) == 0:
            conn["initial"] = draw(st.sampled_from([0.0, 1.5, [1.0, 2.0], "x", [[1.0]], None, float("nan")]))
        if draw(st.integers(min_value=0, max_value=10)) == 0:
            conn.pop(draw(st.sampled_from(["from", "to"])))
        if draw(st.integers(min_value=0, max_value=10)) == 0:
            conn["via"] = "x"
        return conn
    return draw(st.sampled_from([3, None, ["a.y", "b.u"], "a.y b.u", "a.y => b.u", {}]))


@st.composite
def log_section(draw, names: list) -> object:
    kind = draw(st.integers(min_value=0, max_value=9))
    if kind == 0:
        return "all"
    if kind == 1:
        return draw(st.sampled_from([None, "plant.y", 3, {"signal": "a.y"}]))
    entries = []
    for _ in range(draw(st.integers(min_value=0, max_value=4))):
        ep = draw(endpoint(names))
        if draw(st.integers(min_value=0, max_value=3)) == 0:
            entry: dict = {"signal": ep, "decimate": draw(st.sampled_from([1, 2, 5, 0, -1, "x", 1.5, True]))}
            if draw(st.integers(min_value=0, max_value=8)) == 0:
                entry["every"] = 2
            entries.append(entry)
        else:
            entries.append(ep)
    return entries


@st.composite
def diagram_document(draw) -> dict:
    names = draw(st.lists(st.sampled_from(NAMES), unique=True, min_size=0, max_size=5))
    if draw(st.integers(min_value=0, max_value=10)) == 0:
        names.append(draw(st.sampled_from(BAD_NAMES)))
    doc: dict = {}
    if draw(st.booleans()):
        doc["name"] = draw(st.sampled_from(["fuzz", "x", 3, None]))
    if draw(st.integers(min_value=0, max_value=6)) == 0:
        doc["version"] = draw(st.sampled_from([1, 2, "1", True]))
    if draw(st.booleans()):
        doc["time"] = draw(st.one_of(st.fixed_dictionaries({"t_end": st.sampled_from(T_ENDS)}),
                                     st.sampled_from([None, "1 s", {}, {"t_stop": 1}])))
    if draw(st.integers(min_value=0, max_value=12)) != 0:
        doc["blocks"] = {n: draw(block_spec(names)) for n in names}
    else:
        doc["blocks"] = draw(st.sampled_from([None, [], "Gain", {}]))
    str_names = [n for n in names if isinstance(n, str)]
    if draw(st.integers(min_value=0, max_value=8)) != 0:
        doc["connections"] = draw(st.lists(connection(str_names), max_size=8))
    elif draw(st.booleans()):
        doc["connections"] = draw(st.sampled_from([None, "a.y -> b.u", {}, 3]))
    if draw(st.integers(min_value=0, max_value=3)) != 0:
        doc["log"] = draw(log_section(str_names))
    if draw(st.integers(min_value=0, max_value=10)) == 0:
        doc[draw(st.sampled_from(["extra", "blocks_", "conections"]))] = 1
    return doc


TEMPLATES = {
    "Constant": {"params": {"value": 1.0}},
    "Step": {"period": "1 ms", "params": {"time": 0.002}},
    "Ramp": {"period": "2 ms", "params": {"slope": 1.0}},
    "Gain": {"params": {"k": 2.0}},
    "Sum": {"params": {"signs": "+-"}},
    "Saturation": {"params": {"lower": -1.0, "upper": 1.0}},
    "UnitDelay": {"period": "1 ms"},
    "ZeroOrderHold": {"period": "2 ms"},
    "DiscreteStateSpace": {"period": "1 ms", "params": {"A": [[0.5]], "B": [[1.0]], "C": [[1.0]], "D": [[0.0]]}},
    "DiscreteTransferFunction": {"period": "0.5 ms", "params": {"num": [1.0], "den": [1.0, -0.5]}},
}
GOOD_PERIODS = ["0.1 ms", "0.5 ms", "1 ms", "2 ms", "5 ms", "1.5 ms"]


@st.composite
def wired_document(draw, valid: bool = False) -> dict:
    """Library blocks with working parameters, every input wired to a random output, then a
    few random corruptions: mostly valid diagrams with random topology and rates. With
    ``valid``, none of what the loader always refuses is drawn (corruptions, an input left
    unconnected, an offset not within its period, a source without a period), so that most
    documents load (widths and rates that do not fit still make some fail)."""
    n = draw(st.integers(min_value=1, max_value=6))
    specs: dict = {}
    ports: dict = {}
    for i in range(n):
        kinds = ["Constant", "Ramp", "Step"] if i == 0 else sorted(TEMPLATES)
        type_name = draw(st.sampled_from(kinds))
        spec = copy.deepcopy(TEMPLATES[type_name])
        spec["type"] = type_name
        if type_name == "Sum":
            spec["params"]["signs"] = draw(st.sampled_from(["+", "+-", "++-", "-"]))
        if type_name == "Gain" and draw(st.booleans()):
            spec["params"]["k"] = draw(st.sampled_from([[1.0, 2.0], [[1.0, 0.5]], [[1.0], [2.0]], -3.0]))
        if type_name in ("UnitDelay", "Constant") and draw(st.integers(min_value=0, max_value=3)) == 0:
            spec.setdefault("params", {})["value" if type_name == "Constant" else "initial"] = [0.0, 1.0]
        choice = draw(st.integers(min_value=0, max_value=4))
        if choice == 0 and not (valid and i == 0):
            spec.pop("period", None)
        elif choice == 1:
            spec["period"] = draw(st.sampled_from(GOOD_PERIODS))
            if draw(st.integers(min_value=0, max_value=3)) == 0:
                offsets = ["0.1 ms", "0.5 ms", "0 s"]
                if valid:
                    offsets = [o for o in offsets if float(o.split()[0]) < float(spec["period"].split()[0])]
                spec["offset"] = draw(st.sampled_from(offsets))
        name = f"b{i}"
        specs[name] = spec
        block = getattr(blocks.library, type_name)(**spec.get("params", {}))
        ports[name] = (list(block.inputs), list(block.outputs))
    outputs = [f"{b}.{p}" for b, (_, outs) in ports.items() for p in outs]
    connections: list = []
    for i, (b, (ins, _)) in enumerate(ports.items()):
        # Mostly feed-forward (from blocks listed earlier), sometimes from anywhere (loops).
        earlier = [f"{e}.{p}" for e in list(ports)[:i] for p in ports[e][1]]
        for p in ins:
            if not outputs or (not valid and draw(st.integers(min_value=0, max_value=15)) == 0):
                continue                                   # leave an input unconnected
            pool = earlier if earlier and draw(st.integers(min_value=0, max_value=5)) else outputs
            src = draw(st.sampled_from(pool))
            if draw(st.integers(min_value=0, max_value=3)) == 0:
                conn: dict = {"from": src, "to": f"{b}.{p}", "delay": 1}
                if draw(st.booleans()):
                    conn["initial"] = draw(st.sampled_from([0.5, [1.0, 2.0]]))
                connections.append(conn)
            else:
                connections.append(f"{src} -> {b}.{p}")
    log: object = draw(st.lists(st.sampled_from(outputs), unique=True, max_size=4)) if outputs else []
    if log and draw(st.booleans()):
        log = [{"signal": s, "decimate": draw(st.sampled_from([1, 2, 3]))} for s in log]
    if draw(st.integers(min_value=0, max_value=5)) == 0:
        log = "all"
    doc = {"name": "wired", "blocks": specs, "connections": connections, "log": log}
    for _ in range(0 if valid else draw(st.integers(min_value=0, max_value=2))):
        victim = draw(st.sampled_from(sorted(specs)))
        what = draw(st.sampled_from(["period", "param", "type", "drop-connection", "dup-connection"]))
        if what == "period":
            specs[victim]["period"] = draw(st.sampled_from(PERIODS))
        elif what == "param":
            key = draw(st.sampled_from(list(getattr(blocks.library, specs[victim]["type"]).parameters())
                                       or ["k"]))
            specs[victim].setdefault("params", {})[key] = draw(param_values)
        elif what == "type":
            specs[victim]["type"] = draw(st.sampled_from(TYPE_NAMES))
        elif connections and what == "drop-connection":
            connections.pop(draw(st.integers(min_value=0, max_value=len(connections) - 1)))
        elif connections:
            connections.append(draw(st.sampled_from(connections)))
    return doc


@settings(max_examples=400, **FUZZ_SETTINGS)
@given(doc=wired_document(), ticks=st.integers(min_value=1, max_value=40))
def test_wired_diagrams_give_diagram_or_diagram_error(doc, ticks, tmp_path):
    text = dump(doc)
    diagram = load_or_error(text, tmp_path)
    if diagram is not None:
        simulate_briefly(diagram, text, ticks)


def write_params_files(base: Path) -> None:
    """The parameter files the documents name, written once into ``base`` (a test's examples
    share its folder, and loading only reads them)."""
    if not (base / "bad.yaml").is_file():
        (base / "params.yaml").write_text("k: 3.0\nvalue: 2.0\n", encoding="utf-8")
        (base / "bad.yaml").write_text("k: [1, 2\n", encoding="utf-8")


@settings(max_examples=400, **FUZZ_SETTINGS)
@given(doc=diagram_document(), ticks=st.integers(min_value=1, max_value=25))
def test_structured_diagrams_give_diagram_or_diagram_error(doc, ticks, tmp_path):
    write_params_files(tmp_path)
    text = dump(doc)
    diagram = load_or_error(text, tmp_path)
    if diagram is not None:
        simulate_briefly(diagram, text, ticks)


# A sanity check that the structured strategy reaches runnable diagrams at all, so the
# simulate half of the property above is exercised, not vacuous.

VALID_CHAIN = {
    "time": {"t_end": "10 ms"},
    "blocks": {
        "a": {"type": "Step", "period": "1 ms", "params": {"time": 0.002}},
        "b": {"type": "Gain", "params": {"k": 2.0}},
        "c": {"type": "UnitDelay", "period": "2 ms"},
    },
    "connections": ["a.y -> b.u", "b.y -> c.u"],
    "log": "all",
}


VALID_PERIODS = {"0.1 ms": Fraction(1, 10000), "100 us": Fraction(1, 10000), "0.3 ms": Fraction(3, 10000),
                 "1 ms": Fraction(1, 1000), "1e-3": Fraction(1, 1000), 0.001: Fraction(1, 1000),
                 "1.5 ms": Fraction(3, 2000), "2 ms": Fraction(1, 500), 0.002: Fraction(1, 500),
                 "3 ms": Fraction(3, 1000), "10 ms": Fraction(1, 100), "0.5 s": Fraction(1, 2), 1: Fraction(1)}
"""Periods of the step source that keep t_end = 10 ms a whole number of base ticks, with
their exact values."""

valid_gains = st.one_of(
    st.integers(min_value=-5, max_value=5),
    st.floats(min_value=-1e6, max_value=1e6, allow_nan=False),
    st.lists(st.floats(min_value=-10, max_value=10, allow_nan=False), min_size=1, max_size=3)
    .map(lambda column: [[x] for x in column]),
)
"""Gains a width-1 signal can go through: scalars and one-column matrices."""


@settings(max_examples=60, **FUZZ_SETTINGS)
@given(k=valid_gains, period=st.sampled_from(list(VALID_PERIODS)))
def test_valid_chain_with_random_gain_and_period(k, period, tmp_path):
    """Every valid gain and period loads and runs to t_end, and the delay's output at each
    of its hits is k times the step as the source held it at the delay's previous hit."""
    doc = copy.deepcopy(VALID_CHAIN)
    doc["blocks"]["b"]["params"]["k"] = k
    doc["blocks"]["a"]["period"] = period
    text = dump(doc)
    diagram = load_or_error(text, tmp_path)
    assert diagram is not None, text
    results = blocks.simulate(diagram)
    assert results.complete, results.status
    t, y = results["c.y"]
    hits = [Fraction(2, 1000) * j for j in range(6)]
    np.testing.assert_array_equal(t, [float(h) for h in hits])
    p = VALID_PERIODS[period]
    stepped = [float((h // p) * p >= Fraction(2, 1000)) for h in hits[:-1]]
    gain = np.asarray(k, dtype=float).reshape(-1)
    np.testing.assert_array_equal(y, [np.zeros(gain.size)] + [gain * s for s in stepped])


def test_valid_chain_runs(tmp_path):
    text = dump(VALID_CHAIN)
    diagram = load_or_error(text, tmp_path)
    assert diagram is not None
    results = blocks.simulate(diagram, t_end="10 ms")
    assert results.complete
    t, y = results["c.y"]
    np.testing.assert_allclose(t, [0.0, 0.002, 0.004, 0.006, 0.008, 0.010])
    np.testing.assert_array_equal(y[:, 0], [0.0, 0.0, 2.0, 2.0, 2.0, 2.0])


# -- edge inputs found by fuzzing, kept as fixed cases -----------------------------------------

EDGE_INPUTS = {
    "top-level-list": "- a\n- b\n",
    "top-level-empty-list": "[]\n",
    "top-level-scalar": "42\n",
    "empty-text": "",
    "huge-period": "time: {t_end: 1 ms}\nblocks:\n  a: {type: Step, period: 1e5000 s, params: {time: 0.0}}\n",
    "tiny-offset": "blocks:\n  a: {type: Step, period: 1 ms, offset: 1e-5000 s, params: {time: 0.0}}\n",
    "huge-width": "blocks:\n  a: {type: UnitDelay, period: 1 ms, params: {width: 1000000000000000000}}\n"
                  "connections: [a.y -> a.u]\n",
    "deep-nesting": "blocks:\n  a: {type: Gain, params: {k: " + "[" * 300 + "1" + "]" * 300 + "}}\n",
    "very-deep-nesting": "[" * 5000 + "]" * 5000 + "\n",
}


@pytest.mark.parametrize("text", list(EDGE_INPUTS.values()), ids=list(EDGE_INPUTS))
def test_edge_inputs_give_diagram_or_diagram_error(text, tmp_path):
    diagram = load_or_error(text, tmp_path)
    if diagram is not None:
        simulate_briefly(diagram, text, 3)
