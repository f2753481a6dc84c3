"""``DiagramBuilder``: a diagram made in Python is the diagram its YAML makes, is checked by
the same code (with the file:line of the Python call that caused a problem), and is
written back as YAML (``save_diagram``) that loads to the same diagram."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import blocks
from blocks import DiagramBuilder, DiagramError, WriteError, dump_diagram, load_diagram, save_diagram, simulate
from blocks.library import Gain, Step

from ..blockdefs import Model, ScaleByModel

ROOT = Path(__file__).resolve().parents[3]
TOY = ROOT / "diagrams" / "toy.yaml"
HERE = __file__


def structure(d: blocks.Diagram) -> dict:
    """What makes two diagrams the same diagram: blocks (type, timing, parameters, ports),
    connections, logged signals, end time and the diagram's own ports."""
    return {
        "name": d.name, "t_end": d.t_end,
        "blocks": [(n, s.type_name, s.period, s.offset, blocks.builder.diagram.jsonable(s.params), dict(s.block.inputs),
                    dict(s.block.outputs), s.references) for n, s in d.blocks.items()],
        "connections": sorted((c.src, c.dst, c.delay, c.initial) for c in d.connections),
        "log": [(e.signal, e.decimate) for e in d.log],
        "inputs": {n: (p.signals, p.width) for n, p in d.inputs.items()},
        "outputs": {n: (p.signals, p.width) for n, p in d.outputs.items()},
    }


def same_results(a: blocks.Results, b: blocks.Results, rename=lambda s: s) -> None:
    assert {rename(s) for s in a} == set(b)
    for signal in a:
        (ta, va), (tb, vb) = a[signal], b[rename(signal)]
        assert np.array_equal(ta, tb) and np.array_equal(va, vb), signal


def toy_in_code(prop_instance: bool = True) -> DiagramBuilder:
    """diagrams/toy.yaml said in Python, its blocks given in each way the builder takes
    (by name, by class, as an instance when ``prop_instance``)."""
    b = DiagramBuilder("toy-multirate", "discrete plant with a fast integral and a slow proportional controller",
                       t_end="1 s")
    b.add("ref", "Constant", params={"value": 1.0})
    b.add("err", "Sum", params={"signs": "+-"})
    b.add("plant", "DiscreteStateSpace", period="0.1 ms",
          params={"A": [[0.999]], "B": [[1.0e-4]], "C": [[1.0]], "D": [[0.0]]})
    b.add("integ", "DiscreteStateSpace", period="1 ms",
          params={"A": [[1.0]], "B": [[0.02]], "C": [[1.0]], "D": [[0.0]]})
    if prop_instance:
        b.add("prop", Gain(k=5.0), period=Fraction(1, 100))
    else:
        b.add("prop", "Gain", period="10 ms", params={"k": 5.0})
    b.add("u", blocks.library.Sum, params={"signs": "++"})
    for src, dst in [("ref.y", "err.u0"), ("plant.y", "err.u1"), ("err.y", "integ.u"), ("err.y", "prop.u"),
                     ("integ.y", "u.u0"), ("prop.y", "u.u1"), ("u.y", "plant.u")]:
        b.connect(src, dst)
    b.log("plant.y")
    return b


def test_a_diagram_built_in_code_is_the_diagram_of_its_yaml():
    built, loaded = toy_in_code().build(), load_diagram(TOY)
    assert structure(built) == structure(loaded)
    same_results(simulate(loaded), simulate(built))


def test_the_builder_and_the_yaml_front_end_take_the_same_overrides():
    over = {"prop.k": 2.5, "plant.A": [[0.99]]}
    assert structure(toy_in_code(prop_instance=False).build(over)) == structure(load_diagram(TOY, overrides=over))


def test_a_block_instance_records_its_constructor_arguments():
    assert Gain(2.0).constructor_arguments() == {"k": 2.0}
    assert Step(0.5, after=2.0).constructor_arguments() == {"time": 0.5, "after": 2.0}
    b = DiagramBuilder("inst", t_end="3 ms")
    b.add("src", Step(time=0.0), period="1 ms")
    b.add("g", Gain(k=3.0))
    b.connect("src.y", "g.u")
    b.log("g.y")
    d = b.build()
    assert d.parameters() == {"src": {"time": 0.0}, "g": {"k": 3.0}}
    assert d.blocks["g"].block.name == "g"
    assert simulate(d)["g.y"][1][-1, 0] == 3.0


def lines_of(*needles: str) -> list[int]:
    text = Path(HERE).read_text().splitlines()
    return [next(i for i, line in enumerate(text, start=1) if needle in line) for needle in needles]


def test_a_problem_is_reported_at_the_line_of_the_python_call_that_caused_it():
    b = DiagramBuilder("bad")
    b.add("src", "Stepp", period="1 ms")  # the type
    b.add("g", "Gain", period="-1 ms")  # the period
    b.add("h", "Gain", params={"kk": 1})  # the parameter
    b.add("k", "Gain", params={"k": 1.0})
    b.connect("k.y", "k.uu")  # the port
    b.add("g", "Gain")  # twice
    with pytest.raises(DiagramError) as info:
        b.build()
    lines = lines_of("# the type", "# the period", "# the parameter", "# the port", "# twice")
    got = [(i.file, i.line, i.message) for i in info.value.issues]
    assert got == [
        (HERE, lines[4], f"block 'g' is added twice (first at {HERE}:{lines[1]})"),
        (HERE, lines[0], "block 'src': unknown block type 'Stepp'"),
        (HERE, lines[1], "block 'g': period must be positive, got '-1 ms'"),
        (HERE, lines[2], "block 'h' (Gain) has no parameter 'kk'"),
        (HERE, lines[3], "connection 'k.y -> k.uu': block 'k' (Gain) has no input 'uu'"),
    ]
    assert info.value.issues[1].hint == "did you mean 'Step', 'Stop'?"


def test_an_override_of_a_built_diagram_says_how_it_was_given():
    with pytest.raises(DiagramError) as info:
        toy_in_code().build({"plant.AA": 1, "nope.k": 2})
    assert [str(i) for i in info.value.issues] == [
        "--set nope.k=2: no block named 'nope' (hint: blocks are: ref, err, plant, integ, prop, u)",
        "--set plant.AA=1: block 'plant' (DiscreteStateSpace) has no parameter 'AA' (hint: did you mean 'A'?)"]


def test_block_references_by_name_or_by_the_block_itself():
    b = DiagramBuilder("refs", t_end="2 ms")
    model = Model(value=4.0)
    b.add("src", "Step", period="1 ms", params={"time": 0.0})
    b.add("model", model)
    b.add("by_name", ScaleByModel, params={"source": "model"})
    b.add("by_block", ScaleByModel, params={"source": model})
    b.add("instance", ScaleByModel(source=model))
    for name in ("by_name", "by_block", "instance"):
        b.connect("src.y", f"{name}.u")
        b.log(f"{name}.y")
    d = b.build()
    assert {str(r) for r in d.references()} == {"by_name.source -> model", "by_block.source -> model",
                                                 "instance.source -> model"}
    assert d.parameters()["by_block"]["source"] == d.parameters()["instance"]["source"] == "model"
    r = simulate(d)
    assert r["by_name.y"][1][-1, 0] == r["by_block.y"][1][-1, 0] == r["instance.y"][1][-1, 0] == 4.0


def test_what_a_block_instance_cannot_do():
    gain = Gain(k=2.0)
    b = DiagramBuilder("inst")
    b.add("src", "Step", period="1 ms", params={"time": 0.0})
    b.add("g", gain, params={"k": 3.0})  # params
    b.add("twice", gain)
    b.add("outside", ScaleByModel(source=Model()))  # not in the diagram
    b.connect("src.y", "g.u")
    with pytest.raises(DiagramError) as info:
        b.build()
    messages = [i.message for i in info.value.issues]
    assert "block 'twice' is the Block instance already placed as 'g'" in messages
    assert "block 'g' is a Block instance; it takes no params" in messages
    assert "block 'outside': parameter 'source' is a block that is not in this diagram" in messages
    b = DiagramBuilder("inst", t_end="1 ms")
    b.add("src", Step(time=0.0), period="1 ms")
    with pytest.raises(DiagramError) as info:
        b.build({"src.time": 1.0})
    assert [str(i) for i in info.value.issues] == [
        "--set src.time=1.0: block 'src' (Step) was added as a Block instance; its parameters cannot be "
        "overridden (hint: add it by type to override its parameters)"]


def test_an_untrusted_builder_names_no_python_code():
    b = DiagramBuilder("t", trust=False)
    b.add("m", "python:tests.blocks.blockdefs:Model")
    with pytest.raises(DiagramError, match="imports Python code from the diagram"):
        b.build()


# -- written back as YAML ------------------------------------------------------------------------


def test_a_diagram_built_in_code_saved_as_yaml_loads_to_the_same_diagram(tmp_path):
    d = toy_in_code().build()
    path = save_diagram(d, tmp_path / "toy.yaml")
    again = load_diagram(path)
    assert structure(again) == structure(d)
    same_results(simulate(d), simulate(again))
    assert dump_diagram(again) == path.read_text()


def test_every_shipped_diagram_saved_elsewhere_loads_to_the_same_diagram(tmp_path):
    for path in sorted((ROOT / "diagrams").glob("*.yaml")):
        if path.name == "regrasp_fmu.yaml":
            continue  # its FMU is exported by the FMU tests; the path parameter is checked below
        d = load_diagram(path)
        again = load_diagram(save_diagram(d, tmp_path / path.name))
        assert structure(again) == structure(d), path.name
    # a subsystem file the new folder cannot reach is written beside the diagram
    assert load_diagram(tmp_path / "regrasp.ctrl.yaml").inputs.keys() == load_diagram(ROOT / "diagrams" /
                                                                                     "controller.yaml").inputs.keys()


def test_a_path_parameter_is_written_from_the_new_file(tmp_path):
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "gains.yaml").write_text("k: 4.0\n")
    text = "blocks:\n  g: {type: Gain, params_file: lib/gains.yaml}\n  s: {type: Step, period: 1 ms, params: {time: 0}}\n" \
           "connections: [s.y -> g.u]\n"
    d = blocks.loads_diagram(text, filename=str(tmp_path / "d.yaml"), base_dir=tmp_path)
    out = dump_diagram(d, tmp_path / "elsewhere")
    assert "params: {k: 4.0}" in out and "params_file" not in out


def test_a_subsystem_built_in_code_is_saved_beside_the_diagram(tmp_path):
    inner = DiagramBuilder("doubler")
    inner.add("g", Gain(k=2.0), period="1 ms")
    inner.input("x", "g.u")
    inner.output("y", "g.y")
    inner.log("g.y")
    b = DiagramBuilder("outer", t_end="5 ms")
    b.add("src", "Ramp", period="1 ms", params={"slope": 1.0})
    b.add_subsystem("two", inner)
    b.connect("src.y", "two.x")
    d = b.build()
    assert list(d.blocks) == ["src", "two.g"] and d.subsystems["two"].origin == "built in Python"
    with pytest.raises(WriteError, match="subsystem 'two' was built in Python"):
        dump_diagram(d)
    path = save_diagram(d, tmp_path / "outer.yaml")
    assert (tmp_path / "outer.two.yaml").is_file()
    again = load_diagram(path)
    assert structure(again) == structure(d)
    same_results(simulate(d), simulate(again))


def test_what_yaml_cannot_hold_is_refused():
    b = DiagramBuilder("odd", t_end="1 s")
    b.add("g", Gain(k=1.0), period=Fraction(1, 3))
    b.add("s", Step(time=0.0), period=Fraction(1, 3))
    b.connect("s.y", "g.u")
    with pytest.raises(WriteError, match="block 'g' period: the duration 1/3 s is not a decimal number"):
        dump_diagram(b.build())
    b = DiagramBuilder("odd")
    b.add("m", Model(value=np.float64(2.0)))
    assert "value: 2.0" in dump_diagram(b.build())
    b = DiagramBuilder("odd")
    b.add("g", Gain(k=Fraction(1, 2)))
    b.add("s", "Step", period="1 ms", params={"time": 0.0})
    b.connect("s.y", "g.u")
    with pytest.raises(WriteError, match="block 'g' parameter 'k' is a Fraction, which a YAML diagram cannot hold"):
        dump_diagram(b.build())


def test_a_diagram_file_read_into_a_builder_is_a_subsystem_from_python(tmp_path):
    (tmp_path / "double.yaml").write_text("blocks:\n  g: {type: Gain, params: {k: 2.0}}\n"
                                          "inputs: {x: g.u}\noutputs: {y: g.y}\n")
    b = DiagramBuilder("outer", t_end="3 ms")
    b.add("src", "Step", period="1 ms", params={"time": 0.0})
    b.add_subsystem("d", blocks.read_builder(tmp_path / "double.yaml"), params={"g.k": 5.0})
    b.connect("src.y", "d.x")
    b.log("d.g.y")
    d = b.build()
    assert list(d.files.values()) == [tmp_path / "double.yaml"]
    assert simulate(d)["d.g.y"][1][-1, 0] == 5.0
    assert d.subsystems["d"].file == str(tmp_path / "double.yaml")


def gain_from_file(folder: Path, params_file: str, **options) -> tuple[DiagramBuilder, list[blocks.Issue]]:
    """A builder of a Gain whose parameters are in ``params_file``, and the issues of its build."""
    b = DiagramBuilder("p", base_dir=folder, **options)
    b.add("c", "Constant", params={"value": 1.0})
    b.add("g", "Gain", period="1 ms", params_file=params_file)
    b.connect("c.y", "g.u")
    with pytest.raises(DiagramError) as info:
        b.build()
    return b, info.value.issues


def test_a_params_file_named_in_python_is_read_as_a_diagram_files_and_its_problems_are_at_its_lines(tmp_path):
    (tmp_path / "gains.yaml").write_text("k: 3.0\n\nkk: 1.0\n")
    b, [issue] = gain_from_file(tmp_path, "gains.yaml")
    assert (issue.file, issue.line) == (str(tmp_path / "gains.yaml"), 3)
    (tmp_path / "gains.yaml").write_text("k: 3.0\n")
    assert b.build().blocks["g"].params == {"k": 3.0}


class JsonParams:
    """A front end's reader of params files in another format (JSON, one parameter a line):
    the builder reports a problem at the line this reader says its parameter is on."""

    def __init__(self, lines: dict[str, int]):
        self.lines = lines

    def line_at(self, path):
        return (self.lines[path[0]], 1) if path and path[0] in self.lines else (None, 0)

    def __call__(self, path: Path):
        import json

        from blocks.builder.records import ParamsText, SourceError

        text = path.read_text()
        try:
            params = json.loads(text)
        except json.JSONDecodeError as exc:
            raise SourceError(f"not JSON: {exc.msg}", exc.lineno) from None
        return ParamsText(text, params, JsonParams({k: i for i, line in enumerate(text.splitlines(), 1)
                                                    for k in params if f'"{k}"' in line}))


def test_the_builder_reads_params_files_with_the_reader_its_front_end_gives_it(tmp_path):
    """It knows no file format: a reader of JSON gives it the parameters and their lines."""
    (tmp_path / "gains.json").write_text('{\n "k": 4.0,\n "kk": 1.0\n}\n')
    b, [issue] = gain_from_file(tmp_path, "gains.json", read_params=JsonParams({}))
    assert (issue.file, issue.line, issue.hint) == (str(tmp_path / "gains.json"), 3, "did you mean 'k'?")
    (tmp_path / "gains.json").write_text('{\n "k": 4.0,\n')
    with pytest.raises(DiagramError) as info:
        b.build()
    assert [(i.file, i.line) for i in info.value.issues] == [(str(tmp_path / "gains.json"), 3)]
    (tmp_path / "gains.json").write_text('{"k": 4.0}')
    assert b.build().blocks["g"].params == {"k": 4.0}
