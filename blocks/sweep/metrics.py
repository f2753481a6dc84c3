"""Metric expressions: what number a sweep keeps from each run, and computing it.

``NAME=REDUCER(BLOCK.PORT[e])`` reduces one element of a logged signal: final, max, min,
mean, or ``first_time_above(BLOCK.PORT[e], x)`` / ``first_time_below(BLOCK.PORT[e], x)``
(the first sample time strictly above / below x; empty when it never happens). The
element ``e`` is read as a connection and ``plot -s`` read it (``blocks.builder.elements``):
the label its block gives it first (an FMU's ``q[1]`` is the element the FMU calls
``q[1]``), else a 0-based index. It may be left out for a signal of width 1. ``NAME=MEASURE`` or ``NAME=MEASURE(a, ...)``
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

from blocks.builder.elements import pick, split_signal, split_signals

from .errors import SweepError
from .measures import Measure, arity_problem, find_measure, registered_measures, require_logged

REDUCERS = ("final", "max", "min", "mean")
THRESHOLD_REDUCERS = ("first_time_above", "first_time_below")

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_CALL = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*(?:\((.*)\))?$", re.S)


@dataclass(frozen=True)
class Metric:
    """A parsed ``--metric``: its column name, what it computes and its source text."""

    name: str
    kind: str
    """A reducer (REDUCERS, THRESHOLD_REDUCERS) or the name of a measure."""
    text: str
    signal: str | None = None
    element: str | None = None
    """The element of ``signal`` as written between its brackets (a label or an index);
    None for a signal of width 1."""
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
            if isinstance(units, (list, tuple)):
                units = units[self.column(spec.element_labels(port), len(units))]
        except Exception:  # a block's port_units that fails says no unit here; the run says why
            return None
        return units if isinstance(units, str) and units else None

    def column(self, labels: Sequence[str] | None, width: int) -> int:
        """The column of this metric's element in a signal of ``width`` elements that its
        block labels ``labels`` (None: numbered from 0); ValueError if it names none, or
        more than one."""
        if self.element is None:
            if width != 1:
                first = labels[0] if labels else "0"
                raise ValueError(f"{self.signal} has width {width}; pick an element, e.g. {self.signal}[{first}]")
            return 0
        picked = pick(self.element, labels, width, f"signal '{self.signal}'")
        if len(picked) != 1:
            raise ValueError(f"{self.signal}[{self.element}] is {len(picked)} elements; a metric reduces one")
        return picked[0]

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
        try:
            self.column(diagram.blocks[block].element_labels(port), outputs[port])
        except ValueError as exc:  # an ElementError included
            raise SweepError(f"--metric {self.text}: {exc}") from None

    # -- computing -------------------------------------------------------------------

    def evaluate(self, results, diagram) -> float | None:
        """The metric's value for one run (None: the event never happened)."""
        if self.measure is not None:
            value = self.measure(results, diagram, *self.args)
            return None if value is None else float(value)
        t, values = results[self.signal]
        if len(t) == 0:
            raise ValueError(f"{self.signal} has no samples")
        column = values[:, self.column(results.element_labels(self.signal), values.shape[1])]
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
        raise SweepError(f"--metric {item!r}: expected NAME=REDUCER(BLOCK.PORT[e]) or NAME=MEASURE, "
                         "e.g. --metric y_end=final(plant.y)")
    m = _CALL.match(expr)
    if not m:
        raise SweepError(f"--metric {item!r}: cannot read {expr!r}; expected REDUCER(BLOCK.PORT[e])")
    kind, inner = m.group(1), m.group(2)
    args = split_signals(inner) if inner is not None and inner.strip() else []
    if kind not in REDUCERS + THRESHOLD_REDUCERS:
        return _measure_metric(item, name, kind, args)
    want = 2 if kind in THRESHOLD_REDUCERS else 1
    if len(args) != want:
        form = f"{kind}(BLOCK.PORT[e], X)" if want == 2 else f"{kind}(BLOCK.PORT[e])"
        raise SweepError(f"--metric {item!r}: {kind} takes {want} argument(s): {form}")
    found = split_signal(args[0])
    if found is None or found[1] == "":
        raise SweepError(f"--metric {item!r}: {args[0]!r} is not a signal BLOCK.PORT or an element of one "
                         "BLOCK.PORT[e] (its label, or an index from 0)")
    threshold = _number(item, args[1]) if want == 2 else None
    return Metric(name=name, kind=kind, text=item, signal=found[0], element=found[1], threshold=threshold)


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
