"""FromFile: a signal played back from a CSV or NPZ file (blocks.library.datafile reads it).

``path`` is a path parameter: in a diagram a relative path is resolved against the
diagram's folder and the file is listed in ``Diagram.files``, so sweeps ship it to their
workers and a point's hash covers its content. The kernel (lib_sources.c's from_file)
holds the whole table.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from blocks.library import _params
from blocks.library.datafile import read_series
from blocks.library.kernel_block import KernelBlock

METHODS = ("hold", "linear")


class FromFile(KernelBlock):
    """Plays back a time series from a CSV or NPZ file, held or linearly interpolated.

    The output is the last sample at or before t ('hold') or
    the line between the samples around t ('linear'); before the first sample the first
    value, after the last the last value. Equal times make a step (the later row counts).
    A CSV file has the time first and a column per element, with or without a header row
    (a header names the elements; a run's signals.csv reads as it is). An NPZ file holds
    ``time`` and the values, (n,) or (n, width), as a run's signals.npz does.

    Parameters
    ----------
    path : str or path
        the .csv or .npz file; in a diagram a relative path is resolved against the
        diagram's folder
    signal : str
        which data to read: in a CSV with a header the columns named so, or 'NAME[...]'
        (a run's signals.csv: 'plant.q'); in an NPZ the array (times from 'time:NAME' if
        there is one, else 'time'); omitted, every CSV column after the time, or the one
        array beside 'time' (or 'values') of an NPZ
    method : {'hold', 'linear'}
        zero-order hold of the samples, or linear interpolation between them
    """

    kernel_name = "from_file"
    path_params = ("path",)
    confined_params = ("path",)
    time_varying = True

    def __init__(self, path: Any, signal: str | None = None, method: str = "hold"):
        if not isinstance(path, (str, os.PathLike)) or not str(path).strip():
            raise ValueError(f"parameter 'path' must be the path of a .csv or .npz file, got {path!r}")
        if signal is not None and (not isinstance(signal, str) or not signal):
            raise ValueError(f"parameter 'signal' must be a name, got {signal!r}")
        self.method = _params.choice("method", method, METHODS)
        self.path = Path(path).expanduser()
        series = read_series(self.path, signal)
        self.signal = signal
        self.times, self.values, self.labels = series.times, series.values, series.labels
        self._table = np.concatenate((self.times, self.values.ravel()))
        self.inputs, self.outputs = {}, {"y": self.values.shape[1]}
        self.feedthrough = False

    def element_labels(self, port: str) -> list[str] | None:
        return self.labels if port == "y" else None

    def describe(self) -> str:
        return f"{self.times.size} samples of {self.values.shape[1]} element(s) from {self.path}, " \
               f"t = {self.times[0]:g} to {self.times[-1]:g} s"

    def cache_key(self):
        return (id(self._table), self.method)

    def context_numbers(self):
        return (self.times.size, float(self.method == "linear"), self._table)
