"""Sweep metrics: one number per run, from a logged signal or a hand task's summary.

``NAME=REDUCER(BLOCK.PORT[i])`` reduces one element of a logged signal: final, max, min,
mean, or ``first_time_above(BLOCK.PORT[i], x)`` / ``first_time_below(BLOCK.PORT[i], x)``
(the first sample time strictly above / below x; empty when it never happens). The index
may be left out for a signal of width 1. ``NAME=TASK_MEASURE`` names a quantity of the
hand tasks (hierhand.tasks.metrics), computed with the task diagrams' block names
(plant, reflex, manip, suppress):

- ``separation_time``: when the forefinger lets go after the middle finger's contact
  (regrasp_events); empty if it never does;
- ``object_dropped``: 1 if the object was dropped, else 0;
- ``peak_ratio`` / ``recovery_time``: peak |f_t|/f_n after the disturbance and the time
  until it is back under the safety ratio (grasp_summary); the disturbance time is the
  argument, ``peak_ratio(0.5)``, or else the ``time`` parameter of a block named ``push``.

Metrics are checked against the diagram before any run starts (known measure, logged
signal, index in range), so a typo fails in a second, not after the sweep.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from .errors import SweepError

REDUCERS = ("final", "max", "min", "mean")
THRESHOLD_REDUCERS = ("first_time_above", "first_time_below")
TASK_MEASURES = ("separation_time", "object_dropped", "peak_ratio", "recovery_time")
DISTURBANCE_BLOCK = "push"

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_CALL = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*(?:\((.*)\))?$", re.S)
_SIGNAL = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\.([A-Za-z_][A-Za-z0-9_]*)\s*(?:\[\s*(-?\d+)\s*\])?$")


@dataclass(frozen=True)
class Metric:
    """A parsed ``--metric``: its column name, what it computes and its source text."""

    name: str
    kind: str
    """A reducer (REDUCERS, THRESHOLD_REDUCERS) or a task measure (TASK_MEASURES)."""
    text: str
    signal: str | None = None
    index: int | None = None
    threshold: float | None = None
    disturbance_time: float | None = None

    # -- checking against the diagram before the sweep --------------------------------

    def check(self, diagram) -> None:
        """SweepError if this metric cannot be computed from ``diagram``'s logged signals."""
        if self.signal is not None:
            block, port = self.signal.split(".")
            if block not in diagram.blocks:
                raise SweepError(f"--metric {self.text}: no block named '{block}'; blocks are: "
                                 f"{', '.join(diagram.blocks)}")
            outputs = diagram.blocks[block].block.outputs
            if port not in outputs:
                raise SweepError(f"--metric {self.text}: block '{block}' has no output '{port}'; "
                                 f"outputs: {', '.join(outputs) or 'none'}")
            _require_logged(self, diagram, [self.signal])
            width = outputs[port]
            if self.index is None and width != 1:
                raise SweepError(f"--metric {self.text}: {self.signal} has width {width}; pick an "
                                 f"element, e.g. {self.signal}[0]")
            if self.index is not None and not 0 <= self.index < width:
                raise SweepError(f"--metric {self.text}: index {self.index} is out of range for "
                                 f"{self.signal} (width {width}, indices 0..{width - 1})")
            return
        needed = ["plant.contact", "plant.obj"] + (["plant.ratio"] if self.kind in ("peak_ratio", "recovery_time")
                                                   else [])
        _require_logged(self, diagram, needed)
        if self.kind in ("peak_ratio", "recovery_time") and self.disturbance_time is None:
            push = diagram.blocks.get(DISTURBANCE_BLOCK)
            if push is None or "time" not in push.params:
                raise SweepError(f"--metric {self.text}: needs the disturbance time: write "
                                 f"{self.kind}(T) with T in seconds (the diagram has no '{DISTURBANCE_BLOCK}' "
                                 "block with a 'time' parameter)")

    # -- computing -------------------------------------------------------------------

    def evaluate(self, results, diagram) -> float | None:
        """The metric's value for one run (None: the event never happened)."""
        from hierhand.tasks import metrics as task

        if self.kind == "separation_time":
            return task.regrasp_events(results)["fore_separation_time_s"]
        if self.kind == "object_dropped":
            return float(task.object_dropped(results))
        if self.kind in ("peak_ratio", "recovery_time"):
            t0 = self.disturbance_time
            if t0 is None:
                t0 = float(diagram.blocks[DISTURBANCE_BLOCK].params["time"])
            summary = task.grasp_summary(results, t0)
            return summary["peak_ratio" if self.kind == "peak_ratio" else "recovery_time_s"]
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


def _require_logged(metric: Metric, diagram, signals: Sequence[str]) -> None:
    logged = {e.signal for e in diagram.log}
    for signal in signals:
        if signal not in logged:
            raise SweepError(f"--metric {metric.text}: the signal {signal} is not logged by the diagram; "
                             "add it to its log: list")


def parse_metric(item: str) -> Metric:
    """Parse one ``--metric NAME=EXPR`` (see the module docstring for the forms of EXPR)."""
    name, eq, expr = item.partition("=")
    name, expr = name.strip(), expr.strip()
    if not eq or not _NAME.match(name):
        raise SweepError(f"--metric {item!r}: expected NAME=REDUCER(BLOCK.PORT[i]) or NAME=MEASURE, "
                         "e.g. --metric y_end=final(plant.y) or --metric sep=separation_time")
    m = _CALL.match(expr)
    if not m:
        raise SweepError(f"--metric {item!r}: cannot read {expr!r}; expected REDUCER(BLOCK.PORT[i])")
    kind, inner = m.group(1), m.group(2)
    args = [a.strip() for a in inner.split(",")] if inner is not None and inner.strip() else []
    known = REDUCERS + THRESHOLD_REDUCERS + TASK_MEASURES
    if kind not in known:
        raise SweepError(f"--metric {item!r}: unknown reducer or measure '{kind}'; known: {', '.join(known)}")
    if kind in TASK_MEASURES:
        return _task_metric(item, name, kind, args)
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


def _task_metric(item: str, name: str, kind: str, args: list[str]) -> Metric:
    if kind in ("peak_ratio", "recovery_time"):
        if len(args) > 1:
            raise SweepError(f"--metric {item!r}: {kind} takes at most one argument, the disturbance time")
        return Metric(name=name, kind=kind, text=item,
                      disturbance_time=_number(item, args[0]) if args else None)
    if args:
        raise SweepError(f"--metric {item!r}: {kind} takes no arguments")
    return Metric(name=name, kind=kind, text=item)


def _number(item: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise SweepError(f"--metric {item!r}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise SweepError(f"--metric {item!r}: {text!r} is not a finite number")
    return value


def parse_metrics(items: Sequence[str]) -> list[Metric]:
    """Parse every ``--metric``; names must be distinct."""
    metrics = [parse_metric(i) for i in items]
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
