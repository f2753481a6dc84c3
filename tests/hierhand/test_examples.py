"""The shipped diagrams from any folder: ``hierhand run regrasp`` by name, ``hierhand
examples`` to list them and ``hierhand examples DIR`` to copy them."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from hierhand.examples import SHIPPED, example_files, shipped_diagram

ROOT = Path(__file__).resolve().parents[2]


def hierhand(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "hierhand", *args], cwd=cwd, capture_output=True, text=True)


def test_a_shipped_diagram_runs_by_name_in_an_empty_folder(tmp_path):
    proc = hierhand("run", "toy", "-o", "out", "--t-end", "10 ms", "-q", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "out" / "signals.npz").is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_a_file_of_that_name_wins_and_a_path_is_never_looked_up(tmp_path):
    mine = (SHIPPED / "toy.yaml").read_text(encoding="utf-8").replace("name: toy-multirate", "name: mine")
    (tmp_path / "toy").write_text(mine, encoding="utf-8")
    proc = hierhand("validate", "toy", cwd=tmp_path)
    assert proc.returncode == 0 and "diagram 'mine'" in proc.stdout
    proc = hierhand("validate", "elsewhere/toy", cwd=tmp_path)
    assert proc.returncode == 2 and "diagram file not found" in proc.stderr
    assert shipped_diagram("../diagrams/toy") is None and shipped_diagram("toy.yaml") == SHIPPED / "toy.yaml"


def test_examples_lists_them_and_copies_them_without_overwriting(tmp_path):
    listed = hierhand("examples", cwd=tmp_path)
    assert listed.returncode == 0
    names = {p.stem for p in example_files() if p.suffix == ".yaml"}
    assert {line.split()[0] for line in listed.stdout.splitlines()} == names >= {"regrasp", "toy", "controller"}
    proc = hierhand("examples", "mine", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    copied = sorted(p.name for p in (tmp_path / "mine").iterdir())
    assert copied == sorted(p.name for p in example_files()) and "diagram.schema.json" in copied
    assert hierhand("validate", "mine/regrasp.yaml", cwd=tmp_path).returncode == 0  # its subsystem came along
    (tmp_path / "mine" / "toy.yaml").write_text("mine", encoding="utf-8")
    again = hierhand("examples", "mine", cwd=tmp_path)
    assert again.returncode == 2 and len(again.stderr.splitlines()) == 1 and "toy.yaml" in again.stderr
    assert (tmp_path / "mine" / "toy.yaml").read_text(encoding="utf-8") == "mine"
