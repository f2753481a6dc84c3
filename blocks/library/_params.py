"""Checks of the library blocks' parameters, each a one-line ValueError naming the parameter.

The loader reports a constructor's message at the line of the diagram that gave the
value, prefixed with the block's name and type; these helpers word the usual cases the
same way for every block (``parameter 'method' must be one of ...``).
"""

from __future__ import annotations

import operator
from typing import Any, Sequence

import numpy as np

from blocks.arrays import float_array
from blocks.limits import MAX_PORT_WIDTH


def choice(name: str, value: Any, options: Sequence[str]) -> str:
    """``value`` if it is one of ``options``."""
    if not isinstance(value, str) or value not in options:
        listed = ", ".join(repr(o) for o in options)
        raise ValueError(f"parameter '{name}' must be one of {listed}, got {value!r}")
    return value


def integer(name: str, value: Any, minimum: int | None = None, maximum: int | None = None) -> int:
    """``value`` as an int (a whole number, not a bool), within the bounds given."""
    if isinstance(value, bool):
        raise ValueError(f"parameter '{name}' must be a whole number, got {value!r}")
    try:
        number = operator.index(value)
    except TypeError:
        if isinstance(value, float) and value.is_integer():
            number = int(value)
        else:
            raise ValueError(f"parameter '{name}' must be a whole number, got {value!r}") from None
    if minimum is not None and number < minimum:
        raise ValueError(f"parameter '{name}' must be at least {minimum}, got {number}")
    if maximum is not None and number > maximum:
        raise ValueError(f"parameter '{name}' must be at most {maximum}, got {number}")
    return number


def flag(name: str, value: Any) -> bool:
    """``value`` if it is true or false."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"parameter '{name}' must be true or false, got {value!r}")
    return bool(value)


def number(name: str, value: Any, *, positive: bool = False, nonnegative: bool = False,
           allow_inf: bool = False) -> float:
    """``value`` as a float, finite unless ``allow_inf``, with the sign asked for."""
    x = float(float_array(value, name, ndim=0, allow_inf=allow_inf))
    _check_sign(name, np.asarray(x), positive, nonnegative)
    return x


def elementwise(name: str, value: Any, *, positive: bool = False, nonnegative: bool = False,
                nonzero: bool = False, allow_inf: bool = False) -> np.ndarray:
    """A scalar (0-d array: any width) or a vector (one value per element)."""
    arr = float_array(value, name, allow_inf=allow_inf, allow_empty=False)
    if arr.ndim > 1:
        raise ValueError(f"parameter '{name}' must be a scalar or a vector, got shape {arr.shape}")
    _check_sign(name, arr, positive, nonnegative)
    if nonzero and np.any(arr == 0):
        raise ValueError(f"parameter '{name}' must not be zero")
    return arr


def _check_sign(name: str, arr: np.ndarray, positive: bool, nonnegative: bool) -> None:
    if positive and np.any(~(arr > 0)):
        raise ValueError(f"parameter '{name}' must be positive, got {_shown(arr)}")
    if nonnegative and np.any(~(arr >= 0)):
        raise ValueError(f"parameter '{name}' must not be negative, got {_shown(arr)}")


def _shown(arr: np.ndarray) -> str:
    return repr(float(arr)) if arr.ndim == 0 else repr(arr.tolist())


def common_width(**arrays: np.ndarray) -> int | None:
    """The width the vector parameters give (None when all are scalars); ValueError naming
    them when two vectors differ (a one-element vector fits any width)."""
    widths = {name: a.size for name, a in arrays.items() if a.ndim == 1 and a.size != 1}
    if len(set(widths.values())) > 1:
        listed = ", ".join(f"'{n}' has {w}" for n, w in widths.items())
        raise ValueError(f"parameters must be scalars or vectors of one width: {listed}")
    if widths:
        return next(iter(widths.values()))
    return 1 if any(a.ndim == 1 for a in arrays.values()) else None


def spread(value: np.ndarray, width: int) -> np.ndarray:
    """A scalar or one-element parameter repeated to ``width`` (a vector as it is)."""
    return np.broadcast_to(np.asarray(value, dtype=np.float64).reshape(-1), (width,))


def widths_list(name: str, value: Any, ports: str, most: int) -> list[int]:
    """Port widths: a count n (n ports of width 1) or a list of positive widths, at most
    ``most`` ports (checked before any list is built) whose widths add up to at most
    MAX_PORT_WIDTH."""
    if isinstance(value, (list, tuple)):
        if not value:
            raise ValueError(f"parameter '{name}' must list at least one width")
        if len(value) > most:
            raise ValueError(f"parameter '{name}' gives {len(value)} {ports}; at most {most}")
        widths = [integer(name, w, minimum=1) for w in value]
    else:
        count = integer(name, value, minimum=1)
        if count > most:
            raise ValueError(f"parameter '{name}' gives {count} {ports}; at most {most}")
        widths = [1] * count
    if sum(widths) > MAX_PORT_WIDTH:
        raise ValueError(f"parameter '{name}': its widths add up to {sum(widths)}, more than the widest port "
                         f"({MAX_PORT_WIDTH})")
    return widths


def check_limits(lower: np.ndarray, upper: np.ndarray) -> None:
    """lower <= upper, elementwise where both are vectors."""
    if np.any(np.asarray(lower) > np.asarray(upper)):
        raise ValueError(f"parameter 'lower' must be <= 'upper', got lower={_shown(lower)}, "
                         f"upper={_shown(upper)}")
