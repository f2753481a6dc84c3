"""Block references (``Block.block_params``): a parameter that names another block of the diagram.

The loader builds the referenced block first and hands the block object to the one that
refers to it; the diagram's parameters keep the name. Bad references are one line each,
``file:line: message (hint: ...)``, seen here through the real command line.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from blocks import DiagramError, loads_diagram, simulate
from blocks.builder.references import Reference, build_order, chain_text

ROOT = Path(__file__).resolve().parents[3]
DEFS = "python:tests.blocks.blockdefs"

# 'use' refers to 'model', which comes after it in the file.
TEXT = f"""\
name: refs
time:
  t_end: 3 ms
blocks:
  use:
    type: {DEFS}:ScaleByModel
    params:
      source: model
  model:
    type: {DEFS}:Model
    params:
      value: 2.0
  other:
    type: {DEFS}:Model
    params:
      value: 5.0
  src:
    type: Step
    period: 1 ms
    params:
      time: 0.0
connections:
  - src.y -> use.u
log:
  - use.y
"""


def load(text: str = TEXT, **overrides):
    return loads_diagram(text, filename="refs.yaml", trust=True, overrides=overrides)


def line_with(text: str, needle: str) -> int:
    found = [i for i, line in enumerate(text.splitlines(), start=1) if needle in line]
    assert len(found) == 1, f"test setup: {needle!r} on lines {found}"
    return found[0]


def hierhand(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH")) if p))
    return subprocess.run([sys.executable, "-m", "hierhand", *args], capture_output=True, text=True, cwd=cwd,
                          env=env, timeout=120)


# -- what a reference does ---------------------------------------------------------------------


def test_the_referenced_block_is_built_first_and_passed_as_the_block_itself():
    d = load()
    use, model = d.blocks["use"].block, d.blocks["model"].block
    assert use.source is model
    assert use.spare is None
    assert (use.name, model.name) == ("use", "model")
    assert list(d.blocks) == ["use", "model", "other", "src"]  # file order kept
    assert d.blocks["use"].references == {"source": "model"}
    assert d.blocks["model"].references == {}
    assert d.parameters()["use"] == {"source": "model"}


def test_the_run_uses_the_referenced_block_and_run_json_keeps_its_name(tmp_path):
    results = simulate(load())
    np.testing.assert_array_equal(results["use.y"][1][:, 0], [2.0, 2.0, 2.0, 2.0])
    results.save(tmp_path / "run")
    assert type(results).load(tmp_path / "run").info["parameters"]["use"]["source"] == "model"


def test_an_override_of_the_referenced_block_reaches_the_block_that_refers_to_it():
    d = load(**{"model.value": 3.0})
    assert d.blocks["use"].block.source.value == 3.0
    assert simulate(d)["use.y"][1][-1, 0] == 3.0


def test_a_reference_is_overridden_like_any_parameter():
    d = load(**{"use.source": "other"})
    assert d.blocks["use"].block.source is d.blocks["other"].block
    assert d.parameters()["use"]["source"] == "other"
    assert simulate(d)["use.y"][1][-1, 0] == 5.0


def test_references_chain_in_any_file_order():
    text = TEXT.replace("      source: model\n", "      source: model\n      spare: last\n").replace(
        "  src:\n", f"  last:\n    type: {DEFS}:ScaleByModel\n    params:\n      source: other\n  src:\n")
    text = text.replace("  - src.y -> use.u\n", "  - src.y -> use.u\n  - src.y -> last.u\n")
    d = load(text)
    assert d.blocks["use"].block.spare is d.blocks["last"].block
    assert d.blocks["last"].block.source is d.blocks["other"].block


def test_a_block_passed_from_python_needs_no_diagram():
    from tests.blocks.blockdefs import Model, ScaleByModel

    block = ScaleByModel(source=Model(4.0))
    assert block.output(0.0, None, {"u": np.array([0.5])})["y"][0] == 2.0
    assert block.name is None


# -- build order ---------------------------------------------------------------------------------


def test_build_order_puts_referenced_blocks_first_and_keeps_file_order_otherwise():
    order, cycles = build_order({"a": {"x": "c"}, "b": {}, "c": {"y": "d"}, "d": {}, "e": {"z": "nosuch"}})
    assert order == ["d", "c", "a", "b", "e"]
    assert cycles == []


def test_build_order_names_each_cycle_once_by_its_references():
    order, cycles = build_order({"a": {"hand": "b"}, "b": {"x": "a", "y": "a"}, "c": {"hand": "a"}})
    assert sorted(order) == ["a", "b", "c"]
    assert cycles == [[Reference("a", "hand", "b"), Reference("b", "x", "a")]]
    assert chain_text(cycles[0]) == "a.hand -> b, b.x -> a"


# -- errors ----------------------------------------------------------------------------------------


def bad(text: str, tmp_path: Path, *args: str) -> tuple[int, str]:
    """The one issue ``hierhand validate`` reports: (line, message)."""
    path = tmp_path / "refs.yaml"
    path.write_text(text, encoding="utf-8")
    proc = hierhand("validate", str(path), "--trust", *args, cwd=tmp_path)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    where, _, message = lines[0].partition(": ")
    if not args:
        assert where.startswith(f"{path}:"), lines[0]
        return int(where.rsplit(":", 1)[1]), message
    return 0, lines[0]


@pytest.mark.parametrize("value, names", [
    ("modle", ("block 'use'", "parameter 'source'", "no block 'modle'", "did you mean 'model'?")),
    ("use", ("block 'use'", "parameter 'source'", "refers to the block itself")),
    ("3", ("block 'use'", "parameter 'source'", "must be the name of a block", "got 3")),
    ("[model]", ("block 'use'", "parameter 'source'", "must be the name of a block", "got ['model']")),
], ids=["unknown-name", "itself", "a-number", "a-list"])
def test_a_bad_reference_is_one_line_at_its_value(value, names, tmp_path):
    text = TEXT.replace("      source: model\n", f"      source: {value}\n")
    line, message = bad(text, tmp_path)
    assert line == line_with(text, f"source: {value}")
    for name in names:
        assert name in message, message


def test_a_cycle_of_references_names_the_chain(tmp_path):
    text = TEXT.replace("      source: model\n", "      source: loop\n").replace(
        "  src:\n", f"  loop:\n    type: {DEFS}:ScaleByModel\n    params:\n      source: model\n"
                    "      spare: use\n  src:\n")
    line, message = bad(text, tmp_path)
    assert line == line_with(text, "source: loop")
    assert "block references form a cycle: use.source -> loop, loop.spare -> use" in message
    assert "(hint: " in message


def test_a_reference_to_a_block_that_failed_reports_only_that_block(tmp_path):
    text = TEXT.replace(f"type: {DEFS}:Model\n    params:\n      value: 2.0", "type: Gian")
    line, message = bad(text, tmp_path)
    assert line == line_with(text, "type: Gian")
    assert "Gian" in message


def test_a_bad_reference_from_set_names_the_set(tmp_path):
    _, message = bad(TEXT, tmp_path, "--set", "use.source=modle")
    assert message.startswith("--set use.source='modle': ")
    assert "no block 'modle'" in message and "did you mean 'model'?" in message


def test_a_missing_required_reference_is_a_missing_parameter():
    with pytest.raises(DiagramError, match=r"block 'use' \(ScaleByModel\) is missing parameter\(s\) source"):
        load(TEXT.replace("      source: model\n", "      offset: 1.0\n"))


# -- validate ----------------------------------------------------------------------------------------


def test_validate_lists_the_references_and_what_blocks_say_about_themselves(tmp_path):
    path = tmp_path / "refs.yaml"
    path.write_text(TEXT, encoding="utf-8")
    proc = hierhand("validate", str(path), "--trust", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert "references:\n  use.source -> model\n" in out
    assert "  model: value 2; referenced by use.source\n" in out
    assert "  other: value 5\n" in out


def test_blocks_marks_a_reference_parameter(tmp_path):
    from blocks.typeinfo import describe_type
    from tests.blocks.blockdefs import ScaleByModel

    text = describe_type(ScaleByModel)
    assert "source (required; the name of another block of the diagram)" in text
    assert "spare (default None; the name of another block of the diagram)" in text
    assert "ports: see 'hierhand validate' of a diagram using it (it needs the block named by source)" in text


def test_blocks_lists_the_ports_of_a_reference_block_from_its_example():
    from blocks.typeinfo import describe_type
    from tests.blocks.blockdefs import Model, ScaleByModel

    class Documented(ScaleByModel):
        @classmethod
        def example(cls):
            return cls(source=Model(value=2.0))

    text = describe_type(Documented)
    assert "inputs: u[1]" in text and "outputs: y[1]" in text and "see 'hierhand validate'" not in text
