"""Metric expressions: what number a sweep keeps from each run, and computing it.

``NAME=REDUCER(BLOCK.PORT[i])`` reduces one element of a logged signal: final, max, min,
mean, or ``first_time_above(BLOCK.PORT[i], x)`` / ``first_time_below(BLOCK.PORT[i], x)``
(the first sample time strictly above / below x; empty when it never happens). The index
may be left out for a signal of width 1. ``NAME=MEASURE`` or ``NAME=MEASURE(a, ...)``
names a measure that an application registered (``measures``: the entry-point group
``blocks.measures``, or ``register_measure``), with numbers as its arguments.

Metrics are checked against the diagram before any run starts (known reducer or measure,
logged signal, index in range, the measure's own ``check``), so a typo fails in a
second, not after the sweep.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from .errors import SweepError
from .measures import Measure, arity_problem, find_measure, registered_measures, require_logged

REDUCERS = ("final", "max", "min", "mean")
THRESHOLD_REDUCERS = ("first_time_above", "first_time_below")

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_CALL = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*(?:\((.*)\))?$", re.S)
_SIGNAL = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)\.([A-Za-z_][A-Za-z0-9_]*)\s*"
                     r"(?:\[\s*(-?\d+)\s*\])?$")
"""``block.port`` or ``block.port[i]``; the block may be a path into subsystems (``ctrl.integ``)."""


@dataclass(frozen=True)
class Metric:
    """A parsed ``--metric``: its column name, what it computes and its source text."""

    name: str
    kind: str
    """A reducer (REDUCERS, THRESHOLD_REDUCERS) or the name of a measure."""
    text: str
    signal: str | None = None
    index: int | None = None
    threshold: float | None = None
    measure: Measure | None = None
    """The registered measure that ``kind`` names (None for a reducer)."""
    args: tuple[float, ...] = ()
    """The measure's arguments."""

    def unit(self, diagram) -> str | None:
        """The unit of this metric's values, where it is known: a reducer's is its signal
        element's (as the diagram's ports give them), a first time's is seconds, a
        measure's its ``unit`` attribute; None when unknown."""
        if self.measure is not None:
            unit = getattr(self.measure, "unit", None)
            return unit if isinstance(unit, str) else None
        if self.kind in THRESHOLD_REDUCERS:
            return "s"
        block, port = self.signal.rsplit(".", 1)
        spec = diagram.blocks.get(block)
        try:
            units = spec.port_units(port) if spec is not None else None
        except Exception:  # a block's port_units that fails says no unit here; the run says why
            return None
        if isinstance(units, (list, tuple)):
            index = self.index or 0
            units = units[index] if -len(units) <= index < len(units) else None
        return units if isinstance(units, str) and units else None

    # -- checking against the diagram before the sweep --------------------------------

    def check(self, diagram) -> None:
        """SweepError if this metric cannot be computed from ``diagram``'s logged signals."""
        if self.measure is not None:
            check = getattr(self.measure, "check", None)
            try:
                if check is not None:
                    check(diagram, *self.args)
            except ValueError as exc:
                raise SweepError(f"--metric {self.text}: {exc}") from None
            return
        block, port = self.signal.rsplit(".", 1)
        if block not in diagram.blocks:
            raise SweepError(f"--metric {self.text}: no block named '{block}'; blocks are: "
                             f"{', '.join(diagram.blocks)}")
        outputs = diagram.blocks[block].block.outputs
        if port not in outputs:
            raise SweepError(f"--metric {self.text}: block '{block}' has no output '{port}'; "
                             f"outputs: {', '.join(outputs) or 'none'}")
        try:
            require_logged(diagram, [self.signal])
        except ValueError as exc:
            raise SweepError(f"--metric {self.text}: {exc}") from None
        width = outputs[port]
        if self.index is None and width != 1:
            raise SweepError(f"--metric {self.text}: {self.signal} has width {width}; pick an "
                             f"element, e.g. {self.signal}[0]")
        if self.index is not None and not 0 <= self.index < width:
            raise SweepError(f"--metric {self.text}: index {self.index} is out of range for "
                             f"{self.signal} (width {width}, indices 0..{width - 1})")

    # -- computing -------------------------------------------------------------------

    def evaluate(self, results, diagram) -> float | None:
        """The metric's value for one run (None: the event never happened)."""
        if self.measure is not None:
            value = self.measure(results, diagram, *self.args)
            return None if value is None else float(value)
        t, values = results[self.signal]
        if len(t) == 0:
            raise ValueError(f"{self.signal} has no samples")
        column = values[:, self.index or 0]
        return reduce(self.kind, t, column, self.threshold)


def reduce(kind: str, t: np.ndarray, column: np.ndarray, threshold: float | None = None) -> float | None:
    """Apply one reducer to a signal element sampled at times ``t``."""
    if kind == "final":
        return float(column[-1])
    if kind == "max":
        return float(np.max(column))
    if kind == "min":
        return float(np.min(column))
    if kind == "mean":
        return float(np.mean(column))
    hits = np.flatnonzero(column > threshold if kind == "first_time_above" else column < threshold)
    return float(t[hits[0]]) if hits.size else None


def parse_metric(item: str) -> Metric:
    """Parse one ``--metric NAME=EXPR`` (see the module docstring for the forms of EXPR)."""
    name, eq, expr = item.partition("=")
    name, expr = name.strip(), expr.strip()
    if not eq or not _NAME.match(name):
        raise SweepError(f"--metric {item!r}: expected NAME=REDUCER(BLOCK.PORT[i]) or NAME=MEASURE, "
                         "e.g. --metric y_end=final(plant.y)")
    m = _CALL.match(expr)
    if not m:
        raise SweepError(f"--metric {item!r}: cannot read {expr!r}; expected REDUCER(BLOCK.PORT[i])")
    kind, inner = m.group(1), m.group(2)
    args = [a.strip() for a in inner.split(",")] if inner is not None and inner.strip() else []
    if kind not in REDUCERS + THRESHOLD_REDUCERS:
        return _measure_metric(item, name, kind, args)
    want = 2 if kind in THRESHOLD_REDUCERS else 1
    if len(args) != want:
        form = f"{kind}(BLOCK.PORT[i], X)" if want == 2 else f"{kind}(BLOCK.PORT[i])"
        raise SweepError(f"--metric {item!r}: {kind} takes {want} argument(s): {form}")
    s = _SIGNAL.match(args[0])
    if not s:
        raise SweepError(f"--metric {item!r}: {args[0]!r} is not a signal BLOCK.PORT or BLOCK.PORT[i]")
    threshold = _number(item, args[1]) if want == 2 else None
    index = int(s.group(3)) if s.group(3) is not None else None
    if index is not None and index < 0:
        raise SweepError(f"--metric {item!r}: index {index} must be 0 or more")
    return Metric(name=name, kind=kind, text=item, signal=f"{s.group(1)}.{s.group(2)}", index=index,
                  threshold=threshold)


def _measure_metric(item: str, name: str, kind: str, args: list[str]) -> Metric:
    measure = find_measure(kind)
    if measure is None:
        known = REDUCERS + THRESHOLD_REDUCERS + tuple(sorted(registered_measures()))
        raise SweepError(f"--metric {item!r}: unknown reducer or measure '{kind}'; known: {', '.join(known)}")
    problem = arity_problem(kind, measure, len(args))
    if problem:
        raise SweepError(f"--metric {item!r}: {problem}")
    return Metric(name=name, kind=kind, text=item, measure=measure, args=tuple(_number(item, a) for a in args))


def _number(item: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise SweepError(f"--metric {item!r}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise SweepError(f"--metric {item!r}: {text!r} is not a finite number")
    return value


def parse_metrics(items: Sequence[str | Metric]) -> list[Metric]:
    """Parse every ``--metric`` (parsed ones are kept as they are); names must be distinct."""
    metrics = [i if isinstance(i, Metric) else parse_metric(i) for i in items]
    names = [m.name for m in metrics]
    for n in names:
        if names.count(n) > 1:
            raise SweepError(f"--metric: the name '{n}' is used twice")
    return metrics


def metric_value_text(value: Any) -> str:
    """A metric value as a CSV cell: full-precision number, empty for None/NaN."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return repr(float(value))
