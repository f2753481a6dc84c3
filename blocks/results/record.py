"""What a run leaves: its signals and its record (run.json's ``info``), from its outcome.

The status is 'complete', 'failed at t=...: block ... phase: message' or 'interrupted at
t=...' (with the signal's name for a ``StopRequest``); ``ended_by`` records the block that
ended a run early (``EndRun``). Element labels and units of the logged signals are asked
of their blocks once, before the run.
"""

from __future__ import annotations

import functools
import platform
from fractions import Fraction
from importlib import metadata
from typing import Any, Callable

import numpy as np

from blocks.engine.binding import Binding
from blocks.block import BlockError, EndRun, checked_units
from blocks.builder.diagram import Diagram
from blocks.engine.outcome import Failure, Outcome
from blocks.results.signals import Results
from blocks.engine.schedule import Schedule
from blocks.process.stop import StopRequest
from blocks.timebase import format_duration


class PortInfoFailure(Exception):
    """What a block raised when asked for its labels or units, as its failure at t = 0."""

    def __init__(self, failure: Failure):
        super().__init__(str(failure.error))
        self.failure = failure


def port_info(diagram: Diagram) -> tuple[dict[str, list[str]], dict[str, str | list[str]]]:
    """The element labels and units of the logged signals whose blocks or diagram give them
    (``BlockSpec.element_labels``, ``BlockSpec.port_units``), checked: one label per element; a
    unit, or one per element. What a block raises fails the run at t = 0 in that phase."""
    return _logged_port_info(diagram, "element_labels", _labels_of), _logged_port_info(diagram, "port_units",
                                                                                         _units_of)


def _logged_port_info(diagram: Diagram, phase: str, read: Callable[[Any, Any], Any]) -> dict[str, Any]:
    found = {}
    for e in diagram.log:
        try:
            value = read(diagram.blocks[e.block], e)
        except Exception as exc:
            raise PortInfoFailure(Failure(e.block, phase, 0, exc)) from exc
        if value is not None:
            found[e.signal] = value
    return found


def _labels_of(spec, e) -> list[str] | None:
    labels = spec.element_labels(e.port)
    if labels is None:
        return None
    labels = [str(label) for label in labels]
    width = spec.block.outputs[e.port]
    if len(labels) != width:
        raise BlockError(f"{len(labels)} labels for the {width} elements of '{e.port}'", port=e.port)
    return labels


def _units_of(spec, e) -> str | list[str] | None:
    units = spec.port_units(e.port)
    try:
        return checked_units(units, spec.block.outputs[e.port], e.port)
    except ValueError as exc:
        raise BlockError(str(exc), port=e.port) from None


def status_of(diagram: Diagram, schedule: Schedule, outcome: Outcome) -> str:
    """The run's status line."""
    if outcome.failure is not None:
        f = outcome.failure
        err = f.error
        port = getattr(err, "port", None)
        signal = f", signal {f.block}.{port}" if port else ""
        message = (f"EndRun must be raised from update, not {f.phase} ({err.reason})"
                   if isinstance(err, EndRun) else err)
        return (f"failed at t={float(f.tick * schedule.base_tick):.9g} s: block '{f.block}' "
                f"({diagram.blocks[f.block].type_name}){signal} {f.phase}: {message}")
    if outcome.interrupt is not None:
        by = f" by {outcome.interrupt.reason}" if isinstance(outcome.interrupt, StopRequest) else ""
        return f"interrupted at t={float(outcome.reached * schedule.base_tick):.9g} s{by}"
    return "complete"


def stop_time(schedule: Schedule, outcome: Outcome) -> float:
    """Where a run that did not complete stopped, in seconds."""
    tick = outcome.failure.tick if outcome.failure is not None else outcome.reached
    return float(tick * schedule.base_tick)


def ended_by(diagram: Diagram, schedule: Schedule, outcome: Outcome) -> dict[str, Any] | None:
    """run.json's record of the EndRun that ended a complete run before its end time."""
    if outcome.end is None or outcome.end == schedule.n_ticks or outcome.end_request is None:
        return None
    name, reason, asked = outcome.end_request
    tick = schedule.base_tick
    return {"block": name, "type": diagram.blocks[name].type_name, "time": float(outcome.end * tick),
            "tick_time": float(asked * tick), "reason": reason}


def signals(diagram: Diagram, schedule: Schedule, binding: Binding) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The logged signals, in the diagram's order: sample times and values; once more if an
    interrupt cuts the copying short (a program that defers later interrupts lets the
    second try finish), since the signals are all there is of the run."""
    try:
        return _signals(diagram, schedule, binding)
    except KeyboardInterrupt:
        return _signals(diagram, schedule, binding)


def _signals(diagram: Diagram, schedule: Schedule, binding: Binding) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    row_of = {j: r for r, j in enumerate(binding.table.names.log_order)}
    found = {}
    for j, e in enumerate(diagram.log):
        rows, buffer = binding.rows_logged(row_of[j]), binding.logs[row_of[j]]
        # the run's own buffer when the run filled it; a copy of what a run cut short logged
        rows = buffer if len(rows) == len(buffer) else rows.copy()
        found[e.signal] = (schedule.sample_times(e.block, len(rows), e.decimate), rows)
    return found


def info(diagram: Diagram, schedule: Schedule, t_end: Fraction, status: str, wall: float, t_stop: float | None,
         ended: dict | None, labels: dict[str, list[str]], units: dict[str, str | list[str]]) -> dict:
    """run.json's record of the run (``element_labels`` only when a block names elements,
    ``units`` only when a block knows the units of a logged signal, ``decimate`` only for
    signals logged at fewer than every hit)."""
    simulated = float(t_end) if t_stop is None else t_stop
    record = {
        "diagram": diagram.name,
        "diagram_file": diagram.file,
        "diagram_hash": diagram.source_hash,
        "status": status,
        "t_end": float(t_end),
        "t_end_exact": str(t_end),
        "base_tick": format_duration(schedule.base_tick),
        "wall_time_s": wall,
        "real_time_factor": simulated / wall if wall > 0 else None,
        "t_stop": t_stop,
        "ended_by": ended,
        "block_types": {name: spec.type_name for name, spec in diagram.blocks.items()},
        "parameters": diagram.parameters(),
        "versions": dict(package_versions()),
    }
    if diagram.subsystems:
        record["subsystems"] = diagram.composition()
    decimated = {e.signal: e.decimate for e in diagram.log if e.decimate > 1}
    if decimated:
        record["decimate"] = decimated
    if labels:
        record["element_labels"] = labels
    if units:
        record["units"] = units
    return record


def results_of(diagram: Diagram, schedule: Schedule, t_end: Fraction, binding: Binding, outcome: Outcome,
               wall: float, labels: dict, units: dict) -> Results:
    """The Results of a run: its signals and its record."""
    status = status_of(diagram, schedule, outcome)
    ended = ended_by(diagram, schedule, outcome)
    if status != "complete":
        t_stop = stop_time(schedule, outcome)
    else:
        t_stop = None if ended is None else ended["time"]
    return Results(signals(diagram, schedule, binding), info(diagram, schedule, t_end, status, wall, t_stop, ended,
                                                              labels, units))


@functools.cache
def package_versions() -> dict[str, str]:
    """Versions of Python and the packages that shape a run's numbers."""
    versions = {"python": platform.python_version()}
    for dist in ("hierhand", "numpy", "networkx", "control", "fmpy"):
        try:
            versions[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            pass
    return versions
