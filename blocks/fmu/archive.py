"""Safe reading and extraction of FMU archives (zip files from other tools, so untrusted).

``zipfile.ZipFile.extractall`` trusts the member names; this module does not. Before
reading or writing anything it checks the whole member list and refuses the archive,
naming the member, when it finds:

- an absolute name (``/etc/x``, ``\\\\server\\x``, ``C:x``) or a ``..`` component;
- a symbolic link or another special file (device, fifo, socket), or an encrypted member;
- a name that is empty, holds a NUL or control character, or occurs twice with different
  contents (one member could otherwise overwrite another, or a file collide with a
  folder). A name that occurs twice with the same bytes, as some FMU tools write their
  ``extra/`` folders, is read once;
- decompression bombs: a member list (central directory) larger than 1 KiB per allowed
  member (checked before zipfile reads it), more than ``MAX_MEMBERS`` members, a member
  larger than ``MAX_MEMBER_BYTES``, more than ``MAX_TOTAL_BYTES`` in all, or a member of
  more than ``RATIO_FLOOR_BYTES`` that inflates more than ``MAX_RATIO`` times.

The sizes are checked against the headers first and again on the bytes actually
decompressed, with a running count per member and in total (a member that inflates
beyond its declared size is cut off), so forged headers do not get more through.
Files are created exclusively (``O_EXCL``), without the archive's permission bits,
inside a fresh destination folder, and every resolved path is checked to lie inside it.
``read_member`` reads one member (an FMU's modelDescription.xml) into memory without
writing anything to disk. Only regular files are opened as archives (``open_regular``): a
FIFO would block the reader forever and a device such as ``/dev/zero`` never ends.
"""

from __future__ import annotations

import contextlib
import errno
import itertools
import os
import shutil
import stat
import zipfile
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from ..safepath import unusable_path

MAX_MEMBERS = 10_000
"""Limit on the number of members (files and folders) of an archive."""

MAX_MEMBER_BYTES = 256 << 20
"""Limit on the uncompressed size of one member (256 MiB): far above any FMU's binary."""

MAX_TOTAL_BYTES = 256 << 20
"""Limit on the uncompressed size of all members together (256 MiB)."""

MAX_RATIO = 200
"""Limit on how many times a large member may inflate (uncompressed / compressed size):
binaries and XML compress 3 to 20 times, a decompression bomb about 1000 times."""

RATIO_FLOOR_BYTES = 1 << 20
"""Members up to this size (1 MiB) may inflate more than ``MAX_RATIO`` (a small file of
repeated text), since they cannot do harm."""

_CD_BYTES_PER_MEMBER = 1024
_CHUNK = 1 << 20


@dataclass(frozen=True)
class Limits:
    """The limits an archive must keep (the module's constants unless a caller tightens them)."""

    members: int = MAX_MEMBERS
    member_bytes: int = MAX_MEMBER_BYTES
    total_bytes: int = MAX_TOTAL_BYTES
    ratio: float = MAX_RATIO
    ratio_floor: int = RATIO_FLOOR_BYTES


LIMITS = Limits()


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


def _central_directory_size(fp) -> int | None:
    """The size the end record declares for the member list (zip64 too), or None if there
    is no readable end record (zipfile then says what is wrong)."""
    fp.seek(0, os.SEEK_END)
    size = fp.tell()
    fp.seek(max(0, size - (22 + 0xFFFF)))
    tail = fp.read()
    at = tail.rfind(b"PK\x05\x06")
    if at < 0 or len(tail) - at < 22:
        return None
    cd_size = int.from_bytes(tail[at + 12:at + 16], "little")
    locator = tail[at - 20:at] if at >= 20 else b""
    if cd_size != 0xFFFFFFFF or not locator.startswith(b"PK\x06\x07"):
        return cd_size
    fp.seek(int.from_bytes(locator[8:16], "little"))
    record = fp.read(48)
    if not record.startswith(b"PK\x06\x06") or len(record) < 48:
        return None
    return int.from_bytes(record[40:48], "little")


class NotARegularFile(OSError):
    """A path that names a folder, FIFO, device or socket where a file is read."""


def file_kind(mode: int) -> str:
    """What a file of ``st_mode`` ``mode`` is, for messages: 'a folder', 'a FIFO (named pipe)', ..."""
    kind = stat.S_IFMT(mode)
    return {stat.S_IFREG: "a regular file", stat.S_IFDIR: "a folder", stat.S_IFIFO: "a FIFO (named pipe)",
            stat.S_IFCHR: "a device", stat.S_IFBLK: "a device", stat.S_IFSOCK: "a socket"}.get(kind,
                                                                                            "not a regular file")


def open_regular(path: str | os.PathLike):
    """The regular file ``path`` opened for binary reading. Opening does not wait for a
    FIFO's writer, and only a regular file is returned: anything else raises
    ``NotARegularFile``; a file that cannot be opened raises the OSError of ``os.open``."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise NotARegularFile(f"it is {file_kind(mode)}, not a regular file")
        os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


@contextlib.contextmanager
def open_archive(archive: str | os.PathLike, limits: Limits = LIMITS):
    """``zipfile.ZipFile`` of the regular file ``archive`` (``open_regular``), after checking
    that its member list is not too large to read (zipfile reads all of it into memory first)."""
    with open_regular(archive) as fp:
        cd_size = _central_directory_size(fp)
        if cd_size is not None and cd_size > limits.members * _CD_BYTES_PER_MEMBER:
            raise ArchiveError(f"{_describe(archive)}: its member list takes {cd_size} bytes, more than "
                               f"{limits.members} members can need (the limit is {limits.members} members)")
        fp.seek(0)
        with zipfile.ZipFile(fp) as zf:
            yield zf


def check_members(zf: zipfile.ZipFile, archive: str | os.PathLike = "<archive>",
                  limits: Limits = LIMITS) -> list[tuple[zipfile.ZipInfo, list[str]]]:
    """Validate every member of ``zf``; return ``(info, path parts)`` pairs, or raise ArchiveError."""
    where = _describe(archive)
    infos = zf.infolist()
    if len(infos) > limits.members:
        raise ArchiveError(f"{where} has {len(infos)} members, more than the limit of {limits.members}")
    total = 0
    seen: dict[str, zipfile.ZipInfo] = {}
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
        _check_size(info, info.file_size, total + info.file_size, where, limits)
        total += info.file_size
        key = "/".join(parts)
        if key in seen:
            if _same_member(zf, seen[key], info, total, where, limits):
                continue
            raise ArchiveError(f"{where}: member {name!r} occurs twice with different contents "
                               f"(also as {seen[key].filename!r})")
        seen[key] = info
        for i in range(1, len(parts)):
            prefixes.add("/".join(parts[:i]))
        if not _is_dir(info):
            files.add(key)
        checked.append((info, parts))
    clash = files & prefixes
    if clash:
        name = seen[min(clash)].filename
        raise ArchiveError(f"{where}: member {name!r} is a file but other members use it as a folder")
    return checked


def _same_member(zf: zipfile.ZipFile, first: zipfile.ZipInfo, again: zipfile.ZipInfo, before: int,
                 where: str, limits: Limits) -> bool:
    """Whether a second member of the same name is the first one again: both folders, or
    files of the same bytes (compared in full, within the limits)."""
    if _is_dir(first) or _is_dir(again):
        return _is_dir(first) and _is_dir(again)
    if first.file_size != again.file_size or first.CRC != again.CRC:
        return False
    one = _chunks(zf, first, before, where, limits)
    two = _chunks(zf, again, before, where, limits)
    return all(a == b for a, b in itertools.zip_longest(one, two))


def _is_dir(info: zipfile.ZipInfo) -> bool:
    return info.is_dir() or _file_type(info) == stat.S_IFDIR


def _check_size(info: zipfile.ZipInfo, size: int, total: int, where: str, limits: Limits) -> None:
    """Raise ArchiveError if a member of ``size`` bytes (``total`` with the members before it)
    breaks a limit: both for the sizes the headers declare and for the bytes read so far."""
    name = info.filename
    if size > limits.member_bytes:
        raise ArchiveError(f"{where}: member {name!r} is {size} bytes uncompressed, more than the limit "
                           f"of {limits.member_bytes} bytes per member")
    if total > limits.total_bytes:
        raise ArchiveError(f"{where}: the members add up to more than the limit of {limits.total_bytes} "
                           f"bytes uncompressed (at member {name!r})")
    if size > limits.ratio_floor and size > limits.ratio * max(info.compress_size, 1):
        raise ArchiveError(f"{where}: member {name!r} inflates from {info.compress_size} to {size} bytes "
                           f"or more, more than {limits.ratio:g} times (a decompression bomb?)")


def _chunks(zf: zipfile.ZipFile, info: zipfile.ZipInfo, before: int, where: str, limits: Limits):
    """The decompressed data of a member in chunks, counted as it comes: ArchiveError as
    soon as it outgrows its declared size or a limit (``before``: bytes of earlier members)."""
    done = 0
    with zf.open(info) as src:
        while chunk := src.read(_CHUNK):
            done += len(chunk)
            if done > info.file_size:
                raise ArchiveError(f"{where}: member {info.filename!r} inflates beyond its declared "
                                   f"size of {info.file_size} bytes")
            _check_size(info, done, before + done, where, limits)
            yield chunk


def read_member(archive: str | os.PathLike, member: str,
                limits: Limits = LIMITS) -> tuple[bytes | None, list[str]]:
    """The data of the file ``member`` of ``archive`` (None if it has none) and the names of
    all its files (``/``-separated), read without writing anything. Every member is checked
    as for extraction first; raises ``ArchiveError`` or ``zipfile.BadZipFile``."""
    with open_archive(archive, limits) as zf:
        checked = check_members(zf, archive, limits)
        names = ["/".join(parts) for info, parts in checked if not _is_dir(info)]
        for info, parts in checked:
            if "/".join(parts) == member and not _is_dir(info):
                return b"".join(_chunks(zf, info, 0, _describe(archive), limits)), names
    return None, names


def extract_archive(archive: str | os.PathLike, dest: str | os.PathLike, limits: Limits = LIMITS) -> Path:
    """Extract the zip file ``archive`` into the existing, empty folder ``dest``.

    Raises ``ArchiveError`` (a ValueError) before writing anything when a member is
    unsafe, and ``zipfile.BadZipFile`` when ``archive`` is not a readable zip file. On
    an error during writing, what was written is removed again. Returns ``dest``.
    """
    dest = Path(dest)
    root = dest.resolve()
    where = _describe(archive)
    with open_archive(archive, limits) as zf:
        checked = check_members(zf, archive, limits)
        total = 0
        try:
            for info, parts in checked:
                target = root.joinpath(*parts)
                try:
                    os.fsencode(target)
                except UnicodeEncodeError as exc:  # 'ö' in an ASCII locale: not unsafe, but not here
                    raise OSError(errno.EILSEQ, f"member {info.filename!r}: {unusable_path(exc)}") from None
                if not target.resolve().is_relative_to(root):  # defence in depth
                    raise ArchiveError(f"{where}: member {info.filename!r} would be written outside "
                                       "the extraction folder")
                if _is_dir(info):
                    target.mkdir(parents=True, exist_ok=True)
                    continue
                target.parent.mkdir(parents=True, exist_ok=True)
                total += _copy_member(zf, info, target, total, where, limits)
        except BaseException:
            for child in root.iterdir():
                if child.is_dir() and not child.is_symlink():
                    shutil.rmtree(child, ignore_errors=True)
                else:
                    child.unlink(missing_ok=True)
            raise
    return dest


def _copy_member(zf: zipfile.ZipFile, info: zipfile.ZipInfo, target: Path, before: int, where: str,
                 limits: Limits) -> int:
    """Write one member to ``target``; returns its size."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0) | getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(target, flags, 0o644)
    except FileExistsError:  # e.g. names differing only in case on a case-insensitive file system
        raise ArchiveError(f"{where}: member {info.filename!r} collides with another member") from None
    written = 0
    with os.fdopen(fd, "wb") as out:
        for chunk in _chunks(zf, info, before, where, limits):
            out.write(chunk)
            written += len(chunk)
    return written
