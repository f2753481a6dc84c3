"""``python:module:Class`` types: the module is looked up beside the diagram first.

A module in the diagram's folder loads from any working directory without PYTHONPATH; it is
imported from its file under a name of its own, so two diagrams in different folders may each
have a module of the same name, and neither the folder nor the plain name is left on
``sys.path`` / in ``sys.modules`` to shadow anything.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import blocks
from blocks.issues import DiagramError

ROOT = Path(__file__).resolve().parents[3]

MODULE = '''\
from pathlib import Path

from blocks import Block

Path(__file__).with_name("imported.flag").write_text("imported")


class Scale(Block):
    """y = K u."""

    def __init__(self):
        self.inputs, self.outputs = {{"u": 1}}, {{"y": 1}}
        self.feedthrough = True

    def output(self, t, state, inputs):
        return {{"y": {k} * inputs["u"]}}
'''

DIAGRAM = """\
name: local-type
time: {{t_end: 2 ms}}
blocks:
  src: {{type: Constant, params: {{value: 1.0}}}}
  scale: {{type: "python:{module}:Scale", period: 1 ms}}
connections:
  - src.y -> scale.u
log: [scale.y]
"""


def make(folder: Path, k: float, module: str = "blocks_mine") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{module}.py").write_text(MODULE.format(k=k), encoding="utf-8")
    path = folder / "diagram.yaml"
    path.write_text(DIAGRAM.format(module=module), encoding="utf-8")
    return path


def env_without_folder() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT)
    return env


def cli(*args, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "hierhand", *map(str, args)], cwd=cwd,
                          env=env_without_folder(), capture_output=True, text=True, timeout=120)


def test_module_beside_the_diagram_loads_from_any_cwd(tmp_path: Path):
    diagram = make(tmp_path / "project" / "model", 3.0)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out = tmp_path / "out"
    proc = cli("run", diagram, "-o", out, "--trust", "-q", cwd=elsewhere)
    assert proc.returncode == 0, proc.stderr
    _, y = blocks.Results.load(out)["scale.y"]
    assert list(y[:, 0]) == [3.0, 3.0, 3.0]
    # relative to a cwd that is neither the diagram's folder nor on the path
    proc = cli("validate", "model/diagram.yaml", "--trust", cwd=tmp_path / "project")
    assert proc.returncode == 0, proc.stderr


def test_without_trust_the_module_beside_the_diagram_is_not_imported(tmp_path: Path):
    diagram = make(tmp_path / "model", 3.0)
    proc = cli("validate", diagram, cwd=tmp_path)
    assert proc.returncode == 2
    assert "--trust" in proc.stderr
    assert not (tmp_path / "model" / "imported.flag").exists()


def test_two_diagrams_with_modules_of_the_same_name_do_not_shadow_each_other(tmp_path: Path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path_before, modules_before = list(sys.path), set(sys.modules)
    first = blocks.load_diagram(make(tmp_path / "a", 2.0), trust=True)
    second = blocks.load_diagram(make(tmp_path / "b", 5.0), trust=True)
    y1 = blocks.simulate(first)["scale.y"][1][:, 0]
    y2 = blocks.simulate(second)["scale.y"][1][:, 0]
    assert list(y1) == [2.0] * 3 and list(y2) == [5.0] * 3
    assert sys.path == path_before
    assert "blocks_mine" not in sys.modules
    added = set(sys.modules) - modules_before
    assert len([m for m in added if m.endswith("_blocks_mine")]) == 2
    # loading the first again reuses its module; an edited file is imported afresh
    again = blocks.load_diagram(tmp_path / "a" / "diagram.yaml", trust=True)
    assert type(again.blocks["scale"].block) is type(first.blocks["scale"].block)
    (tmp_path / "a" / "blocks_mine.py").write_text(MODULE.format(k=7.0) + "\n# edited\n", encoding="utf-8")
    edited = blocks.load_diagram(tmp_path / "a" / "diagram.yaml", trust=True)
    assert list(blocks.simulate(edited)["scale.y"][1][:, 0]) == [7.0] * 3


def test_the_diagrams_folder_comes_before_the_python_path(tmp_path: Path, monkeypatch):
    # a module beside the diagram named like an importable one wins, for this diagram only
    on_path = tmp_path / "on_path"
    make(on_path, 11.0, module="scaler_mod")
    monkeypatch.syspath_prepend(str(on_path))
    local = blocks.load_diagram(make(tmp_path / "model", 4.0, module="scaler_mod"), trust=True)
    assert list(blocks.simulate(local)["scale.y"][1][:, 0]) == [4.0] * 3
    # a diagram without the module beside it gets the one on the path
    other = tmp_path / "other"
    other.mkdir()
    (other / "diagram.yaml").write_text(DIAGRAM.format(module="scaler_mod"), encoding="utf-8")
    from_path = blocks.load_diagram(other / "diagram.yaml", trust=True)
    assert list(blocks.simulate(from_path)["scale.y"][1][:, 0]) == [11.0] * 3


def test_a_package_beside_the_diagram_with_relative_imports(tmp_path: Path):
    folder = tmp_path / "model"
    package = folder / "mypkg"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("", encoding="utf-8")
    (package / "gains.py").write_text("K = 6.0\n", encoding="utf-8")
    (package / "scale.py").write_text(MODULE.format(k="K").replace(
        "from blocks import Block", "from blocks import Block\n\nfrom .gains import K"), encoding="utf-8")
    (folder / "diagram.yaml").write_text(DIAGRAM.format(module="mypkg.scale"), encoding="utf-8")
    diagram = blocks.load_diagram(folder / "diagram.yaml", trust=True)
    assert list(blocks.simulate(diagram)["scale.y"][1][:, 0]) == [6.0] * 3


def test_a_missing_module_is_one_line_naming_the_line_and_the_folders_searched(tmp_path: Path):
    folder = tmp_path / "model"
    folder.mkdir()
    diagram = folder / "diagram.yaml"
    diagram.write_text(DIAGRAM.format(module="no_such_mod_xyz"), encoding="utf-8")
    proc = cli("validate", diagram, "--trust", cwd=tmp_path)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert re.match(rf"{re.escape(str(diagram))}:5: block 'scale': cannot import 'python:no_such_mod_xyz'", lines[0])
    assert str(folder.resolve()) in lines[0]
    assert "no_such_mod_xyz.py" in lines[0] and "sys.path" in lines[0]


def test_an_error_inside_the_module_is_reported_as_it_is(tmp_path: Path):
    folder = tmp_path / "model"
    folder.mkdir()
    (folder / "broken_mod.py").write_text("import no_such_dependency_xyz\n", encoding="utf-8")
    (folder / "diagram.yaml").write_text(DIAGRAM.format(module="broken_mod"), encoding="utf-8")
    with pytest.raises(DiagramError) as info:
        blocks.load_diagram(folder / "diagram.yaml", trust=True)
    assert "no_such_dependency_xyz" in str(info.value)
    assert not any(m.endswith("_broken_mod") for m in sys.modules)
