"""Named measures: the numbers an application computes from a run, registered by name.

A metric expression names a measure as ``NAME=MEASURE`` or ``NAME=MEASURE(a, b)``
(``--metric ts=settling_time(0.02)``). The framework knows no measures of its own; an
application registers them through the entry-point group ``blocks.measures``, as it
registers block types through ``blocks.types``::

    [project.entry-points."blocks.measures"]
    settling_time = "mypackage.measures:settling_time"

or, from Python, with ``register_measure(name, measure)``.

The contract of a measure:

- ``measure(results, diagram, *args) -> float | None``: ``results`` is the run's
  ``Results``, ``diagram`` the ``Diagram`` it ran (with the point's parameters, for a
  measure that reads one), and ``args`` the numbers written in the parentheses, as floats.
  Parameters after ``diagram`` that have defaults are optional arguments; the signature
  says how many a measure takes, and a metric giving more or fewer is refused when it is
  parsed. The value is a number (a bool counts as 0 or 1), or None when the event it
  times never happened (an empty cell in sweep.csv). A measure that cannot be computed
  raises; that run is recorded as failed and the sweep goes on.
- An optional attribute ``check(diagram, *args)``, called once before a sweep runs
  anything (``checked_by`` attaches it): it raises ``ValueError`` with a one-line reason
  when the measure cannot be computed from that diagram (a signal it reads is not logged,
  a parameter it needs is missing), so a sweep that cannot work fails in a second.
  ``require_logged`` gives the standard message for unlogged signals.
- An optional attribute ``unit`` (``"s"``, ``"1"`` for a dimensionless number): sweep.json
  records it under ``units`` and ``sweep-plot`` labels the metric with it.
- Measures travel to Dask workers with the metric: a module-level function is sent as a
  reference to it, anything else as cloudpickle can send it.
"""

from __future__ import annotations

import inspect
from typing import Any, Callable, Iterable

from ..plugins import load_group
from .errors import SweepError

ENTRY_POINT_GROUP = "blocks.measures"

Measure = Callable[..., Any]
"""``measure(results, diagram, *args) -> float | None`` (see the module's note)."""

_registered: dict[str, Measure] = {}
_installed: dict[str, Measure] | None = None
_load_errors: dict[str, str] = {}


def register_measure(name: str, measure: Measure) -> Measure:
    """Make ``measure`` available as ``NAME=name(...)`` in metrics, ahead of any entry point
    of the same name; returns it, so it also serves as a decorator's body."""
    if not callable(measure):
        raise TypeError(f"measure {name!r}: {measure!r} is not callable")
    _registered[name] = measure
    return measure


def unregister_measure(name: str) -> None:
    """Forget a measure given to ``register_measure`` (entry points stay)."""
    _registered.pop(name, None)


def registered_measures() -> dict[str, Measure]:
    """Every known measure by name: the installed entry points, then those registered from Python."""
    return {**_installed_measures(), **_registered}


def find_measure(name: str) -> Measure | None:
    """The measure called ``name``; None if there is none. SweepError if it is installed but
    fails to load."""
    found = registered_measures().get(name)
    if found is None and name in _load_errors:
        raise SweepError(f"measure '{name}' is registered but failed to load: {_load_errors[name]} "
                         "(hint: reinstall the package that provides it)")
    return found


def _installed_measures() -> dict[str, Measure]:
    global _installed
    if _installed is None:
        _installed, errors = load_group(ENTRY_POINT_GROUP, lambda obj: None if callable(obj) else "is not callable")
        _load_errors.update(errors)
    return _installed


def arity_problem(name: str, measure: Measure, given: int) -> str | None:
    """Why a metric's ``given`` arguments do not fit ``measure``'s signature ('separation_time
    takes no arguments'), or None when they do (or the signature cannot be read)."""
    try:
        params = list(inspect.signature(measure).parameters.values())
    except (TypeError, ValueError):  # some callables do not tell
        return None
    if any(p.kind is p.VAR_POSITIONAL for p in params):
        return None
    positional = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    if len(positional) < 2:
        return f"{name} is not a measure(results, diagram, ...): it takes {len(positional)} argument(s)"
    names = [p.name.replace("_", " ") for p in positional[2:]]
    required = sum(p.default is p.empty for p in positional[2:])
    if required <= given <= len(names):
        return None
    if not names:
        return f"{name} takes no arguments"
    bound = "" if required == len(names) else "at most " if given > len(names) else "at least "
    count = len(names) if given > len(names) or not bound else required
    listed = " and ".join([", ".join(names[:-1]), names[-1]] if len(names) > 1 else names)
    return f"{name} takes {bound}{_count(count)}, the {listed}"


def _count(n: int) -> str:
    """'one argument', 'two arguments', '5 arguments'."""
    return f"{_NUMBERS.get(n, str(n))} argument{'s' if n != 1 else ''}"


_NUMBERS = {1: "one", 2: "two", 3: "three"}


def checked_by(check: Callable[..., None]) -> Callable[[Measure], Measure]:
    """Decorator: attach ``check(diagram, *args)`` to a measure (see the module's note)."""
    def attach(measure: Measure) -> Measure:
        measure.check = check
        return measure
    return attach


def require_logged(diagram, signals: Iterable[str]) -> None:
    """ValueError naming the first of ``signals`` that ``diagram`` does not log."""
    logged = {e.signal for e in diagram.log}
    for signal in signals:
        if signal not in logged:
            raise ValueError(f"the signal {signal} is not logged by the diagram; add it to its log: list")
