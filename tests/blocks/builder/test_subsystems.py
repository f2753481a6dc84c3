"""Subsystems: a diagram file with its own ports used as one block of another.

A diagram declares ``inputs:`` (each feeding one or more inner inputs) and ``outputs:``;
another names it as a block entry ``{diagram: FILE, params: ..., bind: ...}``. Its blocks
become blocks of the including diagram under their path (``ctrl.integ``), so results, log
entries, overrides, sweeps, messages, ``validate`` and run.json name them so; every
problem is reported at the file and line it is written at.
"""

from __future__ import annotations

import csv
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import blocks
from blocks import DiagramError, load_diagram, simulate
from blocks.sweep import grid_points, parse_metrics, run_sweep
from blocks.sweep.plan import execute, prepare

from .test_diagram_builder import structure

ROOT = Path(__file__).resolve().parents[3]
TOY = ROOT / "diagrams" / "toy.yaml"

PI = """\
name: pi
description: a fast integral and a slow proportional path, summed
blocks:
  integ: {type: DiscreteStateSpace, period: 1 ms,
          params: {A: [[1.0]], B: [[0.02]], C: [[1.0]], D: [[0.0]]}}
  prop:  {type: Gain, period: 10 ms, params: {k: 5.0}}
  u:     {type: Sum, params: {signs: "++"}}
connections:
  - integ.y -> u.u0
  - prop.y -> u.u1
inputs: {e: [integ.u, prop.u]}
outputs: {u: u.y}
log: [integ.y]
"""

TOP = """\
name: toy-composed
time: {t_end: 1 s}
blocks:
  ref:   {type: Constant, params: {value: 1.0}}
  err:   {type: Sum, params: {signs: "+-"}}
  plant: {type: DiscreteStateSpace, period: 0.1 ms,
          params: {A: [[0.999]], B: [[1.0e-4]], C: [[1.0]], D: [[0.0]]}}
  ctrl:  {diagram: lib/pi.yaml}
connections:
  - ref.y -> err.u0
  - plant.y -> err.u1
  - err.y -> ctrl.e
  - ctrl.u -> plant.u
log: [plant.y]
"""


def write(folder: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return folder / next(iter(files))


@pytest.fixture
def toy(tmp_path) -> Path:
    """The toy diagram with its controller as the subsystem lib/pi.yaml."""
    return write(tmp_path, {"top.yaml": TOP, "lib/pi.yaml": PI})


def problems(path: Path, **kwargs) -> list[str]:
    with pytest.raises(DiagramError) as info:
        load_diagram(path, **kwargs)
    return [str(i) for i in info.value.issues]


def line(text: str, needle: str) -> int:
    return next(i for i, row in enumerate(text.splitlines(), start=1) if needle in row)


# -- what a subsystem is ----------------------------------------------------------------------


def test_a_subsystem_is_its_blocks_under_its_name_and_runs_as_the_flat_diagram(toy):
    d = load_diagram(toy)
    assert list(d.blocks) == ["ref", "err", "plant", "ctrl.integ", "ctrl.prop", "ctrl.u"]
    assert {str(c) for c in d.connections} >= {"err.y -> ctrl.integ.u", "err.y -> ctrl.prop.u", "ctrl.u.y -> plant.u"}
    assert [e.signal for e in d.log] == ["plant.y", "ctrl.integ.y"]  # the subsystem's own log, by path
    flat = simulate(load_diagram(TOY))
    results = simulate(d)
    assert np.array_equal(results["plant.y"][1], flat["plant.y"][1])
    assert np.array_equal(results["plant.y"][0], flat["plant.y"][0])
    assert results["ctrl.integ.y"][1].shape == (1001, 1)
    sub = d.subsystems["ctrl"]
    assert (sub.file, sub.source, sub.diagram_name, sub.line) == (str(toy.parent / "lib" / "pi.yaml"), "lib/pi.yaml",
                                                                  "pi", 8)
    assert sub.inputs["e"].signals == ("ctrl.integ.u", "ctrl.prop.u") and sub.inputs["e"].width == 1
    assert sub.outputs["u"].signals == ("ctrl.u.y",)
    assert d.files == {"lib/pi.yaml": toy.parent / "lib" / "pi.yaml"}


def test_a_diagram_with_inputs_validates_on_its_own_and_refuses_to_run(toy):
    pi = load_diagram(toy.parent / "lib" / "pi.yaml")
    assert pi.inputs["e"].signals == ("integ.u", "prop.u") and pi.outputs["u"].width == 1
    with pytest.raises(DiagramError) as info:
        simulate(pi, t_end="10 ms")
    assert str(info.value) == (f"{toy.parent / 'lib' / 'pi.yaml'}: diagram 'pi' has inputs (e) that an including "
                               "diagram gives it: it runs only as a subsystem (hint: use it as a block of another "
                               "diagram (ctrl: {diagram: pi.yaml}) and connect its inputs there)")
    proc = cli("run", "lib/pi.yaml", "--t-end", "10 ms", "-o", "out", cwd=toy.parent)
    assert proc.returncode == 2 and "runs only as a subsystem" in proc.stderr and "Traceback" not in proc.stderr
    assert not (toy.parent / "out").exists()


def test_overrides_reach_into_subsystems_the_outermost_winning(toy):
    text = TOP.replace("{diagram: lib/pi.yaml}", "{diagram: lib/pi.yaml, params: {prop.k: 2.0, integ.B: [[0.05]]}}")
    toy.write_text(text)
    d = load_diagram(toy, overrides={"ctrl.prop.k": 3.0})
    assert d.parameters()["ctrl.prop"] == {"k": 3.0} and d.parameters()["ctrl.integ"]["B"] == [[0.05]]
    assert d.subsystems["ctrl"].params == {"prop.k": 3.0, "integ.B": [[0.05]]}
    flat = load_diagram(TOY, overrides={"prop.k": 3.0, "integ.B": [[0.05]]})
    a, b = simulate(flat, t_end="50 ms"), simulate(d, t_end="50 ms")
    assert np.array_equal(a["plant.y"][1], b["plant.y"][1])


def test_run_json_names_the_inner_blocks_by_path_and_the_subsystems_files(toy):
    proc = cli("run", "top.yaml", "-o", "out", "--set", "ctrl.prop.k=4", "--t-end", "20 ms", cwd=toy.parent)
    assert proc.returncode == 0, proc.stderr
    info = json.loads((toy.parent / "out" / "run.json").read_text())
    assert info["parameters"]["ctrl.prop"] == {"k": 4}
    assert info["block_types"]["ctrl.integ"] == "DiscreteStateSpace"
    assert info["subsystems"] == {"ctrl": {"diagram": "lib/pi.yaml", "name": "pi", "params": {"prop.k": 4}}}
    results = blocks.Results.load(toy.parent / "out")
    assert set(results) == {"plant.y", "ctrl.integ.y"}


def test_a_subsystem_inside_a_subsystem(tmp_path):
    outer = """\
name: outer-pi
blocks:
  pre: {type: Gain, params: {k: 1.0}}
  pi:  {diagram: pi.yaml}
connections: [pre.y -> pi.e]
inputs: {e: pre.u}
outputs: {u: pi.u}
"""
    top = TOP.replace("lib/pi.yaml", "lib/outer.yaml")
    path = write(tmp_path, {"top.yaml": top, "lib/outer.yaml": outer, "lib/pi.yaml": PI})
    d = load_diagram(path, overrides={"ctrl.pi.prop.k": 5.0})
    assert list(d.blocks) == ["ref", "err", "plant", "ctrl.pre", "ctrl.pi.integ", "ctrl.pi.prop", "ctrl.pi.u"]
    assert list(d.subsystems) == ["ctrl", "ctrl.pi"]
    assert set(d.files) == {"lib/outer.yaml", "lib/pi.yaml"}
    a, b = simulate(load_diagram(TOY), t_end="0.2 s"), simulate(d, t_end="0.2 s")
    assert np.array_equal(a["plant.y"][1], b["plant.y"][1]) and "ctrl.pi.integ.y" in b


def test_the_same_file_twice_is_two_subsystems(tmp_path):
    top = """\
time: {t_end: 20 ms}
blocks:
  src: {type: Step, period: 1 ms, params: {time: 0.0}}
  a:   {diagram: pi.yaml}
  b:   {diagram: pi.yaml, params: {prop.k: 1.0}}
connections: [src.y -> a.e, src.y -> b.e]
log: [a.u.y, b.u.y]
"""
    d = load_diagram(write(tmp_path, {"top.yaml": top, "pi.yaml": PI}))
    r = simulate(d)
    assert d.parameters()["a.prop"] == {"k": 5.0} and d.parameters()["b.prop"] == {"k": 1.0}
    assert not np.array_equal(r["a.u.y"][1], r["b.u.y"][1])
    assert {e.signal for e in d.log} == {"a.u.y", "b.u.y", "a.integ.y", "b.integ.y"}


# -- problems, each at its file and line -------------------------------------------------------


def test_wires_into_a_subsystem_go_through_its_ports(toy):
    text = TOP.replace("  - err.y -> ctrl.e\n", "  - err.y -> ctrl.f\n  - err.y -> ctrl.integ.u\n") \
              .replace("log: [plant.y]", "log: [plant.y, ctrl.u, ctrl.integ.yy, ctrl.nope.y]")
    toy.write_text(text)
    f = str(toy)
    assert problems(toy) == [
        f"{f}:12: connection 'err.y -> ctrl.f': subsystem 'ctrl' (lib/pi.yaml) has no input 'f' "
        "(hint: inputs of 'ctrl': e)",
        f"{f}:13: connection 'err.y -> ctrl.integ.u': 'ctrl.integ.u' is not 'block.port' (hint: a connection "
        "reaches into subsystem 'ctrl' through its ports: inputs e; outputs u)",
        f"{f}:15: log entry 'ctrl.u': 'ctrl' is a subsystem (hint: log the signal its output 'u' comes from: "
        "ctrl.u.y)",
        f"{f}:15: log entry 'ctrl.integ.yy': block 'ctrl.integ' (DiscreteStateSpace) has no output 'yy' "
        "(hint: did you mean 'y'?)",
        f"{f}:15: log entry 'ctrl.nope.y': no block named 'ctrl.nope' (hint: did you mean 'ctrl.prop'?)"]


def test_a_problem_inside_a_subsystem_is_reported_in_its_file_under_the_block_path(toy):
    pi = toy.parent / "lib" / "pi.yaml"
    pi.write_text(PI.replace("period: 10 ms, params: {k: 5.0}", "period: -10 ms, params: {k: 5.0}")
                  .replace("outputs: {u: u.y}", "outputs: {u: u.yy}\nbogus: 1"))
    assert problems(toy) == [
        f"{pi}:13: unknown top-level key 'bogus' (hint: allowed keys: version, name, description, time, blocks, "
        "connections, inputs, outputs, references, log, units, elements)",
        f"{pi}:6: block 'ctrl.prop': period must be positive, got '-10 ms' (hint: write e.g. period: 1 ms; leave it "
        "out to inherit)",
        f"{pi}:12: diagram output 'u': block 'ctrl.u' (Sum) has no output 'yy' (hint: did you mean 'y'?)"]


def test_an_unconnected_subsystem_input_is_reported_at_its_entry(toy):
    toy.write_text(TOP.replace("  - err.y -> ctrl.e\n", ""))
    assert problems(toy) == [f"{toy}:8: input ctrl.e of subsystem 'ctrl' (lib/pi.yaml) is not connected "
                             "(hint: add a connection '- <block>.<port> -> ctrl.e')"]


def test_an_inner_input_fed_by_the_diagram_and_a_wire_is_driven_twice(toy):
    pi = toy.parent / "lib" / "pi.yaml"
    pi.write_text(PI.replace("  - prop.y -> u.u1\n", "  - prop.y -> u.u1\n  - u.y -> prop.u\n"))
    assert problems(toy) == [f"{pi}:12: input ctrl.prop.u is driven twice: by the diagram's input 'e' and by "
                             "ctrl.u.y (line 11) (hint: an input takes exactly one signal)"]


def test_widths_are_checked_across_the_boundary(toy):
    toy.write_text(TOP.replace("ref:   {type: Constant, params: {value: 1.0}}",
                               "ref:   {type: Constant, params: {value: [1.0, 2.0]}}"))
    issues = problems(toy)
    assert f"{toy}:12: connection 'err.y -> ctrl.e': width mismatch: err.y has width 2, ctrl.e (ctrl.integ.u) has " \
           "width 1 (hint: insert a Gain with a matrix k to map between widths, select elements (c.y[0:2] -> g.u), " \
           "or fix the block parameters)" in issues


def test_a_loop_through_a_subsystem_names_the_inner_port_chain(toy):
    toy.write_text(TOP.replace("  plant: {type: DiscreteStateSpace", "  plant: {type: DiscreteStateSpace")
                   .replace("  - ctrl.u -> plant.u\n", "  - ctrl.u -> err.u1\n  - plant.y -> plant.u\n")
                   .replace("  - plant.y -> err.u1\n", ""))
    with pytest.raises(DiagramError) as info:
        load_diagram(toy)
    assert str(info.value) == (f"{toy}:11: algebraic loop: err.y -> ctrl.prop.u -> ctrl.prop.y -> ctrl.u.u1 -> "
                               "ctrl.u.y -> err.u1 -> err.y (hint: break it with a block without feedthrough (e.g. "
                               "UnitDelay) or add 'delay: 1' to one connection)")


def test_overrides_and_entry_params_that_name_nothing(toy):
    toy.write_text(TOP.replace("{diagram: lib/pi.yaml}", "{diagram: lib/pi.yaml, params: {prx.k: 1, prop.kk: 2}}"))
    assert problems(toy, overrides={"ctrl.integ.Z": 1, "ctrl.x": 2}) == [
        f"{toy}:8: no block named 'ctrl.prx' (hint: did you mean 'ctrl.prop'?)",
        "--set ctrl.x=2: no block named 'ctrl.x' (hint: did you mean 'ctrl.u'?)",
        "--set ctrl.integ.Z=1: block 'ctrl.integ' (DiscreteStateSpace) has no parameter 'Z' (hint: parameters: A, "
        "B, C, D, x0, method)",
        f"{toy}:8: block 'ctrl.prop' (Gain) has no parameter 'kk' (hint: did you mean 'k'?)"]


def test_a_subsystem_file_that_is_missing_outside_or_not_a_diagram(tmp_path):
    top = """\
blocks:
  a: {diagram: missing.yaml}
  b: {diagram: ../outside.yaml}
  c: {diagram: broken.yaml}
  d: {diagram: binary.yaml}
  e: {diagram: 3}
"""
    path = write(tmp_path / "d", {"top.yaml": top, "broken.yaml": "blocks:\n  g: {type: Gain\n",
                                  "../outside.yaml": PI})
    (tmp_path / "d" / "binary.yaml").write_bytes(b"blocks:\n  g: {type: Gain}\x00\n")
    base = tmp_path / "d"
    assert problems(path) == [
        f"{path}:6: subsystem 'e': 'diagram' must be the path of a diagram file (hint: ctrl: {{diagram: pi.yaml}})",
        f"{path}:2: subsystem 'a': diagram 'missing.yaml' not found (looked at {base / 'missing.yaml'}) (hint: a "
        "subsystem's diagram is relative to the including diagram's folder)",
        f"{path}:3: subsystem 'b': diagram '../outside.yaml' is outside the diagram's folder (hint: a diagram reads "
        "files only from its own folder and below; pass --trust (Python: trust=True) if you trust this diagram)",
        f"{base / 'broken.yaml'}:3: YAML syntax error: did not find expected ',' or '}}' (hint: check indentation, "
        "colons and brackets near that line)",
        f"{base / 'binary.yaml'}:2: NUL byte at column 18: a binary file, not YAML text (hint: save the file as UTF-8 "
        "text)"]
    trusted = [i for i in problems(path, trust=True) if "'b'" in i or "outside" in i]
    assert trusted == []


def test_a_file_that_includes_itself_is_refused_with_the_chain(tmp_path):
    path = write(tmp_path, {"self.yaml": "blocks:\n  me: {diagram: self.yaml}\n"})
    assert problems(path) == [f"{path}:2: subsystem 'me': {path} includes itself: {path} -> {path} (hint: a diagram "
                              "cannot contain itself; remove the subsystem that closes the chain)"]
    a = write(tmp_path, {"a.yaml": "blocks:\n  s: {type: Step, period: 1 ms, params: {time: 0}}\n"
                                   "  b: {diagram: b.yaml}\nconnections: [s.y -> b.x]\n",
                         "b.yaml": "blocks:\n  g: {type: Gain, params: {k: 1}}\n  c: {diagram: sub/c.yaml}\n"
                                   "inputs: {x: g.u}\n",
                         "sub/c.yaml": "blocks:\n  back: {diagram: ../a.yaml}\n"})
    c = tmp_path / "sub" / "c.yaml"
    assert problems(a, trust=True) == [
        f"{c}:2: subsystem 'b.c.back': {a} includes itself: {a} -> {tmp_path / 'b.yaml'} -> {c} -> {a} (hint: a "
        "diagram cannot contain itself; remove the subsystem that closes the chain)"]


def test_the_input_limits_hold_for_every_file(tmp_path, monkeypatch):
    import blocks.limits
    import blocks.builder.scopes
    import blocks.diagram_file.yaml_source  # the limits are read where they are used

    chain = {f"d{i}.yaml": f"blocks:\n  next: {{diagram: d{i + 1}.yaml}}\n" for i in range(40)}
    chain["d40.yaml"] = "blocks:\n  g: {type: Constant}\n"
    path = write(tmp_path / "chain", chain)
    issues = problems(path)
    assert len(issues) == 1 and f"d{blocks.limits.MAX_SUBSYSTEM_DEPTH}.yaml:2: subsystem '" in issues[0]
    assert issues[0].endswith(f"subsystems nested deeper than {blocks.limits.MAX_SUBSYSTEM_DEPTH} levels (hint: the "
                              "limit guards against hostile chains of files)")
    doubling = {f"x{i}.yaml": f"blocks:\n  a: {{diagram: x{i + 1}.yaml}}\n  b: {{diagram: x{i + 1}.yaml}}\n"
                for i in range(12)}
    doubling["x12.yaml"] = "blocks:\n  g: {type: Constant}\n"
    monkeypatch.setattr(blocks.builder.scopes, "MAX_SUBSYSTEM_BLOCKS", 1000)
    path = write(tmp_path / "doubling", doubling)
    issues = problems(path)
    assert issues == [f"{path}:2: the subsystems add more than 1000 blocks (hint: the limit guards against files "
                      "that include each other many times over)"]
    monkeypatch.setattr(blocks.diagram_file.yaml_source, "MAX_YAML_BYTES", 100)
    path = write(tmp_path / "big", {"top.yaml": "blocks:\n  s: {diagram: big.yaml}\n",
                                    "big.yaml": "blocks:\n" + "".join(f"  g{i}: {{type: Constant}}\n" for i in range(9))})
    assert problems(path) == [f"{path}:2: subsystem 's': diagram 'big.yaml': file larger than 100 bytes (hint: the "
                              "limit guards against hostile files; keep large data out of YAML)"]


# -- block references into a subsystem ---------------------------------------------------------

MODEL_SUB = """\
name: scaled
references: [model]
blocks:
  use: {type: "python:tests.blocks.blockdefs:ScaleByModel", params: {source: model}}
inputs: {u: use.u}
outputs: {y: use.y}
log: [use.y]
"""

BINDS = """\
name: binds
time: {t_end: 3 ms}
blocks:
  src: {type: Step, period: 1 ms, params: {time: 0.0}}
  m:   {type: "python:tests.blocks.blockdefs:Model", params: {value: 2.0}}
  ok:  {diagram: scaled.yaml, bind: {model: m}}
connections: [src.y -> ok.u]
"""


def test_a_reference_inside_a_subsystem_is_bound_by_the_including_entry(tmp_path):
    path = write(tmp_path, {"binds.yaml": BINDS, "scaled.yaml": MODEL_SUB})
    d = load_diagram(path, trust=True, overrides={"m.value": 3.0})
    assert [str(r) for r in d.references()] == ["ok.use.source -> m"]
    assert d.blocks["ok.use"].block.source is d.blocks["m"].block
    assert d.subsystems["ok"].bindings == {"model": "m"} and d.parameters()["ok.use"]["source"] == "model"
    assert simulate(d)["ok.use.y"][1].ravel().tolist() == [3.0] * 4


def test_bindings_that_are_missing_or_wrong(tmp_path):
    text = BINDS.replace("connections: [src.y -> ok.u]", """\
  none: {diagram: scaled.yaml}
  wrong: {diagram: scaled.yaml, bind: {model: mm, extra: m}}
  kind: {diagram: scaled.yaml, bind: {model: src}}
  sub: {diagram: scaled.yaml, bind: {model: ok}}
connections: [src.y -> ok.u, src.y -> none.u, src.y -> wrong.u, src.y -> kind.u, src.y -> sub.u]""")
    path = write(tmp_path, {"binds.yaml": text, "scaled.yaml": MODEL_SUB})
    scaled = tmp_path / "scaled.yaml"
    assert problems(path, trust=True) == [
        f"{path}:7: subsystem 'none' (scaled.yaml) needs its reference 'model' bound to a block of this diagram "
        "(hint: add bind: {model: <block>} to the entry 'none')",
        f"{path}:8: subsystem 'wrong' (scaled.yaml) declares no reference 'extra' (hint: its references are: model)",
        f"{path}:8: subsystem 'wrong' (scaled.yaml): bind model: no block named 'mm' (hint: did you mean 'm'?)",
        f"{path}:10: subsystem 'sub' (scaled.yaml): bind model: 'ok' is a subsystem, not a block (hint: a reference "
        "names a block)",
        f"{scaled}:4: block 'kind.use' (python:tests.blocks.blockdefs:ScaleByModel): parameter 'source' must be a "
        "Model block, got Step (hint: see 'hierhand blocks ScaleByModel' for its parameters)"]


def test_a_diagram_with_references_alone_needs_a_stand_in(tmp_path):
    write(tmp_path, {"scaled.yaml": MODEL_SUB})
    scaled = tmp_path / "scaled.yaml"
    assert problems(scaled, trust=True) == [
        f"{scaled}:4: block 'use': parameter 'source' names 'model', a reference that an including diagram binds, "
        "and this diagram is loaded on its own (hint: load it as a subsystem (bind: {model: <block>}), or name a "
        "stand-in type: references: {model: <type>})"]
    scaled.write_text(MODEL_SUB.replace("references: [model]",
                                        "references: {model: 'python:tests.blocks.blockdefs:Model'}"))
    d = load_diagram(scaled, trust=True)
    assert d.root.references["model"].type_name == "python:tests.blocks.blockdefs:Model"
    assert d.blocks["use"].references == {"source": "model"}
    assert "block references (model)" in d.open_issue().message


def test_a_reference_passed_on_to_a_nested_subsystem(tmp_path):
    middle = """\
references: [plant]
blocks:
  inner: {diagram: scaled.yaml, bind: {model: plant}}
inputs: {u: inner.u}
outputs: {y: inner.y}
"""
    top = BINDS.replace("{diagram: scaled.yaml, bind: {model: m}}", "{diagram: middle.yaml, bind: {plant: m}}")
    d = load_diagram(write(tmp_path, {"top.yaml": top, "middle.yaml": middle, "scaled.yaml": MODEL_SUB}), trust=True)
    assert [str(r) for r in d.references()] == ["ok.inner.use.source -> m"]
    assert simulate(d)["ok.inner.use.y"][1][-1, 0] == 2.0


# -- commands ----------------------------------------------------------------------------------


def cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH")) if p))
    return subprocess.run([sys.executable, "-m", "blocks", *args], capture_output=True, text=True, cwd=cwd, env=env,
                          timeout=120)


def test_validate_shows_the_subsystems_as_a_tree(toy):
    proc = cli("validate", "top.yaml", "--set", "ctrl.prop.k=2", cwd=toy.parent)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    start = lines.index("blocks:")
    assert lines[start + 4] == ("  ctrl: subsystem lib/pi.yaml (diagram 'pi'); in: e[1] -> integ.u, prop.u; "
                                "out: u[1] <- u.y; params: prop.k=2")
    assert lines[start + 5].startswith("    ctrl.integ  DiscreteStateSpace  1 ms")
    proc = cli("validate", "lib/pi.yaml", cwd=toy.parent)
    assert proc.returncode == 0, proc.stderr
    assert "inputs (of the diagram as a subsystem):\n  e[1] -> integ.u, prop.u\n" in proc.stdout
    assert "outputs (of the diagram as a subsystem):\n  u[1] <- u.y\n" in proc.stdout


def test_graph_draws_a_subsystem_as_one_box_or_expanded_as_a_frame(toy):
    from blocks.graph import draw, to_dot

    d = load_diagram(toy)
    s = blocks.build_schedule(d, None)
    dot = to_dot(d, s)
    assert '"ctrl" [label="{{<in_e> e}|ctrl\\nsubsystem lib/pi.yaml\\n1 ms, 10 ms|{<out_u> u}}"' in dot
    assert '"err":out_y:e -> "ctrl":in_e:w' in dot and "ctrl.integ" not in dot
    expanded = to_dot(d, s, expand=True)
    assert 'subgraph "cluster_ctrl" {' in expanded and '"err":out_y:e -> "ctrl.prop":in_u:w' in expanded
    fig = draw(d, s, expand=True)
    gids = {p.get_gid() for p in fig.axes[0].patches}
    assert {"frame:ctrl", "block:ctrl.integ", "block:ctrl.u"} <= gids
    frame = next(p for p in fig.axes[0].patches if p.get_gid() == "frame:ctrl").get_bbox()
    for patch in fig.axes[0].patches:
        gid = patch.get_gid() or ""
        if gid.startswith("block:"):
            box = patch.get_bbox()
            inside = frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
            assert inside == gid.startswith("block:ctrl."), gid
    collapsed = draw(d, s)
    assert "block:ctrl" in {p.get_gid() for p in collapsed.axes[0].patches}
    proc = cli("graph", "top.yaml", "--expand", "-o", "wiring.svg", cwd=toy.parent)
    assert proc.returncode == 0 and b"frame:ctrl" in (toy.parent / "wiring.svg").read_bytes()


# -- sweeps ------------------------------------------------------------------------------------


def test_a_sweep_sets_parameters_inside_a_subsystem_and_ships_its_files(tmp_path, monkeypatch):
    lib = PI.replace("prop:  {type: Gain, period: 10 ms, params: {k: 5.0}}",
                     "prop:  {type: Gain, period: 10 ms, params_file: gains/prop.yaml}")
    path = write(tmp_path / "proj", {"top.yaml": TOP, "lib/pi.yaml": lib, "lib/gains/prop.yaml": "k: 5.0\n"})
    assert set(load_diagram(path).files) == {"lib/pi.yaml", "lib/gains/prop.yaml"}
    points = grid_points({"ctrl.prop.k": [1.0, 2.0]})
    metrics = parse_metrics(["y=final(plant.y)", "i=final(ctrl.integ.y)"])
    plan = prepare(path, points, metrics, t_end="0.1 s")
    assert {f.ref: f.name for f in plan.job.bundle.files} == {"lib/pi.yaml": "tree/lib/pi.yaml",
                                                              "lib/gains/prop.yaml": "tree/lib/gains/prop.yaml"}
    expected = {k: simulate(load_diagram(TOY, overrides={"prop.k": k}), t_end="0.1 s")["plant.y"][1][-1, 0]
                for k in (1.0, 2.0)}
    shutil.rmtree(tmp_path / "proj")  # the points read the bundle, not the client's files
    monkeypatch.chdir(tmp_path)
    report, skipped, failed = execute(plan, tmp_path / "out", serial=True, progress=False)
    assert (report.ran, failed) == (2, 0)
    with open(tmp_path / "out" / "sweep.csv", newline="") as f:
        rows = {float(r["ctrl.prop.k"]): r for r in csv.DictReader(f)}
    assert {k: float(r["y"]) for k, r in rows.items()} == expected


def test_a_sweep_refuses_a_point_that_names_nothing_inside(toy, tmp_path):
    with pytest.raises(DiagramError) as info:
        run_sweep(toy, grid_points({"ctrl.prp.k": [1.0]}), ["y=final(plant.y)"], tmp_path / "s", serial=True,
                  progress=False)
    assert [str(i) for i in info.value.issues] == [
        "--set ctrl.prp.k=1.0: no block named 'ctrl.prp' (hint: did you mean 'ctrl.prop'?)"]


def test_a_composed_diagram_saved_as_yaml_loads_to_the_same_diagram(toy, tmp_path):
    d = load_diagram(toy, overrides={"ctrl.prop.k": 2.0})
    again = load_diagram(blocks.save_diagram(d, toy.parent / "saved.yaml"))
    assert structure(again) == structure(d)
    assert again.subsystems["ctrl"].params == {"prop.k": 2.0}
