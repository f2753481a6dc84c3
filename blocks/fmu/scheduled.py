"""Scheduled-execution FMUs (FMI 3.0) as blocks: their input clocks activated on the tick grid.

A scheduled-execution FMU has one model partition per input clock, which the importer
activates (``fmi3ActivateModelPartition``). The FMU block runs one at the ticks of its
clocks: at a hit it sets the inputs, activates the partitions of the clocks that tick
there in priority order (the smallest ``priority`` value first, as the standard orders
clocks of one instant) and reads the outputs. Its outputs at a hit thus read its inputs
there, as far as the ModelStructure says (the block's feedthrough), and hold between hits.
The block's period is the grid of the clocks' ticks (the greatest common divisor of their
intervals and shifts, exact where the FMU gives ``intervalCounter / resolution``); a
period given must divide every interval and shift.

Supported: periodic input clocks whose interval the modelDescription gives (``constant``,
and ``fixed`` or ``tunable`` ones with an interval, run at it). Not supported, and refused
with a line that says so: triggered and countdown input clocks (activated by a signal or
at the FMU's request), changing clocks, output clocks (the FMU's ``clockUpdate``
callback), and running the FMU in a process of its own (``isolation: process``).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from xml.etree import ElementTree as ET

from blocks.timebase import fraction_gcd
from .instance import FMI3Instance

PERIODIC = ("constant", "fixed", "tunable")
"""The interval variabilities of the periodic clocks the block runs (at their declared interval)."""


@dataclass(frozen=True)
class InputClock:
    """An input clock: its name, value reference, priority, and interval and shift in seconds."""

    name: str
    vr: int
    priority: int
    interval: Fraction
    shift: Fraction

    def ticks_at(self, t: Fraction) -> bool:
        return t >= self.shift and (t - self.shift) % self.interval == 0


def _time(element: ET.Element, counter: str, decimal: str) -> Fraction | None:
    """A time attribute of a clock: ``counter / resolution`` where given, else the decimal's
    text read exactly; None where neither is."""
    if element.get(counter) is not None and element.get("resolution") is not None:
        return Fraction(int(element.get(counter)), int(element.get("resolution")))
    text = element.get(decimal)
    return Fraction(text) if text is not None else None


def input_clocks(xml: bytes, shown: str) -> tuple[InputClock, ...]:
    """The input clocks of a scheduled-execution FMU's modelDescription, in priority order;
    ValueError naming a clock the block cannot run."""
    found = []
    for element in ET.fromstring(xml).iter("Clock"):
        name, causality = element.get("name"), element.get("causality", "local")
        kind = element.get("intervalVariability")
        if causality == "output":
            raise ValueError(f"{shown} has the output clock '{name}': the FMU block does not run output clocks "
                             "(scheduled execution with periodic input clocks only)")
        if causality != "input":
            continue
        interval = _time(element, "intervalCounter", "intervalDecimal")
        if kind not in PERIODIC or interval is None or interval <= 0:
            raise ValueError(f"{shown}: the input clock '{name}' is {kind} without an interval the "
                             "modelDescription gives; the FMU block activates periodic clocks only (not "
                             "triggered, countdown or changing ones)")
        shift = _time(element, "shiftCounter", "shiftDecimal") or Fraction(0)
        found.append(InputClock(name, int(element.get("valueReference")), int(element.get("priority", 0)),
                                interval, shift))
    if not found:
        raise ValueError(f"{shown} provides scheduled execution without input clocks: nothing activates it")
    return tuple(sorted(found, key=lambda c: c.priority))


def clock_grid(clocks: tuple[InputClock, ...]) -> Fraction:
    """The grid of the clocks' ticks: the gcd of their intervals and shifts."""
    return fraction_gcd([c.interval for c in clocks] + [c.shift for c in clocks if c.shift])


def check_period(clocks: tuple[InputClock, ...], period: Fraction, shown: str) -> None:
    """ValueError unless every tick of every clock is a hit of a block of ``period``."""
    for c in clocks:
        if (c.interval / period).denominator != 1 or (c.shift / period).denominator != 1:
            raise ValueError(f"the period {float(period):g} s does not divide the interval {float(c.interval):g} s "
                             f"(shift {float(c.shift):g} s) of clock '{c.name}' of {shown}; use a period of "
                             f"{float(clock_grid(clocks)):g} s or a divisor of it")


class ScheduledExecution3(FMI3Instance):
    """An FMI 3.0 scheduled-execution instance: partitions activated instead of steps."""

    fmpy_class = "FMU3ScheduledExecution"

    def activate(self, clocks: list[InputClock], t: float) -> None:
        """Activate the partitions of ``clocks`` (in their order) at ``t``; fmpy raises
        FMICallException for a status that is an error."""
        for c in clocks:
            self.slave.activateModelPartition(c.vr, t)
