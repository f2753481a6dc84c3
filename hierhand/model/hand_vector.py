"""A hand's numbers as the flat vector the C core reads, in the order it defines.

The C core (``hierhand/csrc/hand_params.c``) owns the list of a hand's numbers, their
names and their checks; this module maps a validated hand file onto that list by name.
The names use 1-based indices, FMI's structured naming: ``fingers[2].links[3].com[1]`` is
the hand file's ``fingers[1].links[2].com[0]``.
"""

from __future__ import annotations

import functools
import re
from typing import Any, Mapping

import numpy as np

from .. import _native


@functools.cache
def parameter_names() -> tuple[str, ...]:
    """The C core's names of the hand vector's entries, in order."""
    return tuple(name for name, _ in _native.hand_parameters())


@functools.cache
def parameter_docs() -> tuple[str, ...]:
    """What each entry of the hand vector is, with its unit."""
    return tuple(doc for _, doc in _native.hand_parameters())


_INDEX = re.compile(r"\[(\d+)\]")


def hand_file_path(name: str) -> str:
    """The hand-file field (0-based indices) of a hand-vector name: ``fingers[1].q0[2]`` -> ``fingers[0].q0[1]``."""
    return _INDEX.sub(lambda m: f"[{int(m.group(1)) - 1}]", name)


def flatten(hand: Mapping[str, Any]) -> dict[str, float]:
    """Every number of a complete hand dict (``com`` as ``[along, across]``) by its vector name."""
    out: dict[str, float] = {}

    def walk(value: Any, name: str) -> None:
        if isinstance(value, Mapping):
            for key, item in value.items():
                walk(item, f"{name}.{key}" if name else str(key))
        elif isinstance(value, (list, tuple)):
            for i, item in enumerate(value):
                walk(item, f"{name}[{i + 1}]")
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            out[name] = float(value)

    walk(hand, "")
    return out


def hand_vector(hand: Mapping[str, Any]) -> np.ndarray:
    """The hand vector of a complete hand dict (as ``HandParams.to_dict()`` gives it)."""
    values = flatten(hand)
    names = parameter_names()
    missing = [n for n in names if n not in values]
    if missing:
        raise KeyError(f"the hand has no value for {', '.join(missing)}")
    return np.array([values[n] for n in names], dtype=np.float64)
