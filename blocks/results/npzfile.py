"""NPZ archives read within limits: a results folder's ``signals.npz`` and FromFile's data.

An NPZ file may come from someone else (a results folder handed over, a data file), so it
is read as data only and never trusted for sizes: it must be a regular file of at most
``limit`` bytes; each member's ``.npy`` header (shape and type) is read and checked first,
and exactly the bytes it declares are then decompressed, counted against ``limit`` for
the whole archive. A member declaring a shape of 10^12 elements, or a small file that
would inflate to gigabytes, is refused before anything is allocated; Python objects
(pickles) are refused too. Every refusal is a ValueError whose message starts with the
file's name as the caller shows it.
"""

from __future__ import annotations

import math
import os
import stat
import zipfile
from pathlib import Path

import numpy as np

from blocks.limits import MAX_DATA_BYTES
from blocks.safepath import unusable_path

MAX_MEMBERS = 1_000_000
"""Most arrays one archive may hold (a results file holds two per logged signal)."""


def read_npz(path: str | Path, shown: str, limit: int, inflation: int | None = None) -> dict[str, np.ndarray]:
    """The arrays of the NPZ file at ``path`` by name (without ``.npy``): a regular file of
    at most ``limit`` bytes whose arrays hold at most ``limit`` bytes in all, or, with
    ``inflation``, at most that many times the file's size (at least MAX_DATA_BYTES);
    ValueError starting with ``shown`` otherwise."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        raise ValueError(f"{shown}: no such file") from None
    except OSError as exc:
        raise ValueError(f"{shown}: cannot open: {exc.strerror or exc}") from None
    except ValueError as exc:
        raise ValueError(f"{shown}: cannot open: {unusable_path(exc)}") from None
    with os.fdopen(fd, "rb") as fh:
        info = os.fstat(fh.fileno())
        if not stat.S_ISREG(info.st_mode):
            raise ValueError(f"{shown} is not a regular file (a folder, device or pipe)")
        if info.st_size > limit:
            raise ValueError(f"{shown} is larger than {limit} bytes (the limit guards against hostile files)")
        budget = limit if inflation is None else max(MAX_DATA_BYTES, inflation * info.st_size)
        try:
            return _read_archive(fh, shown, budget)
        except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, OSError, NotImplementedError,
                RuntimeError) as exc:
            raise ValueError(f"{shown} is not a readable NPZ archive: {exc}") from None


def _read_archive(fh, shown: str, budget: int) -> dict[str, np.ndarray]:
    with zipfile.ZipFile(fh) as archive:
        members = archive.infolist()
        if len(members) > MAX_MEMBERS:
            raise ValueError(f"{shown} holds {len(members)} arrays, more than {MAX_MEMBERS}")
        arrays: dict[str, np.ndarray] = {}
        for member in members:
            if not member.filename.endswith(".npy"):
                raise ValueError(f"{shown}: member {member.filename!r} is not an array (.npy)")
            with archive.open(member) as stream:
                array = _read_member(stream, f"{shown}: array {member.filename[:-4]!r}", budget)
            budget -= array.nbytes
            arrays[member.filename[:-4]] = array
        return arrays


def _read_member(fh, shown: str, budget: int) -> np.ndarray:
    """One ``.npy`` member: its header checked, then exactly its declared bytes read."""
    fmt = np.lib.format
    try:
        version = fmt.read_magic(fh)
        if version == (1, 0):
            shape, fortran, dtype = fmt.read_array_header_1_0(fh)
        elif version in ((2, 0), (3, 0)):
            shape, fortran, dtype = fmt.read_array_header_2_0(fh)
        else:
            raise ValueError(f"unknown .npy format version {version}")
    except ValueError as exc:
        raise ValueError(f"{shown} has no valid array header ({' '.join(str(exc).split())[:200]})") from None
    if dtype.hasobject:
        raise ValueError(f"{shown} holds Python objects; only numbers are read")
    count = math.prod(shape)
    size = count * dtype.itemsize
    if size > budget:
        raise ValueError(f"{shown} declares shape {shape} of {dtype} ({size} bytes), beyond what the file may "
                         f"hold once decompressed (the limit guards against hostile files)")
    data = fh.read(size)
    if len(data) != size:
        raise ValueError(f"{shown} is truncated: {len(data)} of its {size} bytes")
    return np.frombuffer(data, dtype=dtype).reshape(shape, order="F" if fortran else "C").copy()
