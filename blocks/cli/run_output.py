"""Where the ``run`` command puts its results.

The output folder is checked before the run (created, a folder, writable), so a bad
``-o`` costs nothing; the files and plots are then written as one set
(``blocks.results.folder``). Should writing still fail (a full disk, a folder removed
meanwhile), the results go to a fresh temporary folder and the message says where: a long
run is not lost at its last step.
"""

from __future__ import annotations

import contextlib
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from blocks import Results
from blocks.results.folder import PLOTS, check_links, prepare, replacing_plots, writing

if TYPE_CHECKING:
    from blocks.plot.beside_run import PlotProcess


@dataclass
class Saved:
    """Where the results went: ``folder`` (None: nowhere), their plots, and ``problem``,
    the line to print when they are not in the output folder."""

    folder: Path | None
    plots: list[Path] = field(default_factory=list)
    problem: str | None = None
    kept: Path | None = None
    """Where the complete run that was in the folder went, when these results replaced it."""


def check_output(out: Path, plot: bool = False) -> bool:
    """Make sure ``out`` can take the results (``OutputFolderError`` if not), plots too
    with ``plot``; returns whether it had to be created, so that a run refused later can
    take it away again."""
    created = not out.exists()
    prepare(out)
    check_links(out, plot)
    return created


def remove_if_empty(out: Path) -> None:
    """Take away an output folder made for a run that never started."""
    with contextlib.suppress(OSError):
        out.rmdir()


def save_run(results: Results, out: Path, csv: bool, temp_prefix: str = "results-", mat: bool = False,
             csv_digits: int | None = None) -> Saved:
    """Write the results (signals.csv with ``csv``, at ``csv_digits``, signals.mat with
    ``mat``) into ``out``, or failing that into a new temporary folder whose name starts
    with ``temp_prefix``."""
    kept: list[Path] = []
    try:
        with writing(out, kept) as staged:
            results.write_files(staged, csv, mat=mat, csv_digits=csv_digits)
        return Saved(out, kept=kept[0] if kept else None)
    except OSError as exc:
        reason = describe(exc)
    spare = None
    try:
        spare = Path(tempfile.mkdtemp(prefix=temp_prefix))
        results.save(spare, csv, mat=mat, csv_digits=csv_digits)
    except OSError as exc:
        if spare is not None:
            shutil.rmtree(spare, ignore_errors=True)
        return Saved(None, problem=f"cannot save the results in {out} ({reason}) nor in a temporary "
                                   f"folder ({describe(exc)}): they are lost")
    return Saved(spare, problem=f"cannot save the results in {out}: {reason}; saved them in {spare} instead")


def save_plots(results: Results, saved: Saved, plotter: PlotProcess | None = None) -> None:
    """Draw the saved results' plots into their folder's ``plots/`` (replacing the earlier
    run's as a set), by ``plotter`` if there is one, else here; a stop request ends the
    drawing and leaves no plot of this run. A folder that cannot take them, or a plotter
    that fails, sets ``saved.problem``."""
    from blocks.plot.pages import plot_signals
    from blocks.plot.beside_run import PlotProcessError

    if not len(results):
        return
    try:
        with replacing_plots(saved.folder) as staged:
            target = staged / "signals.png"
            made = plot_signals(results, target) if plotter is None else plotter.draw(saved.folder, target)
        saved.plots = [saved.folder / PLOTS / p.name for p in made]
    except (OSError, PlotProcessError) as exc:
        why = describe(exc) if isinstance(exc, OSError) else exc
        saved.problem = f"the results are saved in {saved.folder}, but not their plots: {why}"


def describe(exc: OSError) -> str:
    """An OSError in a few words, 'No space left on device: /data/run/signals.npz' (for a
    rename, the file it was to become)."""
    path = exc.filename2 or exc.filename
    return f"{exc.strerror}: {path}" if exc.strerror and path else str(exc)
