"""Where the ``run`` command puts its results.

The output folder is checked before the run (created, a folder, writable), so a bad
``-o`` costs nothing; the files and plots are then written as one set
(``blocks.results_folder``). Should writing still fail (a full disk, a folder removed
meanwhile), the results go to a fresh temporary folder and the message says where: a long
run is not lost at its last step.
"""

from __future__ import annotations

import contextlib
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from blocks import Results
from blocks.results_folder import PLOTS, prepare, writing


@dataclass
class Saved:
    """Where the results went: ``folder`` (None: nowhere), their plots, and ``problem``,
    the line to print when they are not in the output folder."""

    folder: Path | None
    plots: list[Path] = field(default_factory=list)
    problem: str | None = None


def check_output(out: Path) -> bool:
    """Make sure ``out`` can take the results (``OutputFolderError`` if not); returns
    whether it had to be created, so that a run refused later can take it away again."""
    created = not out.exists()
    prepare(out)
    return created


def remove_if_empty(out: Path) -> None:
    """Take away an output folder made for a run that never started."""
    with contextlib.suppress(OSError):
        out.rmdir()


def save_run(results: Results, out: Path, csv: bool, plot: bool, temp_prefix: str = "results-",
             mat: bool = False, csv_digits: int | None = None) -> Saved:
    """Write the results (signals.csv with ``csv``, at ``csv_digits``, signals.mat with
    ``mat``, plots with ``plot``) into ``out``, or failing that into a new temporary folder
    whose name starts with ``temp_prefix``."""
    def write(folder: Path) -> list[Path]:
        return write_set(results, folder, csv, plot, mat=mat, csv_digits=csv_digits)

    try:
        return Saved(out, write(out))
    except OSError as exc:
        reason = describe(exc)
    spare = None
    try:
        spare = Path(tempfile.mkdtemp(prefix=temp_prefix))
        plots = write(spare)
    except OSError as exc:
        if spare is not None:
            shutil.rmtree(spare, ignore_errors=True)
        return Saved(None, problem=f"cannot save the results in {out} ({reason}) nor in a temporary "
                                   f"folder ({describe(exc)}): they are lost")
    return Saved(spare, plots, f"cannot save the results in {out}: {reason}; saved them in {spare} instead")


def write_set(results: Results, folder: Path, csv: bool, plot: bool, mat: bool = False,
              csv_digits: int | None = None) -> list[Path]:
    """The run's files, and its plots, into ``folder`` as one set; returns the plots."""
    from blocks.plot import plot_signals

    with writing(folder) as staged:
        results.write_files(staged, csv, mat=mat, csv_digits=csv_digits)
        made = plot_signals(results, staged / PLOTS / "signals.png") if plot and len(results) else []
    return [folder / PLOTS / p.name for p in made]


def describe(exc: OSError) -> str:
    """An OSError in a few words, 'No space left on device: /data/run/signals.npz' (for a
    rename, the file it was to become)."""
    path = exc.filename2 or exc.filename
    return f"{exc.strerror}: {path}" if exc.strerror and path else str(exc)
