"""The hand tasks' scalar measures, registered for sweeps under ``blocks.measures``.

Each is one number of a task summary (``summaries``), on the diagram's hand plant (found
by ``TaskBlocks``, whatever its name), in the framework's measure contract
(``blocks.sweep.measures``): ``measure(results, diagram, *args) -> float | None`` with a
``check(diagram, *args)`` that refuses a diagram which does not log what it reads.

- ``separation_time``: when the forefinger lets go after the middle finger's contact
  (``regrasp_events``); None if it never does;
- ``object_dropped``: 1 if the object was dropped, else 0;
- ``peak_ratio`` / ``recovery_time``: peak |f_t|/f_n after the disturbance and the time
  until it is back under the safety ratio (``grasp_summary``); the disturbance time is
  the argument, ``peak_ratio(0.5)``, or else the ``time`` parameter of a block named
  ``push``.
"""

from __future__ import annotations

from blocks.sweep.measures import checked_by, require_logged

from .summaries import TaskBlocks, grasp_summary, object_dropped as dropped, regrasp_events

DISTURBANCE_BLOCK = "push"
"""The block whose ``time`` parameter is the disturbance time when a metric gives none."""

CONTACT_PORTS = ("contact", "obj")
"""What every hand measure reads of the plant: the contact flags and the object pose."""
RATIO_PORTS = (*CONTACT_PORTS, "ratio")


def _require_plant_signals(diagram, ports: tuple[str, ...]) -> None:
    plant = TaskBlocks.of_diagram(diagram).plant
    require_logged(diagram, [f"{plant}.{port}" for port in ports])


def _check_contact(diagram) -> None:
    _require_plant_signals(diagram, CONTACT_PORTS)


def _check_ratio(measure: str):
    """The check of a ratio measure: the signals, and a disturbance time from somewhere."""
    def check(diagram, disturbance_time: float | None = None) -> None:
        _require_plant_signals(diagram, RATIO_PORTS)
        if disturbance_time is None:
            push = diagram.blocks.get(DISTURBANCE_BLOCK)
            if push is None or "time" not in push.params:
                raise ValueError(f"needs the disturbance time: write {measure}(T) with T in seconds (the "
                                 f"diagram has no '{DISTURBANCE_BLOCK}' block with a 'time' parameter)")
    return check


def _disturbance(diagram, disturbance_time: float | None) -> float:
    if disturbance_time is not None:
        return disturbance_time
    return float(diagram.blocks[DISTURBANCE_BLOCK].params["time"])


@checked_by(_check_contact)
def separation_time(results, diagram) -> float | None:
    """When the forefinger lets go after the middle finger's first contact (None: never)."""
    return regrasp_events(results)["fore_separation_time_s"]


separation_time.unit = "s"


@checked_by(_check_contact)
def object_dropped(results, diagram) -> float:
    """1 if the object was dropped, else 0."""
    return float(dropped(results))


object_dropped.unit = "1"


@checked_by(_check_ratio("peak_ratio"))
def peak_ratio(results, diagram, disturbance_time: float | None = None) -> float:
    """The largest |f_t|/f_n of the thumb and forefinger after the disturbance."""
    return grasp_summary(results, _disturbance(diagram, disturbance_time))["peak_ratio"]


peak_ratio.unit = "1"


@checked_by(_check_ratio("recovery_time"))
def recovery_time(results, diagram, disturbance_time: float | None = None) -> float | None:
    """Seconds from the disturbance until |f_t|/f_n is back under the safety ratio for good
    (None: it never is)."""
    return grasp_summary(results, _disturbance(diagram, disturbance_time))["recovery_time_s"]


recovery_time.unit = "s"
