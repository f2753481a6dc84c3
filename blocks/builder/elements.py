"""The ends of a wire (``block.port``) and the elements of a vector signal, by label, index
or slice: the one grammar of connections and plots.

A signal is ``block.port``; some of its elements are written after it in brackets::

    plant.q[fore.1]            the element its block (or the diagram) labels fore.1
    plant.q[3]  plant.q[-1]    by 0-based index (from the end when negative)
    plant.q[0:3]  plant.q[::2] a slice, start:stop[:step]
    plant.q[thumb.1,fore.1]    several, by label or index, in the order given

A label is matched before an index, so a block whose elements are labelled ``1``, ``2``
(an FMU's ``y[1]``) is selected by those labels. Connections (``c.y[1] -> g.u``,
``a.y -> g.u[0]``), ``hierhand plot -s`` and a sweep's ``--metric final(plant.q[1])``
read elements through ``pick``, so ``q[1]`` is one element in every command.
"""

from __future__ import annotations

import re
from typing import Any, Sequence

SIGNAL = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)+)\s*(?:\[(.*)\])?\s*$")
_SLICE = re.compile(r"^\s*(-?\d+)?\s*:\s*(-?\d+)?\s*(?::\s*(-?\d+)\s*)?$")
_NUMBERED = re.compile(r"^\d+(?:,\d+)*$")
"""An element label that is a number (an FMU's ``z[1]``, ``m[1,2]``): where every label of a
port is one, ``[0]`` could be read as a label or as an index, so it is read only as a label."""
_ENDPOINT = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\.([A-Za-z_][A-Za-z0-9_]*)\s*$")
_WIRE_END = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\.([A-Za-z_][A-Za-z0-9_]*)\s*(?:\[(.*)\])?\s*$")

Endpoint = tuple[str, str]
"""(block path name, port)."""


def parse_endpoint(text: Any) -> Endpoint | None:
    """``("plant", "y")`` from ``"plant.y"``; None if ``text`` is not of that form."""
    m = _ENDPOINT.match(text) if isinstance(text, str) else None
    return (m.group(1), m.group(2)) if m else None


def parse_wire_end(text: Any) -> tuple[str, str, str | None] | None:
    """``("plant", "q", "fore.1")`` from ``"plant.q[fore.1]"`` (None for the whole port:
    ``"plant.q"``); None if ``text`` is neither (an empty selection ``[]`` included)."""
    m = _WIRE_END.match(text) if isinstance(text, str) else None
    if m is None or (m.group(3) is not None and not m.group(3).strip()):
        return None
    return m.group(1), m.group(2), None if m.group(3) is None else m.group(3).strip()


class ElementError(ValueError):
    """A selection that names no element of its signal (one line, with what there is)."""


def split_signal(text: str) -> tuple[str, str | None] | None:
    """``("plant.q", "fore.1")`` from ``"plant.q[fore.1]"`` (``None`` for the elements of a
    whole signal); None when ``text`` is not of that form."""
    found = SIGNAL.match(text) if isinstance(text, str) else None
    if found is None:
        return None
    return found.group(1), None if found.group(2) is None else found.group(2).strip()


def split_signals(text: str) -> list[str]:
    """The comma-separated parts of a list of signals (``"plant.q[1,1], ref.y"``), commas
    inside brackets kept: a plot's selection, a metric's arguments."""
    found, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        depth += (ch == "[") - (ch == "]")
        if ch == "," and depth == 0:
            found.append(text[start:i])
            start = i + 1
    found.append(text[start:])
    return [p.strip() for p in found]


def parts(spec: str) -> list[str]:
    """The comma-separated parts of an element selection (``"thumb.1, 0:3"``)."""
    return [p.strip() for p in spec.split(",")]


def count(spec: str, width: int | None) -> int | None:
    """How many elements ``spec`` picks of a signal of ``width`` elements (None: unknown),
    if that is known: a label or an index is one element, a slice needs the width unless
    its start and stop are given and not negative. Whether they exist is ``pick``'s to say."""
    total = 0
    for part in parts(spec):
        found = _SLICE.match(part) if ":" in part else None
        if found is None:
            total += 1
            continue
        start, stop, step = (None if g is None else int(g) for g in found.groups())
        if width is not None:
            total += len(range(width)[slice(start, stop, step or 1)]) if step != 0 else 0
        elif start is not None and stop is not None and start >= 0 and stop >= 0 and (step or 1) > 0:
            total += len(range(start, stop, step or 1))
        else:
            return None
    return total


def pick(spec: str, labels: Sequence[str] | None, width: int, what: str) -> list[int]:
    """The 0-based indices ``spec`` selects of ``width`` elements named ``labels`` (None:
    numbered from 0); ``what`` names the signal in the messages (``"signal 'plant.q'"``)."""
    names = [str(x) for x in labels] if labels is not None else [str(j) for j in range(width)]
    text = spec.strip()
    if text in names:
        return [names.index(text)]
    if "," in text:
        return [j for part in parts(text) for j in pick(part, labels, width, what)]
    try:
        index = int(text)
    except ValueError:
        pass
    else:
        if labels is not None and all(_NUMBERED.match(name) for name in names):
            raise ElementError(f"{what} numbers its elements {names[0]} to {names[-1]}: [{text}] is none of them "
                               "(on such a port a number names an element; it is not an index)")
        if not -width <= index < width:
            raise ElementError(f"{what} has {width} element(s): index {index} is out of range")
        return [index % width]
    found = _SLICE.match(text)
    if found is not None and ":" in text:
        start, stop, step = (None if g is None else int(g) for g in found.groups())
        if step == 0:
            raise ElementError(f"{what}[{text}]: a slice step must not be 0")
        picked = list(range(width))[slice(start, stop, step)]
        if not picked:
            raise ElementError(f"{what}[{text}] selects no element of its {width}")
        return picked
    raise ElementError(f"{what} has no element '{text}'; its elements: {', '.join(names)} "
                       "(or an index from 0, or a slice start:stop)")


def paired_runs(sources: Sequence[int], targets: Sequence[int]) -> list[tuple[int, int, int]]:
    """Element ``sources[i]`` goes to ``targets[i]``, as runs that are consecutive on both
    sides: (first source, first target, length), for copies of whole runs."""
    found: list[tuple[int, int, int]] = []
    for a, b in zip(sources, targets):
        if found and found[-1][0] + found[-1][2] == a and found[-1][1] + found[-1][2] == b:
            found[-1] = (found[-1][0], found[-1][1], found[-1][2] + 1)
        else:
            found.append((a, b, 1))
    return found


def contiguous(indices: Sequence[int]) -> bool:
    """Whether ``indices`` are consecutive elements in increasing order."""
    return len(paired_runs(indices, indices)) <= 1
