"""Logged signals of a run, their files (signals.npz, signals.csv, run.json) and reloading.

Each signal keeps its own sample times. A run's files replace the previous run's in the
results folder as one set (``results_folder``), so a reader never sees half a file nor
files of two runs, and a failed or interrupted run's partial results are saved the same
way with a status saying where it stopped.
"""

from __future__ import annotations

import csv
import io
import json
import os
import re
from pathlib import Path
from typing import Iterator

import numpy as np

from blocks.builder.api_args import boolean
from blocks.limits import MAX_RESULTS_BYTES
from blocks.results.npzfile import read_npz
from blocks.results.folder import RUN_JSON, SIGNALS_CSV, SIGNALS_MAT, SIGNALS_NPZ, reading, writing

TIME_PREFIX = "time:"


def held_index(t: np.ndarray, times, rtol: float = 0.0) -> np.ndarray:
    """Zero-order hold: for each of ``times``, the index into the sample times ``t`` of the
    last sample at or before it (-1 if there is none).

    With ``rtol``, a sample up to ``rtol * max(1, max |times|)`` after a time counts as at
    it: times computed in floats (a frame every 1/25 s) that stand for sample times land
    on those samples rather than one sample short.
    """
    times = np.asarray(times, dtype=float)
    if rtol:
        times = times + rtol * max(1.0, float(np.abs(times).max(initial=0.0)))
    return np.searchsorted(t, times, side="right") - 1


CSV_ROWS = 4096
"""Rows of signals.csv formatted at a time."""


def check_digits(digits: int | None) -> None:
    """ValueError unless ``digits`` is None (shortest round trip) or 1 to 17."""
    if digits is not None and (isinstance(digits, bool) or not isinstance(digits, int) or not 1 <= digits <= 17):
        raise ValueError(f"CSV digits must be a whole number from 1 to 17 (17 keeps every double), got {digits!r}")


class ResultsError(Exception):
    """A results folder that cannot be read."""


class Results:
    """Logged signals by name ``block.port``: ``results[name] -> (t, values)``.

    ``values`` has shape (samples, width); ``info`` holds what run.json records
    (status, diagram, parameters, timing). ``complete`` is False for a failed run,
    whose signals stop where the failure happened. A run that a block ended early
    (``EndRun``) is complete; ``ended_by`` says who ended it and where.
    """

    def __init__(self, signals: dict[str, tuple[np.ndarray, np.ndarray]], info: dict):
        self.signals = signals
        self.info = info

    def __getitem__(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        try:
            return self.signals[name]
        except KeyError:
            raise KeyError(f"signal '{name}' was not logged; logged signals: "
                           f"{', '.join(self.signals) or 'none'}") from None

    def __contains__(self, name: object) -> bool:
        return name in self.signals

    def __iter__(self) -> Iterator[str]:
        return iter(self.signals)

    def __len__(self) -> int:
        return len(self.signals)

    def __repr__(self) -> str:
        from blocks.results.summary import as_text

        return as_text(self)

    def _repr_html_(self) -> str:
        """Jupyter's view: the status and a table of the signals."""
        from blocks.results.summary import as_html

        return as_html(self)

    @property
    def status(self) -> str:
        return self.info.get("status", "complete")

    @property
    def complete(self) -> bool:
        return self.status == "complete"

    @property
    def interrupted(self) -> bool:
        """True when the run was stopped (Ctrl-C, SIGTERM) rather than by its end time or a failure."""
        return self.status.startswith("interrupted")

    @property
    def ended_by(self) -> dict | None:
        """How a block ended this complete run before its t_end: ``block``, ``type``,
        ``time`` (where the run ended), ``tick_time`` (the update that raised ``EndRun``)
        and ``reason``; None for a run that was not ended that way."""
        return self.info.get("ended_by")

    @property
    def end_note(self) -> str | None:
        """``ended_by`` as one line, 'ended at t=9 s by block 'b' (Type): reason (asked in
        its update at t=8.8 s)'; None when no block ended the run."""
        ended = self.ended_by
        if ended is None:
            return None
        return (f"ended at t={ended['time']:.9g} s by block '{ended['block']}' ({ended['type']}): "
                f"{ended['reason']} (asked in its update at t={ended['tick_time']:.9g} s)")

    @property
    def stop_time(self) -> float | None:
        """Where the data end when that is not t_end: where a failed or interrupted run
        stopped (run.json's ``t_stop``, or the time in the status of files written before
        it was recorded) or where a block ended a complete run; None for a run to t_end."""
        if self.ended_by is not None:
            return float(self.ended_by["time"])
        if self.complete:
            return None
        if self.info.get("t_stop") is not None:
            return float(self.info["t_stop"])
        found = re.match(r"\w+ at t=([-+0-9.eE]+) s", self.status)
        return float(found.group(1)) if found else None

    def held(self, name: str, times: np.ndarray, rtol: float = 0.0) -> np.ndarray:
        """The signal's held (zero-order hold) values at each of ``times`` (one row per
        time), NaN before its first sample; ``rtol`` as in ``held_index``."""
        t, v = self[name]
        idx = held_index(t, times, rtol)
        if not len(t):
            return np.full((len(idx), v.shape[1]), np.nan)
        return np.where((idx >= 0)[:, None], v[np.clip(idx, 0, None)], np.nan)

    def value_at(self, name: str, t: float) -> np.ndarray:
        """The held (zero-order hold) value of a signal at time ``t``."""
        times, values = self[name]
        i = int(held_index(times, [t])[0])
        if i < 0:
            raise ValueError(f"signal '{name}' has no sample at or before t = {t}")
        return values[i]

    def plot(self, *signals: str, title: str | None = None, markers=True):
        """A matplotlib Figure of ``signals`` (selections, as ``hierhand plot -s`` takes them:
        ``"plant.q"``, ``"plant.q[fore.1]"``, ``"plant.q[fore.1],ref.y"``; default every
        logged signal), an axis each, with the diagram's events marked (``markers``: True,
        False, or a list of ``blocks.plot.markers.Marker``). No window opens and pyplot is
        not needed: a notebook shows the figure inline, ``fig.savefig("f.pdf")`` writes it."""
        from blocks.plot.pages import figure_of

        return figure_of(self, list(signals) or None, title, markers)

    # -- files ---------------------------------------------------------------------

    def save(self, directory: str | Path, csv: bool = False, mat: bool = False,
             csv_digits: int | None = None) -> Path:
        """Write signals.npz and run.json (and signals.csv, signals.mat) into ``directory``,
        replacing the result files of the run saved there before as one set (a complete
        run's kept in ``previous-complete-run`` when this one is not complete:
        ``results_folder``)."""
        boolean("csv", csv)
        boolean("mat", mat)
        with writing(directory) as staged:
            self.write_files(staged, csv, mat=mat, csv_digits=csv_digits)
        return Path(directory)

    def save_mat(self, path: str | Path) -> Path:
        """Write the signals, with their times, units and element names, and the run's
        record as a MATLAB MAT file (see ``blocks.results.mat``); needs scipy."""
        from blocks.results.atomic_file import atomic_writer
        from blocks.results.mat import write_mat

        with atomic_writer(path) as f:
            write_mat(self, f)
        return Path(path)

    def write_files(self, folder: Path, csv: bool = False, mat: bool = False, csv_digits: int | None = None) -> None:
        """Write signals.npz, run.json (and signals.csv with ``csv``, signals.mat with
        ``mat``) into ``folder`` as they are: the staging folder of
        ``results_folder.writing``, which makes them one set."""
        from blocks.results.mat import write_mat

        for name, (_, v) in self.signals.items():
            if np.ndim(v) != 2:
                raise ValueError(f"signal '{name}' cannot be saved: its values must be an array of "
                                 f"shape (samples, width), got shape {np.shape(v)}")
        check_digits(csv_digits)
        arrays = {}
        for name, (t, v) in self.signals.items():
            arrays[name] = v
            arrays[TIME_PREFIX + name] = t
        with open(folder / SIGNALS_NPZ, "wb") as f:
            np.savez(f, **arrays)
        if csv:
            with open(folder / SIGNALS_CSV, "wb") as f:
                self.write_csv(f, csv_digits)
        if mat:
            with open(folder / SIGNALS_MAT, "wb") as f:
                write_mat(self, f)
        info = dict(self.info)
        info["signals"] = {n: {"width": int(v.shape[1]), "samples": int(v.shape[0])}
                           for n, (t, v) in self.signals.items()}
        (folder / RUN_JSON).write_text(json.dumps(info, indent=2, default=str) + "\n", encoding="utf-8")

    def element_labels(self, name: str) -> list[str] | None:
        """The names the block gave the elements of signal ``name`` (run.json's
        ``element_labels``), or None when they are numbered from 0."""
        labels = (self.info.get("element_labels") or {}).get(name)
        width = self[name][1].shape[1]
        return [str(label) for label in labels] if labels is not None and len(labels) == width else None

    def units(self, name: str) -> list[str] | None:
        """The unit of each element of signal ``name`` (run.json's ``units``, which holds
        one string for a signal whose elements share a unit), ``""`` for an element of
        unknown unit; None when its block gave no units."""
        units = (self.info.get("units") or {}).get(name)
        width = self[name][1].shape[1]
        if isinstance(units, str):
            return [units] * width
        return [str(u) for u in units] if isinstance(units, list) and len(units) == width else None

    def unit(self, name: str) -> str | None:
        """The unit all elements of signal ``name`` share (``"rad"``, ``"N m"``, ``"1"``);
        None when its block gave none or its elements differ (see ``units``)."""
        units = self.units(name)
        return units[0] if units and units[0] and all(u == units[0] for u in units) else None

    def write_csv(self, f, digits: int | None = None) -> None:
        """Columns ``time`` (every logged sample time) and each signal held at those times.

        A signal of width 1 is the column ``block.port``; the columns of a wider one are
        ``block.port[i]``, counting from 0, unless its block names its elements
        (``Block.element_labels``): then ``block.port[label]``, so an FMU's ports keep the
        FMU's own indices (``plant.y[1]``, ``plant.A[1,2]``). Numbers are written as the
        shortest text that reads back as the same double (``0.001``, not
        ``0.0010000000000000000208``), or with ``digits`` significant digits (1 to 17).
        """
        check_digits(digits)
        if not self.signals:
            f.write(b"time\n")
            return
        grid = np.unique(np.concatenate([t for t, _ in self.signals.values()]))
        columns, header = [grid[:, None]], ["time"]
        for name, (t, v) in self.signals.items():
            columns.append(self.held(name, grid))
            labels = self.element_labels(name)
            if labels is not None:
                header += [f"{name}[{label}]" for label in labels]
            else:
                header += [name] if v.shape[1] == 1 else [f"{name}[{i}]" for i in range(v.shape[1])]
        names = io.StringIO()
        csv.writer(names, lineterminator="").writerow(header)  # quotes labels such as "A[1,2]"
        f.write((names.getvalue() + "\n").encode("utf-8"))
        number = float.__repr__ if digits is None else f"%.{digits}g".__mod__
        table = np.hstack(columns)
        for start in range(0, len(table), CSV_ROWS):
            rows = table[start:start + CSV_ROWS].tolist()
            f.write("".join(",".join(map(number, row)) + "\n" for row in rows).encode("ascii"))

    @classmethod
    def load(cls, directory: str | Path) -> "Results":
        """Read a results folder written by ``save`` (or ``hierhand run``).

        The folder may have been changed since (or come from someone else), so its files
        are read as data under limits: ``run.json`` as a JSON object of at most
        MAX_YAML_BYTES whose fields have the types a run writes, ``signals.npz`` through
        ``npzfile`` (sizes checked before anything is allocated), each signal a 2-D array
        with a 1-D time array of its length. Anything else is a ResultsError naming the
        file and what is wrong with it."""
        directory = Path(directory)
        npz, meta = directory / SIGNALS_NPZ, directory / RUN_JSON
        with reading(directory):
            if not os.path.lexists(npz):
                raise ResultsError(f"{directory}: no {SIGNALS_NPZ} here; is this the -o folder of a run?")
            if not os.path.lexists(meta):
                raise ResultsError(f"{directory}: no {RUN_JSON} beside {SIGNALS_NPZ}: the results were "
                                   "being replaced when their run stopped; run it again")
            info = _read_info(meta)
            try:
                arrays = read_npz(npz, str(npz), MAX_RESULTS_BYTES, inflation=MAX_INFLATION)
            except ValueError as exc:
                raise ResultsError(f"{exc}") from None
        return cls(_signals(arrays, npz), info)


MAX_INFLATION = 200
"""How many times its size on disk a results file's arrays may hold (``np.savez`` stores
them uncompressed, so a real file holds about its size; a 'zip bomb' thousands of times)."""

_INFO_TYPES = {"status": str, "diagram": str, "t_stop": (int, float, type(None)), "t_end": (int, float, type(None)),
               "wall_time_s": (int, float), "real_time_factor": (int, float, type(None)), "ended_by": (dict, type(None)),
               "element_labels": (dict, type(None)), "units": (dict, type(None)), "parameters": dict,
               "block_types": dict}
"""The fields of run.json that readers use, and the JSON types a run writes them as."""
_ENDED_BY_TYPES = {"block": str, "type": str, "reason": str, "time": (int, float), "tick_time": (int, float)}


def _read_info(meta: Path) -> dict:
    """run.json as a dict whose used fields have their types; ResultsError otherwise."""
    from blocks.diagram_file.yaml_source import YamlSourceError, read_yaml_file

    try:
        info = json.loads(read_yaml_file(meta, "JSON"))
    except FileNotFoundError:
        raise ResultsError(f"{meta}: no such file") from None
    except YamlSourceError as exc:
        raise ResultsError(f"{meta}{f':{exc.line}' if exc.line else ''}: {exc.message}") from None
    except json.JSONDecodeError as exc:
        raise ResultsError(f"{meta}:{exc.lineno}: not JSON: {exc.msg}") from None
    except RecursionError:
        raise ResultsError(f"{meta}: JSON nested too deeply to be a run's record") from None
    if not isinstance(info, dict):
        raise ResultsError(f"{meta}: a run's record is a JSON object, not {_json_kind(info)}")
    _check_fields(meta, info, _INFO_TYPES, "")
    if isinstance(info.get("ended_by"), dict):
        _check_fields(meta, info["ended_by"], _ENDED_BY_TYPES, "ended_by.", required=True)
    for field in ("element_labels", "units"):
        for name, value in (info.get(field) or {}).items():
            if not (isinstance(value, str) and field == "units") and not (
                    isinstance(value, list) and all(isinstance(v, (str, int, float)) for v in value)):
                raise ResultsError(f"{meta}: field '{field}.{name}' must be a list of names"
                                   f"{' or one unit' if field == 'units' else ''}, not {_json_kind(value)}")
    status = info.get("status", "complete")
    if not status.startswith(("complete", "failed", "interrupted")):
        raise ResultsError(f"{meta}: field 'status' is {status[:60]!r}, not a run's status (complete, failed "
                           "at ..., interrupted at ...)")
    return info


def _check_fields(meta: Path, info: dict, types: dict, prefix: str, required: bool = False) -> None:
    for field, kind in types.items():
        if field not in info:
            if required:
                raise ResultsError(f"{meta}: field '{prefix}{field}' is missing")
            continue
        value = info[field]
        if isinstance(value, bool) or not isinstance(value, kind):
            raise ResultsError(f"{meta}: field '{prefix}{field}' must be {_kinds(kind)}, not {_json_kind(value)}")


def _kinds(kind) -> str:
    kinds = kind if isinstance(kind, tuple) else (kind,)
    return " or ".join(dict.fromkeys(_json_kind(k()) if k is not type(None) else "null" for k in kinds))


def _json_kind(value) -> str:
    return {dict: "an object", list: "a list", str: "text", bool: "true/false", int: "a number",
            float: "a number", type(None): "null"}.get(type(value), type(value).__name__)


def _signals(arrays: dict[str, np.ndarray], npz: Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The signals of a results file's arrays: each ``name`` (samples x width) with its
    ``time:name`` (samples); ResultsError for arrays that do not pair up so."""
    signals = {}
    for name, values in arrays.items():
        if name.startswith(TIME_PREFIX):
            if name[len(TIME_PREFIX):] not in arrays:
                raise ResultsError(f"{npz}: array '{name}' has no signal '{name[len(TIME_PREFIX):]}' beside it")
            continue
        t = arrays.get(TIME_PREFIX + name)
        if t is None:
            raise ResultsError(f"{npz}: signal '{name}' has no times (array '{TIME_PREFIX}{name}')")
        for key, arr in ((TIME_PREFIX + name, t), (name, values)):
            if arr.dtype.kind not in "fiu":
                raise ResultsError(f"{npz}: array '{key}' must hold real numbers, not {arr.dtype}")
        if t.ndim != 1 or values.ndim != 2 or values.shape[0] != t.shape[0]:
            raise ResultsError(f"{npz}: signal '{name}' must be samples x width with one time per sample, "
                               f"got values of shape {values.shape} and times of shape {t.shape}")
        signals[name] = (t.astype(float, copy=False), values.astype(float, copy=False))
    return signals
