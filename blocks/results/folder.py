"""A results folder written as one consistent set of files, whoever else writes there.

A run's files (signals.npz, run.json, signals.csv with --csv, signals.mat with --mat,
plots/signals*.png with --plot) must belong together: two runs into one folder must
never leave one run's run.json beside the other's signals.npz, nor a run without --csv
an earlier run's signals.csv. So a run writes its files into a private staging folder inside the results
folder, then, holding an exclusive lock on the folder, replaces the previous run's result
files with them: run.json is removed first and put in last, so a folder with a run.json
holds one complete set, and a folder left without one (the machine stopped while the
files were replaced) reads as incomplete, never as a mix. Readers hold a shared lock, so
they never see a set half replaced either.

The result files belong to the run that wrote them and go when the next run replaces
them; any other file in the folder is the user's and stays. Locks are POSIX ``flock``
on the folder; where there is none (Windows), writers are not serialised.
"""

from __future__ import annotations

import contextlib
import itertools
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Iterator

try:
    import fcntl
except ImportError:  # Windows: no flock
    fcntl = None

SIGNALS_NPZ = "signals.npz"
SIGNALS_CSV = "signals.csv"
SIGNALS_MAT = "signals.mat"
RUN_JSON = "run.json"
PLOTS = "plots"
PLOT_PATTERN = "signals*.png"
STAGING_PREFIX = ".blocks-staging-"
"""Prefix of the private folders that runs write into before their files replace the old ones."""
STAGING_MARK = ".blocks-staging"
"""The file inside each staging folder that makes it one: only folders with the prefix and
this file are ever removed as a dead writer's, so a user's ``.staging-notes/`` (or even a
``.blocks-staging-x/`` of their own) stays."""
KEPT_PREFIX = "previous-complete-run"
"""Name (``-2``, ``-3``, ... when taken) of the folder that keeps a complete run's files when
a failed or interrupted run replaces them."""


class OutputFolderError(OSError):
    """A results folder that cannot be created or written: '``directory`` ``reason``'."""

    def __init__(self, directory: Path, reason: str):
        super().__init__(f"{directory} {reason}")
        self.reason = reason


def prepare(directory: str | Path) -> Path:
    """Create ``directory`` if needed and prove that this process can write in it (a probe
    file is created and removed), so that a bad output folder is found before a run rather
    than after it, when the results would have nowhere to go."""
    directory = Path(directory)
    if directory.exists() and not directory.is_dir():
        raise OutputFolderError(directory, "is a file, not a folder")
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        blocker = next((p for p in directory.parents if p.exists() and not p.is_dir()), directory)
        raise OutputFolderError(directory, f"cannot be created: {blocker} is a file") from None
    except OSError as exc:
        raise OutputFolderError(directory, f"cannot be created: {exc.strerror or exc}") from None
    try:
        fd, probe = tempfile.mkstemp(prefix=".write-probe-", dir=directory)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise OutputFolderError(directory, f"is not writable: {exc.strerror or exc}") from None
    return directory


def check_links(directory: str | Path, plots: bool) -> None:
    """OutputFolderError if the run would write through a link out of ``directory``: a
    ``plots`` that links elsewhere, when the run is to draw plots."""
    from blocks.safepath import link_out_of

    link = link_out_of(directory, PLOTS) if plots else None
    if link is not None:
        raise OutputFolderError(Path(directory), f"holds {PLOTS}, a symbolic link out of it: plots are written "
                                "only inside the output folder (hint: remove the link, or choose another -o)")


@contextlib.contextmanager
def writing(directory: str | Path, kept: list[Path] | None = None) -> Iterator[Path]:
    """A fresh staging folder for one run's files; when the block ends without an error,
    they replace the result files in ``directory`` as one set (see the module's note).
    On an error the staging folder goes and the folder is left as it was.

    Files of a complete run are never replaced by those of a failed or interrupted one:
    they move into a new folder ``previous-complete-run`` (``-2``, ...) inside
    ``directory``, which the new run.json names (``previous_complete_run``) and which is
    appended to ``kept``."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    with _locked(directory, exclusive=True) as locked:
        if locked:
            for stale in directory.glob(STAGING_PREFIX + "*"):
                if (stale / STAGING_MARK).is_file() and not stale.is_symlink():
                    shutil.rmtree(stale, ignore_errors=True)  # a writer that died: only writers hold the lock
        staged = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=directory))
        try:
            (staged / STAGING_MARK).touch()
            yield staged
            folder = _replace(directory, staged)
            if folder is not None and kept is not None:
                kept.append(folder)
        finally:
            shutil.rmtree(staged, ignore_errors=True)


@contextlib.contextmanager
def replacing_plots(directory: str | Path) -> Iterator[Path]:
    """A fresh staging folder for a run's plots; when the block ends without an error they
    replace the ``plots/signals*.png`` in ``directory``; otherwise they go, and nothing
    else changes. A ``plots`` linking out of ``directory`` is refused (OutputFolderError)."""
    directory = Path(directory)
    check_links(directory, plots=True)
    staged = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=directory))
    try:
        (staged / STAGING_MARK).touch()
        yield staged
        with _locked(directory, exclusive=True):
            check_links(directory, plots=True)
            _replace_plots(directory / PLOTS, staged)
    finally:
        shutil.rmtree(staged, ignore_errors=True)


@contextlib.contextmanager
def reading(directory: str | Path) -> Iterator[None]:
    """Hold a shared lock on ``directory`` while its files are read."""
    with _locked(Path(directory), exclusive=False):
        yield


def _replace(directory: Path, staged: Path) -> Path | None:
    """Put the staged files in place of the folder's result files, run.json last; returns
    the folder that keeps a complete run's files the staged ones would have replaced."""
    from blocks.safepath import link_out_of

    plots_link = link_out_of(directory, PLOTS) is not None
    if plots_link and (staged / PLOTS).is_dir():
        check_links(directory, plots=True)
    marker = directory / RUN_JSON
    kept = None
    if _status(marker) == "complete" and _status(staged / RUN_JSON) not in (None, "complete"):
        kept = _keep(directory, plots_link)
        _note_kept(staged / RUN_JSON, kept.name)
    marker.unlink(missing_ok=True)
    for name in (SIGNALS_NPZ, SIGNALS_CSV, SIGNALS_MAT):
        if (staged / name).exists():
            os.replace(staged / name, directory / name)
        else:
            (directory / name).unlink(missing_ok=True)
    if not plots_link:
        _replace_plots(directory / PLOTS, staged / PLOTS)
    if (staged / RUN_JSON).exists():
        os.replace(staged / RUN_JSON, marker)
    return kept


def _status(run_json: Path) -> str | None:
    """The status a run.json records (None for none, or one that is not a run's record)."""
    try:
        if not run_json.is_file() or run_json.stat().st_size > 1 << 24:
            return None
        info = json.loads(run_json.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    status = info.get("status", "complete") if isinstance(info, dict) else None
    return status if isinstance(status, str) else None


def _keep(directory: Path, plots_link: bool) -> Path:
    """Move the folder's result files (a complete run's) into a new folder inside it."""
    for n in itertools.count(1):
        kept = directory / (KEPT_PREFIX if n == 1 else f"{KEPT_PREFIX}-{n}")
        try:
            kept.mkdir()
            break
        except FileExistsError:
            continue
    for name in (SIGNALS_NPZ, SIGNALS_CSV, SIGNALS_MAT, RUN_JSON):
        if os.path.lexists(directory / name):
            os.replace(directory / name, kept / name)
    plots = directory / PLOTS
    if not plots_link and plots.is_dir():
        old = sorted(plots.glob(PLOT_PATTERN))
        if old:
            (kept / PLOTS).mkdir()
        for path in old:
            os.replace(path, kept / PLOTS / path.name)
    return kept


def _note_kept(run_json: Path, name: str) -> None:
    info = json.loads(run_json.read_text(encoding="utf-8"))
    info["previous_complete_run"] = name
    run_json.write_text(json.dumps(info, indent=2, default=str) + "\n", encoding="utf-8")


def _replace_plots(plots: Path, staged: Path) -> None:
    new = sorted(staged.glob(PLOT_PATTERN)) if staged.is_dir() else []
    old = {p.name for p in plots.glob(PLOT_PATTERN)} if plots.is_dir() else set()
    if new:
        plots.mkdir(exist_ok=True)
    for path in new:
        os.replace(path, plots / path.name)
    for name in old - {p.name for p in new}:
        (plots / name).unlink(missing_ok=True)
    if old and not new and not any(plots.iterdir()):
        plots.rmdir()


@contextlib.contextmanager
def _locked(directory: Path, exclusive: bool) -> Iterator[bool]:
    """flock ``directory``; yields whether the lock is held (False where locks are unavailable)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        yield False
        return
    try:
        held = False
        if fcntl is not None:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH)
                held = True
            except OSError:  # a file system without locks: go on unserialised
                pass
        yield held
    finally:
        os.close(fd)
