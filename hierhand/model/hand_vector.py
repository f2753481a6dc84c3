"""A hand's numbers as the flat vector the C core reads, in the order it defines.

The C core (``hierhand/csrc/hand_params.c``) owns the list of a hand's numbers, their
names and their checks; this module maps a validated hand file onto that list by name.
The names use 1-based indices, FMI's structured naming: ``fingers[2].links[3].com[1]`` is
the hand file's ``fingers[1].links[2].com[0]``. ``unflatten`` and ``hand_dict`` go back
from names (or the vector) to the hand dict, e.g. to rebuild the hand an exported FMU
simulates from its parameters.
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
    return tuple(name for name, *_ in _native.hand_parameters())


@functools.cache
def parameter_docs() -> tuple[str, ...]:
    """What each entry of the hand vector is, with its unit."""
    return tuple(doc for _, doc, _ in _native.hand_parameters())


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


_PART = re.compile(r"^(?P<key>[A-Za-z_][A-Za-z0-9_]*)(?P<indices>(?:\[\d+\])*)$")


def unflatten(values: Mapping[str, float]) -> dict[str, Any]:
    """The inverse of ``flatten``: the nested dict (lists for the ``[i]`` indices, which
    must run 1..n) of numbers given by vector name."""
    root: dict = {}
    for name, value in values.items():
        steps: list[str | int] = []
        for part in name.split("."):
            m = _PART.match(part)
            if m is None:
                raise ValueError(f"'{name}' is not a hand-vector name (e.g. fingers[2].links[3].com[1])")
            steps.append(m.group("key"))
            steps.extend(int(i) - 1 for i in _INDEX.findall(m.group("indices")))
        node = root
        for step in steps[:-1]:
            node = node.setdefault(step, {})
            if not isinstance(node, dict):
                raise ValueError(f"'{name}': a number is also given for a part of its path")
        if isinstance(node.get(steps[-1]), dict):
            raise ValueError(f"'{name}': numbers are also given for parts of it")
        node[steps[-1]] = float(value)
    return _as_lists(root, "")


def _as_lists(node: Any, path: str) -> Any:
    """Mappings keyed by 0..n-1 (1-based in the names) as lists."""
    if not isinstance(node, dict):
        return node
    if node and all(isinstance(k, int) for k in node):
        if sorted(node) != list(range(len(node))):
            raise ValueError(f"the indices of '{path}' must run from 1 to {len(node)} without gaps")
        return [_as_lists(node[i], f"{path}[{i + 1}]") for i in range(len(node))]
    if any(isinstance(k, int) for k in node):
        raise ValueError(f"'{path}' has both indices and named fields")
    return {k: _as_lists(v, f"{path}.{k}" if path else k) for k, v in node.items()}


def hand_dict(vector: Any) -> dict[str, Any]:
    """The inverse of ``hand_vector``: a hand dict from the vector in the core's order.
    Finger names are not numbers, so not in the vector: the fingers come without them."""
    names = parameter_names()
    values = np.asarray(vector, dtype=np.float64)
    if values.shape != (len(names),):
        raise ValueError(f"a hand vector has {len(names)} numbers, got shape {values.shape}")
    return unflatten(dict(zip(names, values.tolist())))
