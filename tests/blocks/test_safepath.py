"""Paths from a diagram stay in the diagram's folder: ``inside`` and the params_file policy."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from blocks import DiagramError, load_diagram
from blocks.limits import MAX_FOLDER_NAME
from blocks.safepath import folder_name, inside

DIAGRAM = """\
name: p
blocks:
  src: {{type: Constant, params: {{value: 1.0}}}}
  g: {{type: Gain, params_file: {file}}}
connections:
  - src.y -> g.u
"""


def test_inside(tmp_path):
    (tmp_path / "sub").mkdir()
    assert inside(tmp_path / "a.yaml", tmp_path)
    assert inside(tmp_path / "sub" / ".." / "a.yaml", tmp_path)
    assert inside(tmp_path, tmp_path)
    assert not inside(tmp_path / ".." / "a.yaml", tmp_path)
    assert not inside("/etc/passwd", tmp_path)
    assert not inside(tmp_path / "sub" / "a\x00b", tmp_path / "sub" / "a")


def test_a_link_out_of_the_folder_is_outside(tmp_path):
    (tmp_path / "d").mkdir()
    (tmp_path / "secret.yaml").write_text("k: 1\n")
    os.symlink(tmp_path / "secret.yaml", tmp_path / "d" / "link.yaml")
    assert not inside(tmp_path / "d" / "link.yaml", tmp_path / "d")


def write(tmp_path, file: str):
    (tmp_path / "d").mkdir()
    (tmp_path / "secret.yaml").write_text("k: 3\n")
    (tmp_path / "d" / "p.yaml").write_text("k: 2\n")
    path = tmp_path / "d" / "diagram.yaml"
    path.write_text(DIAGRAM.format(file=file))
    return path


@pytest.mark.parametrize("file", ["../secret.yaml", "{tmp}/secret.yaml", "link.yaml"])
def test_params_file_out_of_the_folder_needs_trust(tmp_path, file):
    path = write(tmp_path, file.format(tmp=tmp_path))
    os.symlink(tmp_path / "secret.yaml", tmp_path / "d" / "link.yaml")
    with pytest.raises(DiagramError) as info:
        load_diagram(path)
    [issue] = info.value.issues
    assert issue.line == 4 and "is outside the diagram's folder" in issue.message and "--trust" in issue.hint
    assert load_diagram(path, trust=True).blocks["g"].params == {"k": 3}


@pytest.mark.parametrize("file", ["p.yaml", "./p.yaml", "{tmp}/d/p.yaml"])
def test_params_file_in_the_folder_needs_no_trust(tmp_path, file):
    path = write(tmp_path, file.format(tmp=tmp_path))
    assert load_diagram(path).blocks["g"].params == {"k": 2}


def test_unknown_key_of_a_params_file_is_reported_at_its_line(tmp_path):
    path = write(tmp_path, "p.yaml")
    (tmp_path / "d" / "p.yaml").write_text("k: 2\n\nkk: 3\n")
    with pytest.raises(DiagramError) as info:
        load_diagram(path)
    [issue] = info.value.issues
    assert (issue.file, issue.line) == (str(tmp_path / "d" / "p.yaml"), 3)
    assert issue.message == "block 'g' (Gain) has no parameter 'kk'" and issue.hint == "did you mean 'k'?"


@pytest.mark.parametrize("name, folder", [
    ("toy-multirate", "toy-multirate"), ("grasp_v2.1", "grasp_v2.1"), ("Greifer-\u00fc", "Greifer-\u00fc"),
    ("../../escaped", "_escaped"), ("/tmp/x", "_tmp_x"), ("a\\\\b", "a_b"), ("a\x00b", "a_b"),
    ("..", "_"), (".", "diagram"), ("", "diagram"), (".hidden", "hidden"), ("--rm -rf", "rm_-rf"),
    ("a..b", "a_b"), ("my run", "my_run"), ("C:\\\\x", "C_x"),
])
def test_folder_name(name, folder):
    assert folder_name(name) == folder


def test_folder_name_is_cut_to_the_limit_in_utf8_bytes():
    assert folder_name("a" * 500) == "a" * MAX_FOLDER_NAME
    cut = folder_name("\u00fc" * 500)
    assert len(cut.encode("utf-8")) <= MAX_FOLDER_NAME and set(cut) == {"\u00fc"}


@pytest.mark.parametrize("name", ["../../x", "/abs/x", "..", "a/../../b", "\\\\..\\\\x", "x\x00/..", "~/x"])
def test_folder_name_is_one_component_that_stays_below(tmp_path, name):
    folder = folder_name(name)
    assert len(Path(folder).parts) == 1 and inside(tmp_path / folder, tmp_path) and tmp_path / folder != tmp_path
