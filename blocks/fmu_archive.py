"""Safe extraction of FMU archives (zip files from other tools, so treated as untrusted).

``zipfile.ZipFile.extractall`` trusts the member names; this extractor does not. Before
writing anything it checks the whole member list and refuses the archive, naming the
member, when it finds:

- an absolute name (``/etc/x``, ``\\\\server\\x``, ``C:x``) or a ``..`` component;
- a symbolic link or another special file (device, fifo, socket), or an encrypted member;
- a name that is empty, holds a NUL or control character, or occurs twice (one member
  could otherwise overwrite another, or a file collide with a folder);
- more members than ``max_members``, a member larger than ``max_member_bytes``, or more
  than ``max_total_bytes`` in all (decompression bombs).

Sizes are checked against the headers first and again while decompressing (a member
that inflates beyond its declared size is cut off). Files are created exclusively
(``O_EXCL``), without the archive's permission bits, inside a fresh destination folder,
and every resolved path is checked to lie inside it.
"""

from __future__ import annotations

import os
import shutil
import stat
import zipfile
from pathlib import Path, PurePosixPath

MAX_MEMBERS = 10_000
"""Default limit on the number of members (files and folders) of an archive."""

MAX_MEMBER_BYTES = 1 << 30
"""Default limit on the uncompressed size of one member (1 GiB)."""

MAX_TOTAL_BYTES = 4 << 30
"""Default limit on the uncompressed size of all members together (4 GiB)."""

_CHUNK = 1 << 20


class ArchiveError(ValueError):
    """An archive that cannot be extracted safely; the message names the archive and the member."""


def _describe(archive: str | os.PathLike) -> str:
    return f"archive '{archive}'"


def _member_parts(name: str) -> list[str]:
    """The path components of a member name (both '/' and '\\' separate), or raise ValueError."""
    if not name:
        raise ValueError("has an empty name")
    if any(ord(c) < 32 for c in name):
        raise ValueError("has a control character in its name")
    unified = name.replace("\\", "/")
    if unified.startswith("/") or PurePosixPath(unified).is_absolute():
        raise ValueError("has an absolute path")
    if len(unified) >= 2 and unified[1] == ":" and unified[0].isalpha():
        raise ValueError("has a drive letter (an absolute Windows path)")
    parts = [p for p in unified.split("/") if p not in ("", ".")]
    if ".." in parts:
        raise ValueError("has a '..' component (it would escape the extraction folder)")
    if not parts:
        raise ValueError("has no file name")
    return parts


def _file_type(info: zipfile.ZipInfo) -> int:
    """The stat file-type bits of a member (0 when the archive records none)."""
    return stat.S_IFMT(info.external_attr >> 16)


def check_members(zf: zipfile.ZipFile, archive: str | os.PathLike = "<archive>", *,
                  max_members: int = MAX_MEMBERS, max_member_bytes: int = MAX_MEMBER_BYTES,
                  max_total_bytes: int = MAX_TOTAL_BYTES) -> list[tuple[zipfile.ZipInfo, list[str]]]:
    """Validate every member of ``zf``; return ``(info, path parts)`` pairs, or raise ArchiveError."""
    where = _describe(archive)
    infos = zf.infolist()
    if len(infos) > max_members:
        raise ArchiveError(f"{where} has {len(infos)} members, more than the limit of {max_members}")
    total = 0
    seen: dict[str, str] = {}
    prefixes: set[str] = set()
    files: set[str] = set()
    checked = []
    for info in infos:
        name = info.filename
        try:
            parts = _member_parts(name)
        except ValueError as exc:
            raise ArchiveError(f"{where}: member {name!r} {exc}") from None
        kind = _file_type(info)
        if kind == stat.S_IFLNK:
            raise ArchiveError(f"{where}: member {name!r} is a symbolic link; links are not extracted")
        if kind not in (0, stat.S_IFREG, stat.S_IFDIR):
            raise ArchiveError(f"{where}: member {name!r} is a special file (mode {oct(kind)}), "
                               "not a regular file or folder")
        if info.flag_bits & 0x1:
            raise ArchiveError(f"{where}: member {name!r} is encrypted")
        if info.file_size > max_member_bytes:
            raise ArchiveError(f"{where}: member {name!r} is {info.file_size} bytes uncompressed, more "
                               f"than the limit of {max_member_bytes} bytes per member")
        total += info.file_size
        if total > max_total_bytes:
            raise ArchiveError(f"{where}: the members add up to more than the limit of "
                               f"{max_total_bytes} bytes uncompressed (at member {name!r})")
        key = "/".join(parts)
        if key in seen:
            raise ArchiveError(f"{where}: member {name!r} occurs twice (also as {seen[key]!r})")
        seen[key] = name
        is_dir = info.is_dir() or kind == stat.S_IFDIR
        for i in range(1, len(parts)):
            prefixes.add("/".join(parts[:i]))
        if not is_dir:
            files.add(key)
        checked.append((info, parts))
    clash = files & prefixes
    if clash:
        name = seen[min(clash)]
        raise ArchiveError(f"{where}: member {name!r} is a file but other members use it as a folder")
    return checked


def extract_archive(archive: str | os.PathLike, dest: str | os.PathLike, *,
                    max_members: int = MAX_MEMBERS, max_member_bytes: int = MAX_MEMBER_BYTES,
                    max_total_bytes: int = MAX_TOTAL_BYTES) -> Path:
    """Extract the zip file ``archive`` into the existing, empty folder ``dest``.

    Raises ``ArchiveError`` (a ValueError) before writing anything when a member is
    unsafe, and ``zipfile.BadZipFile`` when ``archive`` is not a readable zip file. On
    an error during writing, what was written is removed again. Returns ``dest``.
    """
    dest = Path(dest)
    root = dest.resolve()
    where = _describe(archive)
    with zipfile.ZipFile(archive) as zf:
        checked = check_members(zf, archive, max_members=max_members,
                                max_member_bytes=max_member_bytes, max_total_bytes=max_total_bytes)
        try:
            for info, parts in checked:
                target = root.joinpath(*parts)
                if not target.resolve().is_relative_to(root):  # defence in depth
                    raise ArchiveError(f"{where}: member {info.filename!r} would be written outside "
                                       "the extraction folder")
                if info.is_dir() or _file_type(info) == stat.S_IFDIR:
                    target.mkdir(parents=True, exist_ok=True)
                    continue
                target.parent.mkdir(parents=True, exist_ok=True)
                _copy_member(zf, info, target, min(info.file_size, max_member_bytes), where)
        except BaseException:
            for child in root.iterdir():
                if child.is_dir() and not child.is_symlink():
                    shutil.rmtree(child, ignore_errors=True)
                else:
                    child.unlink(missing_ok=True)
            raise
    return dest


def _copy_member(zf: zipfile.ZipFile, info: zipfile.ZipInfo, target: Path, limit: int, where: str) -> None:
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0) | getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(target, flags, 0o644)
    except FileExistsError:  # e.g. names differing only in case on a case-insensitive file system
        raise ArchiveError(f"{where}: member {info.filename!r} collides with another member") from None
    written = 0
    with os.fdopen(fd, "wb") as out, zf.open(info) as src:
        while True:
            chunk = src.read(_CHUNK)
            if not chunk:
                break
            written += len(chunk)
            if written > limit:
                raise ArchiveError(f"{where}: member {info.filename!r} inflates beyond its declared "
                                   f"size of {info.file_size} bytes")
            out.write(chunk)
