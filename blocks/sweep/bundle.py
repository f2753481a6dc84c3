"""A diagram as content: its YAML text and every file it reads, for workers that cannot see them.

A sweep's workers may run on other machines, with other folders, so a point never loads
the diagram from the client's path. ``make_bundle`` reads the diagram's text and every
file the loader reports it read (``Diagram.files``: params files, files named by path
parameters such as an FMU's ``path``, ``python:`` modules from the diagram's folder), each
stored once by its sha256. A bundle's ``hash`` covers the text and, for every reference the
diagram makes, the content it names (an FMU's bytes included), never where the files lie:
it is what the sweep's point hashes are made from, so a changed params file or FMU makes
new points rather than reusing old rows.

In each process that runs points the bundle is written once into a private temporary
folder (``folder``, in the scratch root of ``blocks.process.scratch``, which the sweep's process
removes at its exit, also after a runner was killed under it), keyed by its hash, each file checked against its sha256 first. The
files keep the layout the diagram expects: the diagram's folder is a subfolder deep enough
that ``../fmu/X.fmu`` lands inside the bundle folder; a file named by an absolute path goes
to ``abs/<sha256>/NAME``. The diagram is then loaded from its text with ``files`` mapping
each reference to its copy (``blocks.diagram_file.load.loads_diagram``), and with the client's file name
and folder, so its parameters and run.json name the paths the user gave. The Dask
execution sends the files to every worker once with a worker plugin
(``worker_plugin.DiagramFiles``) and the tasks carry only the ``manifest`` (no file
content); the serial execution uses the same bundle in its own process.
"""

from __future__ import annotations

import atexit
import hashlib
import json
import os
import posixpath
import shutil
import threading
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Iterable, Mapping

from blocks.process import scratch
from blocks.diagram_file.reader import CODE_DIR_KEY

from .errors import SweepError

TEMP_PREFIX = "bundle-"
"""Prefix of the temporary folders bundles are written into (in the scratch root, ``blocks.process.scratch``)."""


class BundleError(SweepError):
    """A bundle that cannot be made or written, or whose files did not reach this process."""


@dataclass(frozen=True)
class BundleFile:
    """A file of the bundle: the reference the diagram makes to it, its place in the
    bundle folder, its sha256 and size."""

    ref: str
    name: str
    sha256: str
    size: int


@dataclass(frozen=True)
class DiagramBundle:
    """A diagram's text and files, by content (``blobs``: sha256 -> bytes; None in a manifest)."""

    filename: str
    """The diagram file as the user gave it: messages and run.json's ``diagram_file``."""
    base_dir: str
    """Its folder as the client saw it: relative paths in its parameters resolve against it."""
    diagram: str
    """The diagram file's place in the bundle folder (posix, relative)."""
    text: str
    files: tuple[BundleFile, ...]
    hash: str
    blobs: Mapping[str, bytes] | None = None
    ssp: bool = False
    """The diagram is an SSP: ``diagram`` is its archive (a folder SSP zipped), ``text`` empty."""
    step: str | None = None
    """For an SSP, the step of the components whose SSD gives none (``--step``)."""

    def manifest(self) -> "DiagramBundle":
        """This bundle without the files' content: what a task carries."""
        return replace(self, blobs=None)

    @property
    def size(self) -> int:
        """Bytes of the files' content (each distinct file once) and the text."""
        return len(self.text.encode("utf-8")) + sum({f.sha256: f.size for f in self.files}.values())

    def file_map(self, folder: Path) -> dict[str, Path]:
        """Each reference -> its copy in ``folder``, and the diagram's folder's copy."""
        files = {f.ref: folder / f.name for f in self.files}
        files[CODE_DIR_KEY] = (folder / self.diagram).parent
        return files

    def load(self, overrides: Mapping[str, Any] | None = None, trust: bool = False,
             origins: Mapping[str, str] | None = None):
        """The diagram, loaded from this bundle's copy of its files (written on first use)."""
        from blocks import load_diagram, loads_diagram

        if self.ssp:
            return load_diagram(folder(self) / self.diagram, overrides=overrides, trust=trust, origins=origins,
                                step=self.step)
        return loads_diagram(self.text, filename=self.filename, base_dir=self.base_dir, overrides=overrides,
                             trust=trust, origins=origins, files=self.file_map(folder(self)))


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _layout_name(ref: str, sha: str, diagram_dir: str) -> str:
    path = Path(ref).expanduser()
    if path.is_absolute():
        return f"abs/{sha[:16]}/{path.name or 'file'}"
    return posixpath.normpath(posixpath.join(diagram_dir, Path(ref).as_posix()))


def make_bundle(path: str | Path, files: Mapping[str, Path], text: str | None = None,
                step: str | None = None) -> DiagramBundle:
    """The bundle of the diagram file ``path`` with ``files`` (reference -> file to read, as
    ``Diagram.files``); ``text``: the diagram's text if already read. An SSP is bundled as
    its archive alone (its FMUs are inside), with ``step`` (``--step``)."""
    from blocks.ssp import is_ssp
    from blocks.diagram_file.yaml_source import read_yaml_file

    path = Path(path)
    if is_ssp(path):
        return _ssp_bundle(path, step)
    try:
        text = read_yaml_file(path) if text is None else text
        contents = {ref: Path(real).read_bytes() for ref, real in sorted(files.items())}
    except OSError as exc:
        raise BundleError(f"cannot read the diagram's files: {exc}") from None
    shas = {ref: _sha256(data) for ref, data in contents.items()}
    relative = [Path(ref).as_posix() for ref in contents if not Path(ref).expanduser().is_absolute()]
    depth = max((_ups(r) for r in relative), default=0)
    parents = Path(path.parent.resolve()).parts[1:]
    above = list(parents[len(parents) - depth:]) if depth <= len(parents) else []
    above = ["up"] * (depth - len(above)) + above
    diagram_dir = posixpath.join("tree", *above)
    bundle_files, used = [], {posixpath.join(diagram_dir, path.name): _sha256(text.encode("utf-8"))}
    for ref, data in contents.items():
        sha = shas[ref]
        name = _layout_name(ref, sha, diagram_dir)
        if used.setdefault(name, sha) != sha:  # the same name for other content (links): a place of its own
            name = f"other/{sha[:16]}/{posixpath.basename(name)}"
        bundle_files.append(BundleFile(ref, name, sha, len(data)))
    identity = {"text": _sha256(text.encode("utf-8")), "files": sorted([ref, shas[ref]] for ref in contents)}
    digest = _sha256(json.dumps(identity, sort_keys=True).encode("utf-8"))
    return DiagramBundle(filename=str(path), base_dir=str(path.parent), diagram=posixpath.join(diagram_dir, path.name),
                         text=text, files=tuple(bundle_files), hash=digest,
                         blobs={shas[ref]: data for ref, data in contents.items()})


def _ssp_bundle(path: Path, step: str | None) -> DiagramBundle:
    """An SSP's bundle: the archive's bytes (a folder's, or an ``.ssd`` file's folder,
    zipped with its files in name order), its hash covering them and ``step``."""
    try:
        if path.is_file() and path.suffix.lower() == ".ssp":
            data = path.read_bytes()
        else:
            data = _zipped(path if path.is_dir() else path.parent)
    except OSError as exc:
        raise BundleError(f"cannot read the SSP {path}: {exc.strerror or exc}") from None
    sha = _sha256(data)
    name = f"tree/{path.stem or 'system'}.ssp"
    digest = _sha256(json.dumps({"ssp": sha, "step": step}, sort_keys=True).encode("utf-8"))
    return DiagramBundle(filename=str(path), base_dir=str(path.parent), diagram=name, text="",
                         files=(BundleFile(str(path), name, sha, len(data)),), hash=digest, blobs={sha: data},
                         ssp=True, step=step)


def _zipped(folder: Path) -> bytes:
    """The files under ``folder`` (links and all: the SSP reader refuses them) as a zip."""
    import io
    import zipfile

    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for file in sorted(folder.rglob("*")):
            if file.is_file() or file.is_symlink():
                info = zipfile.ZipInfo(file.relative_to(folder).as_posix(), date_time=(1980, 1, 1, 0, 0, 0))
                archive.writestr(info, file.read_bytes(), zipfile.ZIP_DEFLATED)
    return buffer.getvalue()


def _ups(ref: str) -> int:
    """How many folders above the diagram's folder a relative reference reaches."""
    level = low = 0
    for part in ref.split("/"):
        if part == "..":
            level -= 1
            low = min(low, level)
        elif part not in ("", "."):
            level += 1
    return -low


def bundle_for(path: str | Path, diagrams: Iterable[Any], more: Mapping[str, Path] | None = None,
               step: str | None = None) -> DiagramBundle:
    """The bundle of the diagram file ``path`` with the files that any of ``diagrams``
    (loaded from it, with different overrides) read, and ``more`` (reference -> file);
    ``step``: an SSP's ``--step``."""
    files: dict[str, Path] = {}
    for diagram in diagrams:
        files.update(diagram.files)
    files.update(more or {})
    return make_bundle(path, files, step=step)


# -- the copies in this process ----------------------------------------------------------

_lock = threading.RLock()
_written: dict[str, list] = {}
"""bundle hash -> [pid, folder, holders, bundle]: the copies written by this process (the
bundle with its content, to write the copy again should it be removed under a run)."""


def folder(bundle: DiagramBundle) -> Path:
    """The folder holding this process's copy of the bundle, written on first use.

    A copy whose files are gone or changed in size is written again. A bundle without
    content (a manifest) must have been written here before (by ``hold``: the worker
    plugin); otherwise BundleError.
    """
    with _lock:
        entry = _written.get(bundle.hash)
        if entry is not None and entry[0] == os.getpid():
            if _intact(bundle, entry[1]):
                return entry[1]
            if bundle.blobs is None:
                bundle = _full(bundle)
            shutil.rmtree(entry[1], ignore_errors=True)
            holders = entry[2]
        else:
            holders = 0
        if bundle.blobs is None:
            raise BundleError(f"the files of diagram {bundle.filename} (bundle {bundle.hash[:12]}) were not "
                              "sent to this process")
        target = _write(bundle)
        _written[bundle.hash] = [os.getpid(), target, holders, bundle]
        return target


def _full(bundle: DiagramBundle) -> DiagramBundle:
    entry = _written.get(bundle.hash)
    if entry is not None and len(entry) > 3 and entry[3].blobs is not None:
        return entry[3]
    raise BundleError(f"the copy of diagram {bundle.filename}'s files in {entry[1] if entry else '?'} was "
                      "changed or removed, and its content is not in this process")


def _intact(bundle: DiagramBundle, target: Path) -> bool:
    try:
        return all((target / f.name).stat().st_size == f.size for f in bundle.files)
    except OSError:
        return False


def _write(bundle: DiagramBundle) -> Path:
    target = scratch.folder(f"{TEMP_PREFIX}{bundle.hash[:12]}-")
    try:
        for f in bundle.files:
            data = bundle.blobs.get(f.sha256)
            if data is None or _sha256(data) != f.sha256:
                raise BundleError(f"diagram {bundle.filename}: the content sent for {f.ref} does not match its "
                                  f"sha256 {f.sha256[:12]}")
            place = target / f.name
            place.parent.mkdir(parents=True, exist_ok=True)
            if not place.exists():
                place.write_bytes(data)
        if not bundle.ssp:  # an SSP's archive is one of its files
            place = target / bundle.diagram
            place.parent.mkdir(parents=True, exist_ok=True)
            place.write_text(bundle.text, encoding="utf-8")
    except BaseException:
        shutil.rmtree(target, ignore_errors=True)
        raise
    return target


def hold(bundle: DiagramBundle) -> Path:
    """Write the bundle here (if not yet) and keep it until as many ``release`` calls."""
    with _lock:
        target = folder(bundle)
        _written[bundle.hash][2] += 1
        return target


def release(bundle_hash: str) -> None:
    """One holder fewer; the copy is removed when none is left."""
    with _lock:
        entry = _written.get(bundle_hash)
        if entry is None or entry[0] != os.getpid():
            return
        entry[2] -= 1
        if entry[2] <= 0:
            del _written[bundle_hash]
            shutil.rmtree(entry[1], ignore_errors=True)


def discard(bundle_hash: str) -> None:
    """Remove this process's copy unless a worker plugin holds it."""
    with _lock:
        entry = _written.get(bundle_hash)
        if entry is not None and entry[0] == os.getpid() and entry[2] <= 0:
            del _written[bundle_hash]
            shutil.rmtree(entry[1], ignore_errors=True)


@atexit.register
def _remove_all() -> None:
    for entry in list(_written.values()):
        if entry[0] == os.getpid():
            shutil.rmtree(entry[1], ignore_errors=True)
