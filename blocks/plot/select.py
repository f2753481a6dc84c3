"""What a plot shows: signals, elements of them, and which share an axis.

A selection is the text of one ``plot -s``: one axis, holding one or more signals
separated by commas, each optionally narrowed to some of its elements in brackets, as a
connection names them (``blocks.builder.elements``)::

    plant.q                      every element of plant.q
    plant.q[fore.1]              the element the block labels fore.1
    plant.q[3]  plant.q[0:3]     by 0-based index, or a slice (start:stop[:step])
    plant.q[thumb.1,fore.1]      several elements, by label or index
    plant.q[fore.1],ref.y        two signals overlaid on one axis

Commas inside brackets list elements; outside they separate signals. ``results`` is a
``blocks.Results`` (typed Any: ``Results.plot`` draws through this package, which
therefore does not import it back).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from blocks.builder.elements import ElementError, pick, split_signal, split_signals


class SelectionError(ElementError):
    """A selection that names no logged signal or element (one line, with what there is)."""


@dataclass(frozen=True)
class Trace:
    """Some elements of one signal: ``columns`` into its values, their ``labels`` as the
    block names them (or their indices), and ``title``: the signal as selected."""

    signal: str
    columns: tuple[int, ...]
    labels: tuple[str, ...]
    title: str

    @property
    def whole(self) -> bool:
        return self.title == self.signal


def select(results: Any, text: str) -> list[Trace]:
    """The traces of one axis, from the text of one selection."""
    traces = []
    for part in split_signals(text):
        found = split_signal(part)
        if found is None:
            raise SelectionError(f"'{part}' is not a signal (block.port) or an element of one (block.port[label])")
        signal, elements = found
        if signal not in results:
            raise SelectionError(f"signal '{signal}' was not logged; logged signals: "
                                 f"{', '.join(results) or 'none'}")
        traces.append(_trace(results, signal, elements))
    return traces


def by_unit(results: Any, traces: list[Trace]) -> list[list[Trace]]:
    """The axes an axis of ``traces`` becomes so that each has one unit: a whole signal
    whose elements differ in unit (``plant.obj``: x, y in m, theta in rad) one axis per
    unit, ``plant.obj[x,y]`` and ``plant.obj[theta]``, in the order the units come; any
    other selection (elements, overlays) one axis, as asked."""
    if len(traces) != 1 or not traces[0].whole:
        return [traces]
    (tr,) = traces
    units = results.units(tr.signal)
    if units is None or len(set(units)) < 2:
        return [traces]
    groups: dict[str, list[int]] = {}
    for column, unit in zip(tr.columns, units):
        groups.setdefault(unit, []).append(column)
    return [[Trace(tr.signal, tuple(cols), tuple(tr.labels[c] for c in cols),
                   f"{tr.signal}[{','.join(tr.labels[c] for c in cols)}]")] for cols in groups.values()]


def _trace(results: Any, signal: str, elements: str | None) -> Trace:
    width = results[signal][1].shape[1]
    given = results.element_labels(signal)
    labels = given or [str(j) for j in range(width)]
    if elements is None:
        return Trace(signal, tuple(range(width)), tuple(labels if given else (f"[{j}]" for j in range(width))),
                     signal)
    try:
        columns = pick(elements, labels, width, f"signal '{signal}'")
    except ElementError as exc:
        raise SelectionError(str(exc)) from None
    return Trace(signal, tuple(columns), tuple(labels[c] for c in columns), f"{signal}[{elements}]")
