"""A run's signals as a MATLAB MAT file (level 5, which MATLAB, Octave and scipy read).

The file holds two variables. ``signals`` is a struct tree along the signals' names:
``signals.plant.q`` (``signals.ctrl.reflex.tau_g`` for a subsystem's block) is a struct
with the signal's ``time`` (n x 1), ``values`` (n x width), ``units`` and ``elements``
(cell arrays of one string per element: its unit, ``''`` where unknown, and its name as
the block gives it, else its 0-based index) and ``name`` (``'plant.q'``). ``run`` holds
the diagram's name, the status, t_end, and ``info_json``: the whole of run.json's record
as JSON text, so nothing of it is lost. MATLAB::

    load('signals.mat');
    plot(signals.plant.q.time, signals.plant.q.values); legend(signals.plant.q.elements)

Names are MATLAB identifiers already (block and port names are), except that MATLAB
wants a letter first: a part beginning with ``_`` is written with an ``x`` before it
(``_aux`` -> ``x_aux``), and ``name`` keeps the signal's own name.
"""

from __future__ import annotations

import json
import re
from typing import Any, BinaryIO

import numpy as np

MAX_NAME = 63
"""The longest field name MATLAB takes (``namelengthmax``)."""
_IDENTIFIER = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


class MatNameError(ValueError):
    """A signal name that cannot be a MATLAB struct path."""


def field_name(part: str, signal: str) -> str:
    """``part`` of a signal name as a MATLAB field name."""
    name = part if part[:1].isalpha() else "x" + part
    if not _IDENTIFIER.match(name) or len(name) > MAX_NAME:
        raise MatNameError(f"signal '{signal}' cannot be written to a MAT file: '{part}' is not a MATLAB "
                           f"name (letters, digits and '_', at most {MAX_NAME} characters)")
    return name


def mat_paths(signals) -> dict[str, list[str]]:
    """Each signal name's path of MATLAB field names (``ctrl._aux.y`` -> ctrl, x_aux, y);
    MatNameError for a name that is no MATLAB path or meets another one."""
    paths: dict[str, list[str]] = {}
    seen: dict[tuple[str, ...], str] = {}
    for signal in signals:
        parts = [field_name(p, signal) for p in signal.split(".")]
        for n in range(1, len(parts) + 1):
            other = seen.get(tuple(parts[:n]))
            if other is not None and (n == len(parts) or other != "block"):
                taken = "a block's path" if other == "block" else f"signal '{other}'"
                raise MatNameError(f"signal '{signal}' cannot be written to a MAT file: its MATLAB name "
                                   f"'{'.'.join(parts[:n])}' is taken by {taken}")
        for n in range(1, len(parts)):
            seen[tuple(parts[:n])] = "block"
        seen[tuple(parts)] = signal
        paths[signal] = parts
    return paths


def mat_contents(results: Any) -> dict[str, Any]:
    """The variables of the MAT file of ``results``: ``signals`` and ``run``."""
    tree: dict[str, Any] = {}
    for signal, parts in mat_paths(results.signals).items():
        t, v = results.signals[signal]
        node = tree
        for part in parts[:-1]:
            node = node.setdefault(part, {})
        width = np.shape(v)[1]
        labels = results.element_labels(signal) or [str(j) for j in range(width)]
        units = results.units(signal) or [""] * width
        node[parts[-1]] = {"name": signal, "time": np.asarray(t, dtype=float).reshape(-1, 1),
                           "values": np.asarray(v, dtype=float), "units": _cell(units),
                           "elements": _cell(labels)}
    info = results.info
    run = {"diagram": str(info.get("diagram", "")), "status": results.status,
           "t_end": float(info["t_end"]) if info.get("t_end") is not None else np.nan,
           "info_json": json.dumps(info, default=str)}
    return {"signals": tree, "run": run}


def write_mat(results: Any, f: BinaryIO) -> None:
    """Write the MAT file of ``results`` to the binary file ``f`` (zlib-compressed)."""
    from scipy.io import savemat

    savemat(f, mat_contents(results), do_compression=True, oned_as="column", long_field_names=True)


def _cell(texts) -> np.ndarray:
    """A cell array of strings (a row): an object array, as scipy writes cells."""
    cell = np.empty((1, len(texts)), dtype=object)
    cell[0, :] = [str(t) for t in texts]
    return cell
