"""A file written atomically: whole or not at all, no temporary file left, usual permissions."""

from __future__ import annotations

import os
import stat

import pytest

from blocks.results.atomic_file import atomic_writer, write_atomically


def test_text_and_bytes_replace_the_file(tmp_path):
    path = tmp_path / "a.json"
    assert write_atomically(path, "{}\n") == path
    assert path.read_text() == "{}\n"
    write_atomically(path, b"\x00\x01")
    assert path.read_bytes() == b"\x00\x01"
    assert os.listdir(tmp_path) == ["a.json"]


def test_a_failure_while_writing_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    path = tmp_path / "a.txt"
    path.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_writer(path) as f:
            f.write(b"half")
            raise RuntimeError("disk gone")
    assert path.read_text() == "old"
    assert os.listdir(tmp_path) == ["a.txt"]


def test_the_file_gets_the_permissions_of_a_plain_write(tmp_path):
    old = os.umask(0o022)
    try:
        write_atomically(tmp_path / "a", "x")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "a").stat().st_mode) == 0o644
