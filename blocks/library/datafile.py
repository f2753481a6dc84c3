"""Time series read from a CSV or NPZ file, for FromFile, within the limits of blocks.limits.

A CSV file has a time column first and a column per element, with or without a header row
(a header names the elements); ``signals.csv`` of a run reads as it is, and ``signal``
picks the columns of one signal (``plant.q`` takes ``plant.q[thumb.1]``, ...). An NPZ file
holds a ``time`` array and the values, (n,) or (n, width); ``signal`` names the values'
array, and its times are ``time:<signal>`` where there is such an array (as in a run's
``signals.npz``), else ``time``. Times must be finite and non-decreasing (equal times make
a step), values finite. Every problem is one ValueError naming the file.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from blocks.limits import MAX_DATA_BYTES
from blocks.results.npzfile import read_npz
from blocks.diagram_file.yaml_source import YamlSourceError, read_yaml_file

TIME_PREFIX = "time:"


@dataclass(frozen=True)
class Series:
    """Sample times (n,), values (n, width) and the elements' names (None: numbered)."""

    times: np.ndarray
    values: np.ndarray
    labels: list[str] | None


def read_series(path: str | Path, signal: str | None = None) -> Series:
    """The time series in ``path`` (.csv or .npz, by its suffix)."""
    path = Path(path)
    shown = f"data file '{path}'"
    suffix = path.suffix.lower()
    if suffix not in (".csv", ".npz"):
        raise ValueError(f"{shown}: the name must end in .csv or .npz, got {path.suffix or 'no suffix'!r}")
    if not path.exists():
        raise ValueError(f"{shown} not found (in a diagram, a relative path is resolved against the diagram's "
                         "folder)")
    series = _read_csv(path, signal, shown) if suffix == ".csv" else _read_npz(path, signal, shown)
    _check(series, shown)
    return series


def _read_csv(path: Path, signal: str | None, shown: str) -> Series:
    try:
        text = read_yaml_file(path, kind="CSV")
    except YamlSourceError as exc:
        where = f" line {exc.line}" if exc.line else ""
        raise ValueError(f"{shown}{where}: {exc.message}") from None
    rows = [row for row in csv.reader(io.StringIO(text)) if any(cell.strip() for cell in row)]
    if not rows:
        raise ValueError(f"{shown} is empty")
    header = None
    if not _numeric(rows[0]):
        header, rows = [cell.strip() for cell in rows[0]], rows[1:]
    if not rows:
        raise ValueError(f"{shown} has a header but no rows")
    columns = len(rows[0])
    if columns < 2:
        raise ValueError(f"{shown}: a row needs a time and at least one value, got {columns} column")
    table = np.empty((len(rows), columns))
    for r, row in enumerate(rows):
        line = r + (2 if header else 1)
        if len(row) != columns:
            raise ValueError(f"{shown} line {line}: {len(row)} values, the first row has {columns}")
        for k, cell in enumerate(row):
            try:
                table[r, k] = float(cell)
            except ValueError:
                raise ValueError(f"{shown} line {line}, column {k + 1}: {cell.strip()!r} is not a number") from None
    labels = header[1:] if header is not None else None
    picked = list(range(1, columns))
    if signal is not None:
        if labels is None:
            raise ValueError(f"{shown} has no header row, so 'signal' cannot pick columns by name")
        picked, elements = [], []
        for k, name in enumerate(labels, start=1):
            if name == signal or (name.startswith(signal + "[") and name.endswith("]")):
                picked.append(k)
                elements.append(name[len(signal) + 1:-1])
        if not picked:
            raise ValueError(f"{shown} has no column '{signal}' or '{signal}[...]'; columns: {', '.join(labels)}")
        labels = elements if all(elements) else None
    return Series(table[:, 0].copy(), table[:, picked].copy(), labels)


def _numeric(row: list[str]) -> bool:
    try:
        [float(cell) for cell in row]
    except ValueError:
        return False
    return True


def _read_npz(path: Path, signal: str | None, shown: str) -> Series:
    arrays = read_npz(path, shown, MAX_DATA_BYTES)
    names = list(arrays)
    values_key = signal if signal is not None else _only_values(names, shown)
    time_key = TIME_PREFIX + values_key if TIME_PREFIX + values_key in names else "time"
    missing = [k for k in (values_key, time_key) if k not in names]
    if missing:
        raise ValueError(f"{shown} has no array '{missing[0]}'; arrays: {', '.join(names) or 'none'}")
    times, values = arrays[time_key], arrays[values_key]
    for key, arr in ((time_key, times), (values_key, values)):
        if not np.issubdtype(arr.dtype, np.number) or np.issubdtype(arr.dtype, np.complexfloating):
            raise ValueError(f"{shown}: array '{key}' must hold real numbers, got {arr.dtype}")
    if times.ndim != 1 or values.ndim not in (1, 2) or values.shape[0] != times.shape[0]:
        raise ValueError(f"{shown}: '{time_key}' must have shape (n,) and '{values_key}' (n,) or (n, width), got "
                         f"{times.shape} and {values.shape}")
    return Series(times.astype(float), values.astype(float).reshape(times.size, -1), None)


def _only_values(names: list[str], shown: str) -> str:
    rest = [n for n in names if n != "time" and not n.startswith(TIME_PREFIX)]
    if "time" in names and "values" in rest:
        return "values"
    if "time" in names and len(rest) == 1:
        return rest[0]
    raise ValueError(f"{shown}: name the array to read with 'signal' (arrays: {', '.join(names) or 'none'})")


def _check(series: Series, shown: str) -> None:
    times, values = series.times, series.values
    if times.size == 0 or values.shape[1] == 0:
        raise ValueError(f"{shown} holds no samples")
    if not np.all(np.isfinite(times)):
        raise ValueError(f"{shown}: the times must be finite (row {int(np.argmin(np.isfinite(times))) + 1})")
    if np.any(times[1:] < times[:-1]):  # compared, not subtracted: times of +-1e308 overflow a difference
        row = int(np.argmax(times[1:] < times[:-1])) + 2
        raise ValueError(f"{shown}: the times must not decrease (row {row} is earlier than the row before)")
    if not np.all(np.isfinite(values)):
        row = int(np.argmax(~np.all(np.isfinite(values), axis=1))) + 1
        raise ValueError(f"{shown}: the values must be finite (row {row})")
