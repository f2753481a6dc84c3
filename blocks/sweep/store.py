"""The sweep's files: sweep.csv (one row per finished run, append-only) and sweep.json.

Every row is written whole with one ``write`` on a file opened for appending, then
flushed and fsynced, so an interrupted sweep (Ctrl-C, a killed process, a crash) leaves
a file whose rows are all complete; a torn last line (a power cut mid-write) is cut off
when the sweep is resumed. Resuming reads the hashes already present and runs only the
points that are missing. Parameter cells hold the value as JSON; metric cells hold the
number, or nothing when the event never happened or the run failed.
"""

from __future__ import annotations

import csv
import io
import json
import os
from pathlib import Path
from typing import Any, Sequence

from blocks.results.atomic_file import write_atomically
from .errors import SweepError

SWEEP_CSV = "sweep.csv"
SWEEP_JSON = "sweep.json"
RUNS = "runs"
"""The folder of the runs kept with ``--keep-results``: RUNS/<point hash>/ (signals.npz, run.json)."""
FIXED_COLUMNS = ("point_hash", "status", "error", "wall_s")
OK, FAILED = "ok", "failed"


def check_folder(directory: Path) -> None:
    """SweepError unless ``directory`` can hold a sweep's files, all of them inside it."""
    from blocks.results.folder import OutputFolderError, prepare
    from ..safepath import link_out_of

    try:
        prepare(directory)
    except OutputFolderError as exc:
        raise SweepError(f"sweep folder {exc}") from None
    link = link_out_of(directory, SWEEP_CSV, SWEEP_JSON, RUNS)
    if link is not None:
        raise SweepError(f"{link} is a symbolic link out of the sweep folder: the sweep writes only inside "
                         f"{directory} (hint: remove the link, or choose another -o folder)")
    for name in (SWEEP_CSV, SWEEP_JSON):
        entry = directory / name
        if entry.exists() and not entry.is_file():
            raise SweepError(f"{entry} is not a regular file (hint: move it away, or choose another -o folder)")
    if (directory / RUNS).exists() and not (directory / RUNS).is_dir():
        raise SweepError(f"{directory / RUNS} is not a folder; the sweep keeps its runs' results there (hint: move "
                         "it away, or choose another -o folder)")


def columns(parameters: Sequence[str], metrics: Sequence[str]) -> list[str]:
    """The header: the fixed columns, then the parameters, then the metrics."""
    return [*FIXED_COLUMNS, *parameters, *metrics]


class SweepStore:
    """Appends finished runs to DIR/sweep.csv; knows which points it already holds."""

    def __init__(self, directory: str | Path, parameters: Sequence[str], metrics: Sequence[str]):
        self.directory = Path(directory)
        self.path = self.directory / SWEEP_CSV
        self.parameters = list(parameters)
        self.metrics = list(metrics)
        self.header = columns(self.parameters, self.metrics)

    def open(self) -> dict[str, str]:
        """Prepare the file (header if new, torn tail cut) and return {hash: status} of the rows in it.

        A file written by a different sweep (other parameters or metrics) is refused rather
        than mixed, with a message naming both headers. A folder that cannot take the
        sweep (a file, not writable), and a ``sweep.csv``, ``sweep.json`` or ``runs`` in it
        that links out of it or is no regular file, are refused before anything is written.
        """
        check_folder(self.directory)
        if not self.path.exists() or self.path.stat().st_size == 0:
            self._append_text(_csv_line(self.header))
            return {}
        self._cut_torn_tail()
        try:
            with open(self.path, newline="", encoding="utf-8") as f:
                reader = csv.reader(f)
                header = next(reader, None)
                if header != self.header:
                    raise SweepError(f"{self.path} belongs to another sweep (columns {', '.join(header or [])[:200]}; "
                                     f"this sweep writes {', '.join(self.header)}); use another -o folder")
                return {row[0]: row[1] for row in reader if len(row) == len(self.header)}
        except (ValueError, csv.Error) as exc:  # not UTF-8, a field beyond the csv module's limit
            raise SweepError(f"{self.path}: not a sweep's CSV file: {exc}; use another -o folder") from None

    def append(self, point_hash: str, point: dict[str, Any], status: str, error: str, wall_s: float,
               values: dict[str, Any]) -> None:
        """Append one finished run as a whole line, flushed and fsynced before returning."""
        from .metrics import metric_value_text

        row = [point_hash, status, " ".join(error.split()), f"{wall_s:.6g}"]
        row += [json.dumps(point[p], default=str) for p in self.parameters]
        row += [metric_value_text(values.get(m)) for m in self.metrics]
        self._append_text(_csv_line(row))

    def write_description(self, description: dict[str, Any]) -> Path:
        """Write DIR/sweep.json atomically (a reader never sees half a file)."""
        self.directory.mkdir(parents=True, exist_ok=True)
        return write_atomically(self.directory / SWEEP_JSON, json.dumps(description, indent=2, default=str) + "\n")

    def _append_text(self, text: str) -> None:
        data = text.encode("utf-8")
        fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            written = os.write(fd, data)
            while written < len(data):
                written += os.write(fd, data[written:])
            os.fsync(fd)
        finally:
            os.close(fd)

    def _cut_torn_tail(self) -> None:
        with open(self.path, "rb+") as f:
            data = f.read()
            if data and not data.endswith(b"\n"):
                f.truncate(data.rfind(b"\n") + 1)
                f.flush()
                os.fsync(f.fileno())


def _csv_line(cells: Sequence[str]) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow(cells)
    return buf.getvalue()


class NotASweep(SweepError):
    """A folder without sweep.csv, where a finished sweep was expected."""

    def __init__(self, directory: Path, expected: str = "the output folder of a sweep"):
        super().__init__(f"{directory}: no {SWEEP_CSV} here; is this {expected}?")
        self.directory = directory


def _check_description(description: Any) -> None:
    """ValueError unless ``description`` is a sweep.json as a sweep writes it, in the fields
    that are read back: ``parameters`` a list of names, ``metrics`` and ``units`` objects."""
    if not isinstance(description, dict):
        raise ValueError(f"{SWEEP_JSON} is not a JSON object")
    kinds = {"parameters": list, "metrics": dict, "units": dict}
    for key, kind in kinds.items():
        value = description.get(key)
        if value is not None and not isinstance(value, kind):
            raise ValueError(f"{SWEEP_JSON}: '{key}' is not a JSON {'array' if kind is list else 'object'}")
    if not all(isinstance(p, str) for p in description.get("parameters") or ()):
        raise ValueError(f"{SWEEP_JSON}: 'parameters' must be names")


def read_sweep(directory: str | Path) -> tuple[dict[str, Any], list[dict[str, str]]]:
    """sweep.json and the rows of sweep.csv (the last row per point wins)."""
    directory = Path(directory)
    csv_path, json_path = directory / SWEEP_CSV, directory / SWEEP_JSON
    if not csv_path.is_file():
        raise NotASweep(directory)
    try:
        description = json.loads(json_path.read_text(encoding="utf-8")) if json_path.is_file() else {}
        _check_description(description)
        with open(csv_path, newline="", encoding="utf-8") as f:
            reader = csv.DictReader(f)
            missing = [c for c in FIXED_COLUMNS if c not in (reader.fieldnames or ())]
            if missing:
                raise ValueError(f"{SWEEP_CSV} has no column {', '.join(missing)}")
            rows = [r for r in reader if None not in r.values() and None not in r]
    except (OSError, ValueError, csv.Error) as exc:
        raise SweepError(f"{directory}: cannot read the sweep: {exc}") from None
    latest = {r["point_hash"]: r for r in rows}
    return description, list(latest.values())
