"""Event markers of a run's plots: what its diagram makes happen, and when.

A marker spans ``start`` to ``end`` (equal for an instant) and says what happens, in the
words ``during`` (while it lasts) or ``after`` (once it is over). The framework marks each
``Step`` block's switching time. An application adds its own through the entry-point group
``blocks.plot.markers`` (the hand registers its task phases: the support's hand-over, the
fingertip trajectories' spans), as it registers block types and sweep measures::

    [project.entry-points."blocks.plot_markers"]
    task_phases = "mypackage.phases:task_phases"

or, from Python, with ``register_markers(name, source)``. A source is a function of a
run's ``run.json`` info (``block_types`` and ``parameters`` say what the diagram holds)
returning objects with ``start``, ``end``, ``during`` and ``after``: Markers, or anything
shaped like them. A source that fails or returns something else is left out, with the
reason, so a plot never fails for a marker. ``draw_markers`` draws them on matplotlib axes,
for the signal plots and the application's figures alike.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Iterable, Sequence

from blocks.plugins import load_group

MARKER_COLOUR = "dimgray"
"""The colour of every marker, on signal plots and on the application's figures."""
MARKER_GID = "marker"
"""The gid of every artist that draws a marker (their lines, spans and texts)."""

ENTRY_POINT_GROUP = "blocks.plot_markers"

MarkerSource = Callable[[dict], Iterable[Any]]


@dataclass(frozen=True)
class Marker:
    """Something the diagram makes happen from ``start`` to ``end`` (seconds)."""

    start: float
    end: float
    during: str = ""
    after: str = ""

    @property
    def label(self) -> str:
        return self.during or self.after

    @property
    def instant(self) -> bool:
        return self.end <= self.start


def step_markers(info: dict) -> list[Marker]:
    """Each Step block's switching time, from run.json's parameters."""
    types = info.get("block_types") or {}
    params = info.get("parameters") or {}
    out = []
    for name, kind in types.items():
        at = (params.get(name) or {}).get("time")
        if kind == "Step" and _finite(at):
            out.append(Marker(float(at), float(at), "", f"{name}: step at {float(at):g} s"))
    return out


_registered: dict[str, MarkerSource] = {}


def register_markers(name: str, source: MarkerSource) -> MarkerSource:
    """Add a marker source from Python (ahead of an entry point of the same name)."""
    if not callable(source):
        raise TypeError(f"marker source {name!r}: {source!r} is not callable")
    _registered[name] = source
    return source


def unregister_markers(name: str) -> None:
    _registered.pop(name, None)


def marker_sources() -> tuple[dict[str, MarkerSource], dict[str, str]]:
    """(every source by name: the framework's, the installed, the registered; why any
    installed one is left out)."""
    installed, errors = load_group(ENTRY_POINT_GROUP, lambda obj: None if callable(obj) else "is not callable")
    return {"steps": step_markers, **installed, **_registered}, errors


def markers(info: dict) -> tuple[list[Marker], list[str]]:
    """The run's markers, in time order, each once (a Step an application also marks is
    one marker), and a note per source left out."""
    sources, errors = marker_sources()
    notes = [f"markers '{name}' left out: {why}" for name, why in errors.items()]
    found: dict[tuple[float, float, str], Marker] = {}
    for name, source in sources.items():
        try:
            items = [_as_marker(item) for item in source(info)]
        except Exception as exc:  # a broken plug-in must not break the plot
            notes.append(f"markers '{name}' left out: {type(exc).__name__}: {exc}")
            continue
        for m in items:
            if m.label:
                found.setdefault((m.start, m.end, m.label), m)
    return sorted(found.values(), key=lambda m: (m.start, m.end)), notes


def _as_marker(item: Any) -> Marker:
    if isinstance(item, Marker):
        return item
    start, end = getattr(item, "start", None), getattr(item, "end", None)
    if not (_finite(start) and _finite(end)):
        raise ValueError(f"{item!r} has no finite start and end")
    return Marker(float(start), float(end), str(getattr(item, "during", "") or ""),
                  str(getattr(item, "after", "") or ""))


def _finite(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def draw_markers(axes: Sequence, markers: Sequence[Marker]) -> None:
    """Each marker on every one of matplotlib ``axes``: a dotted line at an instant, a light
    band over a span; its words at the top of the first axis, cut off at the axis's edge."""
    for m in markers:
        for ax in axes:
            if m.instant:
                ax.axvline(m.start, color=MARKER_COLOUR, ls=":", lw=1.0, gid=MARKER_GID)
            else:
                ax.axvspan(m.start, m.end, color=MARKER_COLOUR, alpha=0.08, lw=0, gid=MARKER_GID)
        axes[0].annotate(m.label, xy=(m.start, 1.0), xycoords=("data", "axes fraction"), xytext=(2, -2),
                         textcoords="offset points", rotation=90, ha="left", va="top", fontsize="x-small",
                         color=MARKER_COLOUR, gid=MARKER_GID, annotation_clip=True, clip_on=True,
                         bbox={"boxstyle": "square,pad=0.1", "facecolor": "white", "alpha": 0.7, "linewidth": 0})
