"""Safe reading and extraction of FMU archives: unsafe member names, links, special files,
duplicates, and the size, count and inflation limits, checked on the headers and on the
bytes actually decompressed."""

from __future__ import annotations

import os
import stat
import zipfile
from pathlib import Path

import pytest

from blocks.fmu import archive
from blocks.fmu.archive import ArchiveError, Limits, _chunks, extract_archive, read_member

pytest.importorskip("fmpy")

from .build import zip_files  # noqa: E402


def _zip_with(path: Path, name: str, data: bytes = b"x", mode: int | None = None) -> Path:
    info = zipfile.ZipInfo(name)
    if mode is not None:
        info.create_system = 3
        info.external_attr = mode << 16
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("ok.txt", "fine")
        zf.writestr(info, data)
    return path


@pytest.mark.filterwarnings("ignore:Duplicate name")
@pytest.mark.parametrize("name, mode, expected", [
    ("../evil.txt", None, "has a '..' component"),
    ("a/../../evil.txt", None, "has a '..' component"),
    ("..\\evil.txt", None, "has a '..' component"),
    ("/abs/evil.txt", None, "has an absolute path"),
    ("C:/evil.txt", None, "drive letter"),
    ("link", stat.S_IFLNK | 0o777, "is a symbolic link"),
    ("fifo", stat.S_IFIFO | 0o644, "is a special file"),
    ("ok.txt", None, "occurs twice"),
])
def test_extractor_rejects_unsafe_members(tmp_path, name, mode, expected):
    archive = _zip_with(tmp_path / "a.zip", name, b"/etc/passwd" if mode else b"x", mode)
    dest = tmp_path / "out"
    dest.mkdir()
    with pytest.raises(ArchiveError, match=expected) as info:
        extract_archive(archive, dest)
    assert repr(name) in str(info.value)
    assert list(dest.iterdir()) == []               # nothing written
    assert not (tmp_path / "evil.txt").exists()


def test_extractor_limits_size_and_count(tmp_path):
    big = _zip_with(tmp_path / "big.zip", "big.bin", b"\0" * 5000)
    (tmp_path / "o1").mkdir()
    with pytest.raises(ArchiveError, match="'big.bin' is 5000 bytes uncompressed, more than the limit of 1000"):
        extract_archive(big, tmp_path / "o1", Limits(member_bytes=1000))
    with pytest.raises(ArchiveError, match="more than the limit of 3000 bytes"):
        extract_archive(big, tmp_path / "o1", Limits(total_bytes=3000))
    many = zip_files(tmp_path / "many.zip", {f"f{i}.txt": "x" for i in range(20)})
    with pytest.raises(ArchiveError, match="has 20 members, more than the limit of 10"):
        extract_archive(many, tmp_path / "o1", Limits(members=10))
    with pytest.raises(ArchiveError, match="its member list takes .* bytes, more than 1 members can need"):
        read_member(many, "f1.txt", Limits(members=1))
    extract_archive(many, tmp_path / "o1")
    assert len(list((tmp_path / "o1").iterdir())) == 20


def test_archive_limits_keep_a_zip_bomb_small():
    """At most 256 MiB per member and in all (once 1 GiB and 4 GiB), at most 200-fold inflation."""
    assert archive.MAX_MEMBER_BYTES == archive.MAX_TOTAL_BYTES == 256 * 2**20
    assert archive.MAX_RATIO == 200 and archive.RATIO_FLOOR_BYTES == 2**20
    assert archive.MAX_MEMBERS == 10_000


def test_a_member_that_inflates_too_much_is_refused(tmp_path):
    bomb = zip_files(tmp_path / "bomb.fmu", {"modelDescription.xml": "<x/>", "resources/zeros.bin": b"\0" * (4 << 20)})
    (tmp_path / "out").mkdir()
    with pytest.raises(ArchiveError, match=r"'resources/zeros.bin' inflates from \d+ to 4194304 bytes or more, "
                                           "more than 200 times"):
        extract_archive(bomb, tmp_path / "out")
    with pytest.raises(ArchiveError, match="more than 200 times"):
        read_member(bomb, "modelDescription.xml")     # every member is checked, even when reading one
    small = zip_files(tmp_path / "small.fmu", {"notes.txt": b"\0" * 100_000})  # below the floor: fine
    assert read_member(small, "notes.txt") == (b"\0" * 100_000, ["notes.txt"])


def test_the_bytes_are_counted_as_they_are_decompressed(tmp_path):
    """The running count does not rely on the headers: a member whose header says it is
    huge (so zipfile does not cut it) is stopped once the bytes read pass a limit."""
    archive = zip_files(tmp_path / "a.zip", {"x.bin": os.urandom(5000)})
    with zipfile.ZipFile(archive) as zf:
        info = zf.getinfo("x.bin")
        info.file_size = 10**9
        with pytest.raises(ArchiveError, match="is 5000 bytes uncompressed, more than the limit of 1000"):
            list(_chunks(zf, info, 0, "a.zip", Limits(member_bytes=1000)))
        with pytest.raises(ArchiveError, match="add up to more than the limit of 6000"):
            list(_chunks(zf, info, 2000, "a.zip", Limits(total_bytes=6000)))


def test_extractor_catches_members_that_inflate_beyond_their_header(tmp_path):
    """A forged header declaring a small size does not let more data through."""
    archive = tmp_path / "forged.zip"
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_STORED) as zf:
        zf.writestr("x.bin", b"A" * 4096)
    data = bytearray(archive.read_bytes())
    # Patch the uncompressed size in the central directory (offset 24 of its entry) to 16.
    cd = data.rfind(b"PK\x01\x02")
    data[cd + 24:cd + 28] = (16).to_bytes(4, "little")
    archive.write_bytes(bytes(data))
    (tmp_path / "out").mkdir()
    with pytest.raises((ArchiveError, zipfile.BadZipFile)):
        extract_archive(archive, tmp_path / "out", Limits(member_bytes=100))
    assert not (tmp_path / "out" / "x.bin").exists()
