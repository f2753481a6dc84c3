"""A results folder holds one run's files as one set: modes, stale files, locking, races."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from blocks import Results, ResultsError
from blocks.results.folder import OutputFolderError, prepare, writing

REPO = Path(__file__).resolve().parents[3]


def results(name: str = "a", value: float = 1.0) -> Results:
    t = np.arange(4) * 1e-3
    return Results({f"{name}.y": (t, np.full((4, 1), value))}, {"diagram": name, "status": "complete"})


@pytest.fixture
def umask():
    """Sets a umask for one test and puts the old one back."""
    old = os.umask(0o022)
    os.umask(old)
    yield os.umask
    os.umask(old)


@pytest.mark.parametrize("mask, mode", [(0o022, 0o644), (0o027, 0o640)])
def test_result_files_get_the_usual_mode_under_the_umask(tmp_path, umask, mask, mode):
    umask(mask)
    results().save(tmp_path / "run", csv=True)
    for name in ("signals.npz", "signals.csv", "run.json"):
        assert (tmp_path / "run" / name).stat().st_mode & 0o777 == mode, name


def test_a_run_without_csv_removes_the_previous_runs_csv(tmp_path):
    results("a").save(tmp_path, csv=True)
    results("b").save(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.json", "signals.npz"]
    assert list(Results.load(tmp_path)) == ["b.y"]


def test_plots_of_the_previous_run_go_and_other_files_stay(tmp_path):
    with writing(tmp_path) as staged:
        results("a").write_files(staged)
        (staged / "plots").mkdir()
        (staged / "plots" / "signals-1.png").write_bytes(b"old plot")
    (tmp_path / "notes.txt").write_text("mine")
    (tmp_path / "plots" / "sketch.png").write_bytes(b"mine too")
    results("b").save(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt", "plots", "run.json", "signals.npz"]
    assert [p.name for p in (tmp_path / "plots").iterdir()] == ["sketch.png"]


def test_a_writer_waits_until_the_other_has_replaced_the_files(tmp_path):
    second = threading.Thread(target=lambda: results("b", 2.0).save(tmp_path))
    with writing(tmp_path) as staged:
        results("a").write_files(staged)
        second.start()
        second.join(0.3)
        assert second.is_alive(), "the second writer did not wait for the lock"
    second.join(10)
    back = Results.load(tmp_path)
    assert list(back) == ["b.y"] and back.info["diagram"] == "b"
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_a_replace_cut_short_leaves_an_incomplete_folder_not_a_mix(tmp_path, monkeypatch):
    results("a").save(tmp_path)
    real = os.replace

    def fail_on_npz(src, dst):
        if str(dst).endswith("signals.npz"):
            raise OSError(28, "No space left on device")
        real(src, dst)

    monkeypatch.setattr(os, "replace", fail_on_npz)
    with pytest.raises(OSError, match="No space"):
        results("b").save(tmp_path)
    monkeypatch.setattr(os, "replace", real)
    with pytest.raises(ResultsError, match="no run.json"):
        Results.load(tmp_path)
    results("c").save(tmp_path)  # the next run also clears the staging folder left behind
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.json", "signals.npz"]
    assert list(Results.load(tmp_path)) == ["c.y"]


RACER = """\
import sys
import numpy as np
from blocks import Results
name, folder = sys.argv[1], sys.argv[2]
for i in range(40):
    n = 3 + i % 5
    t = np.arange(n) * 1e-3
    info = {"diagram": name, "status": "complete", "round": i}
    Results({name + ".y": (t, np.full((n, 1), float(i)))}, info).save(folder, csv=(name == "a"))
"""


def test_racing_runs_never_leave_a_mix(tmp_path):
    """Two processes save 40 times each into one folder (one with --csv, one without)
    while this one reads it: every read, and the end, is one run's consistent set."""
    folder = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=str(REPO))
    racers = [subprocess.Popen([sys.executable, "-c", RACER, name, str(folder)], env=env)
              for name in ("a", "b")]
    reads = 0
    while any(p.poll() is None for p in racers):
        try:
            r = Results.load(folder)
        except ResultsError:
            continue  # not written yet
        name = r.info["diagram"]
        assert list(r) == [f"{name}.y"]
        t, v = r[f"{name}.y"]
        assert len(t) == 3 + r.info["round"] % 5 and (v == r.info["round"]).all()
        reads += 1
    assert [p.returncode for p in racers] == [0, 0]
    info = json.loads((folder / "run.json").read_text())
    assert (folder / "signals.csv").exists() == (info["diagram"] == "a")
    assert sorted(p.name for p in folder.iterdir() if p.name != "signals.csv") == ["run.json", "signals.npz"]


def test_prepare_creates_the_folder_and_proves_it_writable(tmp_path):
    assert prepare(tmp_path / "a" / "b") == tmp_path / "a" / "b"
    assert (tmp_path / "a" / "b").is_dir() and list((tmp_path / "a" / "b").iterdir()) == []


def test_prepare_refuses_a_file_and_a_folder_under_a_file(tmp_path):
    (tmp_path / "f").write_text("x")
    with pytest.raises(OutputFolderError, match="is a file, not a folder"):
        prepare(tmp_path / "f")
    with pytest.raises(OutputFolderError, match=f"cannot be created: {tmp_path / 'f'} is a file"):
        prepare(tmp_path / "f" / "sub")


def writable(folder: Path) -> bool:
    try:
        (folder / ".probe").touch()
    except OSError:
        return False
    (folder / ".probe").unlink()
    return True


def read_only_folder(tmp_path: Path) -> Path:
    """A folder this user cannot write: mode 0555, or for root (who writes anyway) sysfs."""
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    if writable(folder):
        folder = Path("/sys/kernel")
        if not folder.is_dir() or writable(folder):
            pytest.skip("no read-only folder available to this user")
    return folder


def test_prepare_refuses_a_read_only_folder(tmp_path):
    with pytest.raises(OutputFolderError, match="is not writable"):
        prepare(read_only_folder(tmp_path))
