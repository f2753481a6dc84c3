"""An SSP as files: a zip archive (``.ssp``) or an unpacked folder with ``SystemStructure.ssd``.

An archive comes from another tool, so it is unpacked by the FMU block's rules
(``blocks.fmu.archive``: no absolute names, ``..``, links or special files; size,
member-count and inflation limits) into a private folder, once per process and archive
content; the folder is removed when the process ends. The files an SSD names (FMUs,
``.ssv``, ``.ssm``) are resolved against the SSD's folder and must lie inside the package:
an SSP never reads a file of the user's outside it. Nothing in it is run here.
"""

from __future__ import annotations

import atexit
import hashlib
import shutil
import threading
import zipfile
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from urllib.parse import unquote, urlparse

from blocks.process import scratch
from ..fmu.archive import ArchiveError, NotARegularFile, extract_archive, file_kind, open_regular
from ..safepath import inside
from .names import SSD_NAME

_unpacked: dict[str, Path] = {}
_lock = threading.Lock()


class PackageError(ValueError):
    """An SSP that cannot be opened: the message names the file and what is wrong."""


@dataclass(frozen=True)
class Package:
    """An opened SSP: ``root`` the folder its files are read from, ``shown`` how messages
    name it (the path the user gave), ``ssd`` the SystemStructure.ssd to read."""

    root: Path
    shown: str
    ssd: Path

    def where(self, path: Path) -> str:
        """A file of the package as messages name it: ``sys.ssp/resources/a.ssv``."""
        try:
            return f"{self.shown}/{path.relative_to(self.root).as_posix()}"
        except ValueError:
            return str(path)

    def resolve(self, reference: str, base: Path | None = None) -> Path:
        """The file a URI of the SSD names (relative to ``base``, default the SSD's folder);
        PackageError for one outside the package, a URI of another scheme, or a missing file."""
        text = (reference or "").strip()
        parsed = urlparse(text)
        if parsed.scheme not in ("", "file") or parsed.netloc:
            raise PackageError(f"'{text}' is not a file of the SSP (only relative references into the package "
                               "are read)")
        rel = unquote(parsed.path)
        if not rel or PurePosixPath(rel).is_absolute():
            raise PackageError(f"'{text}' must be a path relative to the SSD, inside the SSP")
        target = (base or self.ssd.parent) / rel
        if not inside(target, self.root):
            raise PackageError(f"'{text}' lies outside the SSP")
        if not target.is_file():
            if target.exists():
                raise PackageError(f"'{text}' is {file_kind(target.stat().st_mode)}, not a regular file "
                                   f"({self.where(target)})")
            raise PackageError(f"'{text}' is not in the SSP (looked at {self.where(target)})")
        return target

    def relative(self, path: Path) -> str:
        """``path`` relative to the SSD's folder, posix: what a diagram's FMU path says."""
        return path.resolve().relative_to(self.ssd.parent.resolve()).as_posix()


def open_package(path: str | Path) -> Package:
    """The SSP at ``path`` (archive, folder or its ``.ssd`` file), unpacked if an archive."""
    p = Path(path)
    shown = str(path)
    if p.is_dir():
        ssd = p / SSD_NAME
        if not ssd.is_file():
            raise PackageError(f"{shown}: the folder has no {SSD_NAME}")
        return Package(p, shown, ssd)
    if not p.exists():
        raise PackageError(f"{shown}: SSP not found")
    if p.suffix.lower() == ".ssd":
        return Package(p.parent, str(p.parent), p)
    root = _unpack(p, shown)
    ssd = root / SSD_NAME
    if not ssd.is_file():
        raise PackageError(f"{shown}: the archive has no {SSD_NAME} at its root")
    return Package(root, shown, ssd)


def _unpack(path: Path, shown: str) -> Path:
    """The folder the archive ``path`` is unpacked in, by the FMU archive rules; one per
    archive content in this process."""
    try:
        with open_regular(path) as fp:
            digest = hashlib.file_digest(fp, "sha256").hexdigest()
    except NotARegularFile:
        raise PackageError(f"{shown} is not an SSP: not a regular file") from None
    except OSError as exc:
        raise PackageError(f"{shown}: cannot be read: {exc.strerror or exc}") from None
    with _lock:
        found = _unpacked.get(digest)
        if found is not None and found.is_dir():
            return found
        dest = scratch.folder("ssp-")
        try:
            extract_archive(path, dest)
        except ArchiveError as exc:
            shutil.rmtree(dest, ignore_errors=True)
            raise PackageError(f"unsafe SSP archive, not unpacked: {exc}") from None
        except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, NotImplementedError) as exc:
            shutil.rmtree(dest, ignore_errors=True)
            raise PackageError(f"{shown} is not an SSP: not a readable zip archive ({exc})") from None
        except OSError as exc:
            shutil.rmtree(dest, ignore_errors=True)
            raise PackageError(f"{shown}: cannot be unpacked: {exc.strerror or exc}") from None
        atexit.register(shutil.rmtree, dest, True)
        _unpacked[digest] = dest
        return dest
