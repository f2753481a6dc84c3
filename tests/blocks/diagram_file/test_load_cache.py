"""Loading a diagram again: the Diagram made before while its files hold the same bytes,
a new one as soon as any file it read (its own, a params file, a subsystem's) changes."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import blocks
from blocks.diagram_file import load_cache

TOP = """
name: top
time: {t_end: 3 ms}
blocks:
  c: {type: Constant, params: {value: 2.0}}
  g: {type: Gain, period: 1 ms, params_file: gains.yaml}
  sub: {diagram: inner.yaml}
connections: [c.y -> g.u, g.y -> sub.u]
log: [sub.h.y]
"""
INNER = """
name: inner
blocks:
  h: {type: Gain, period: 1 ms, params: {k: 10.0}}
inputs: {u: h.u}
outputs: {y: h.y}
"""


def age(*paths: Path) -> None:
    """Files as if written an hour ago: settled, as a diagram's files are between loads."""
    old = os.stat(paths[0]).st_mtime_ns - 3600 * 10**9
    for path in paths:
        os.utime(path, ns=(old, old))


@pytest.fixture
def files(tmp_path):
    load_cache.forget()
    top, gains, inner = tmp_path / "top.yaml", tmp_path / "gains.yaml", tmp_path / "inner.yaml"
    top.write_text(TOP)
    gains.write_text("k: 3.0\n")
    inner.write_text(INNER)
    age(top, gains, inner)
    yield top, gains, inner
    load_cache.forget()


def last(diagram) -> float:
    return float(blocks.simulate(diagram)["sub.h.y"][1][-1, 0])


def test_unchanged_files_give_the_same_diagram_even_when_touched(files):
    top, gains, inner = files
    first = blocks.load_diagram(top)
    assert blocks.load_diagram(top) is first and last(first) == 60.0
    os.utime(gains)  # a new time, the same bytes
    age(gains)
    assert blocks.load_diagram(top) is first


@pytest.mark.parametrize("which, edit, expected", [
    ("top", ("value: 2.0", "value: 5.0"), 150.0),
    ("gains", ("3.0", "4.0"), 80.0),
    ("inner", ("10.0", "100.0"), 600.0),
])
def test_a_changed_file_of_any_kind_gives_a_new_diagram(files, which, edit, expected):
    """Whichever file changes (the diagram, its params file, its subsystem's), and even with
    its old time put back, the next load reads it again."""
    top, gains, inner = files
    first = blocks.load_diagram(top)
    assert blocks.load_diagram(top) is first
    path = {"top": top, "gains": gains, "inner": inner}[which]
    before = os.stat(path).st_mtime_ns
    path.write_text(path.read_text().replace(*edit))
    os.utime(path, ns=(before, before))
    again = blocks.load_diagram(top)
    assert again is not first and last(again) == expected and last(first) == 60.0


def test_other_arguments_are_other_loads(files):
    top, _, _ = files
    plain = blocks.load_diagram(top)
    changed = blocks.load_diagram(top, overrides={"g.k": 1.0})
    assert changed is not plain and last(changed) == 20.0
    assert blocks.load_diagram(top, overrides={"g.k": 1.0}) is changed and blocks.load_diagram(top) is plain


def test_a_file_written_just_before_its_load_is_read_again_next_time(files):
    """A file modified moments before the load began may still have been being written:
    that load is not kept."""
    top, gains, _ = files
    gains.write_text("k: 3.0\n")
    assert blocks.load_diagram(top) is not blocks.load_diagram(top)


def test_a_removed_file_fails_the_next_load(files):
    top, gains, _ = files
    blocks.load_diagram(top)
    gains.unlink()
    with pytest.raises(blocks.DiagramError):
        blocks.load_diagram(top)
