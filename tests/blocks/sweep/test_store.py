"""sweep.csv: header once, whole rows, resume set, torn tails, foreign files."""

from __future__ import annotations

import csv

import pytest

from blocks.sweep import SweepError
from blocks.sweep.store import SweepStore, read_sweep


def test_rows_append_and_reopen(tmp_path):
    store = SweepStore(tmp_path, ["a.k", "b.v"], ["m"])
    assert store.open() == {}
    store.append("h1", {"a.k": 1, "b.v": [1, 2]}, "ok", "", 0.5, {"m": 0.25})
    store.append("h2", {"a.k": 2, "b.v": [3, 4]}, "failed", "bad\nvalue, here", 0.1, {})
    rows = list(csv.reader(open(tmp_path / "sweep.csv")))
    assert rows == [["point_hash", "status", "error", "wall_s", "a.k", "b.v", "m"],
                    ["h1", "ok", "", "0.5", "1", "[1, 2]", "0.25"],
                    ["h2", "failed", "bad value, here", "0.1", "2", "[3, 4]", ""]]
    assert SweepStore(tmp_path, ["a.k", "b.v"], ["m"]).open() == {"h1": "ok", "h2": "failed"}


def test_a_torn_last_line_is_cut_on_resume(tmp_path):
    store = SweepStore(tmp_path, ["a.k"], ["m"])
    store.open()
    store.append("h1", {"a.k": 1}, "ok", "", 0.5, {"m": 1.0})
    with open(tmp_path / "sweep.csv", "a") as f:
        f.write("h2,ok,,0.1,2")
    assert store.open() == {"h1": "ok"}
    assert (tmp_path / "sweep.csv").read_text().endswith("1.0\n")


def test_another_sweeps_file_is_refused(tmp_path):
    SweepStore(tmp_path, ["a.k"], ["m"]).open()
    with pytest.raises(SweepError, match="belongs to another sweep"):
        SweepStore(tmp_path, ["a.k"], ["other"]).open()


def test_read_sweep_keeps_the_last_row_per_point(tmp_path):
    store = SweepStore(tmp_path, ["a.k"], ["m"])
    store.open()
    store.write_description({"parameters": ["a.k"], "metrics": {"m": "final(x.y)"}})
    store.append("h1", {"a.k": 1}, "failed", "lost", 0.0, {})
    store.append("h1", {"a.k": 1}, "ok", "", 0.2, {"m": 3.0})
    description, rows = read_sweep(tmp_path)
    assert description["metrics"] == {"m": "final(x.y)"}
    assert [(r["status"], r["m"]) for r in rows] == [("ok", "3.0")]
