"""The program's temporary folder (blocks/process/scratch.py): private, shared with the processes a
process starts, removed by the one that made it, and never one a variable merely names."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from blocks.process import scratch

REPO = Path(__file__).resolve().parents[3]
CHILD = "from blocks.process import scratch; print(scratch.folder('child-'), scratch.root())"

pytestmark = pytest.mark.skipif(os.name != "posix", reason="POSIX permissions")


def child(tmp_path: Path, named: str | None) -> tuple[Path, Path]:
    """A new Python process with TMPDIR ``tmp_path / 'tmp'`` and BLOCKS_SCRATCH ``named``:
    the folder it made and its root."""
    (tmp_path / "tmp").mkdir(exist_ok=True)
    env = {**os.environ, "PYTHONPATH": str(REPO), "TMPDIR": str(tmp_path / "tmp"), scratch.ENV: named or ""}
    done = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, check=True)
    made, root = done.stdout.split()
    return Path(made), Path(root)


def test_a_folder_lies_in_a_private_root():
    made = scratch.folder("test-")
    root = scratch.root()
    assert made.parent == root and made.name.startswith("test-") and root.name.startswith(scratch.PREFIX)
    assert stat.S_IMODE(root.stat().st_mode) == 0o700
    assert os.environ[scratch.ENV] == str(root)


def test_a_started_process_works_in_the_root_it_is_given_and_leaves_it(tmp_path):
    given = tmp_path / "given"
    given.mkdir(mode=0o700)
    made, root = child(tmp_path, str(given))
    assert root == given and made.parent == given
    assert given.is_dir()                                # the process that made it removes it, not a child
    assert list((tmp_path / "tmp").iterdir()) == []


@pytest.mark.parametrize("how", ["group-writable", "a link", "missing"])
def test_a_root_named_that_is_not_private_is_not_used(tmp_path, how):
    given = tmp_path / "given"
    if how == "group-writable":
        given.mkdir()
        given.chmod(0o770)
    elif how == "a link":
        (tmp_path / "real").mkdir(mode=0o700)
        given.symlink_to(tmp_path / "real")
    made, root = child(tmp_path, str(given))
    assert root.parent == tmp_path / "tmp" and made.parent == root
    assert list((tmp_path / "tmp").iterdir()) == []      # its own root, removed at its exit
