"""Numbers as float64 arrays: the one place that coerces (and checks) parameters and inputs.

Blocks take numbers from YAML (integers, floats, nested lists, numeric text such as
``"1e-3"``) and from Python (arrays of any dtype, views, lists). ``float_array`` turns
them into an owned, C-contiguous float64 array of the expected shape, or raises a
ValueError whose message names the value (``parameter 'k' must be finite``); the loader
reports that message at the line of the diagram that gave the value.
"""

from __future__ import annotations

import reprlib
from typing import Any

import numpy as np

_SHAPES = {0: "a scalar", 1: "a scalar or a vector", 2: "a matrix"}


def float_array(value: Any, name: str, *, ndim: int | None = None, width: int | None = None,
                broadcast: bool = False, finite: bool = True, allow_inf: bool = False,
                allow_empty: bool = True, what: str = "parameter") -> np.ndarray:
    """``value`` as a new C-contiguous float64 array, checked.

    - ``ndim``: None keeps the shape given; 1 makes a scalar a vector of one element; 2
      makes a scalar 1x1 and a vector a row. Any other shape is an error.
    - ``width``: the array must be a vector of exactly this width; with ``broadcast`` a
      scalar (or one-element vector) is widened to it (a per-joint gain given once).
    - ``finite``: reject NaN and infinities (only NaN with ``allow_inf``).
    - ``allow_empty``: whether an array without elements is accepted.
    - ``what``: the word before the name in messages (``parameter``, ``input``, ``argument``).
    """
    label = f"{what} '{name}'"
    if _holds_bool(value):
        raise ValueError(f"{label} must be numeric, got {reprlib.repr(value)} (true/false, and YAML's "
                         "yes/no/on/off, are booleans, not numbers: write 1 or 0)")
    try:
        arr = np.array(value, dtype=np.float64, order="C")
    except (TypeError, ValueError):
        raise ValueError(f"{label} must be numeric, got {reprlib.repr(value)}") from None
    if ndim is not None:
        if ndim >= 1 and arr.ndim == 0:
            arr = arr.reshape((1,) * ndim)
        elif ndim == 2 and arr.ndim == 1:
            arr = arr.reshape(1, -1)
        if arr.ndim != ndim:
            raise ValueError(f"{label} must be {_SHAPES.get(ndim, f'{ndim}-dimensional')}, got shape {arr.shape}")
    if broadcast and width is not None and arr.size == 1:
        arr = np.full(width, arr.reshape(-1)[0])
    if width is not None and arr.shape != (width,):
        raise ValueError(f"{label} must have width {width}{' (or be a scalar)' if broadcast else ''}, "
                         f"got shape {arr.shape}")
    if not allow_empty and arr.size == 0:
        raise ValueError(f"{label} must not be empty")
    if finite:
        bad = np.isnan(arr) if allow_inf else ~np.isfinite(arr)
        if bad.any():
            raise ValueError(f"{label} must be {'not NaN' if allow_inf else 'finite'}")
    return arr


def _holds_bool(value: Any) -> bool:
    """Whether ``value`` is a boolean or a (nested) list or array of them anywhere: numpy
    would read True as 1.0, and a gain written as YAML's ``yes`` is a mistake, not a 1."""
    if isinstance(value, (bool, np.bool_)):
        return True
    if isinstance(value, np.ndarray):
        return value.dtype == np.bool_
    if isinstance(value, (list, tuple)):
        return any(_holds_bool(v) for v in value)
    return False


def flat_float64(value: Any) -> np.ndarray:
    """``value`` as a 1-D C-contiguous float64 array, without checks, and without a copy
    when it already is one: the hot-path sibling of ``float_array``, for arguments of
    compiled calls that refuse anything else (a list, another dtype, a strided view)."""
    return np.ascontiguousarray(value, dtype=np.float64).reshape(-1)
