"""The clocks of a scheduled-execution FMU (FMI 3.0) as the FMU block runs them: read from
its modelDescription, the grid of their ticks, and what a run remembers of them.

The block's behaviour with them is in ``scheduled`` (whose docstring says what is
supported); this module imports nothing of the instances, so the model can read them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from xml.etree import ElementTree as ET

from blocks.timebase import fraction_gcd
from .description import step_of
from .ports import port_name

SHORTEST, LONGEST = Fraction(1, 10**12), Fraction(10**9)
"""The range of a clock's interval or shift, as of every duration (``timebase``)."""

PERIODIC = ("constant", "fixed", "tunable")
"""The interval variabilities of the periodic clocks the block runs (at their declared interval)."""


@dataclass(frozen=True)
class Clock:
    """A clock of the FMU: name, port name, value reference, kind (``periodic``,
    ``triggered``, ``countdown``, ``output``), priority; a periodic one's interval and shift."""

    name: str
    port: str
    vr: int
    kind: str
    priority: int = 0
    interval: Fraction | None = None
    shift: Fraction = Fraction(0)

    def ticks_at(self, t: Fraction) -> bool:
        return self.kind == "periodic" and t >= self.shift and (t - self.shift) % self.interval == 0


def _time(element: ET.Element, counter: str, decimal: str, shown: str) -> Fraction | None:
    """A time attribute of a clock: ``counter / resolution`` where given, else the decimal
    (the double it is, exactly); None where neither is. ValueError naming the clock and the
    attribute for a value that is no time in the range of durations (1e-12 s to 1e9 s)."""
    name = element.get("name")
    try:
        if element.get(counter) is not None and element.get("resolution") is not None:
            try:
                value = Fraction(int(element.get(counter)), int(element.get("resolution")))
            except (ValueError, ZeroDivisionError):
                raise ValueError("not a whole counter of a positive resolution") from None
            if value < 0 or (value and not LONGEST >= value >= SHORTEST) or int(element.get("resolution")) < 0:
                raise ValueError("out of range (1e-12 s to 1e9 s)")
            return value
        text = element.get(decimal)
        if text is None:
            return None
        return Fraction(0) if text.strip() in ("0", "0.0") else step_of(text)
    except ValueError as exc:
        raise ValueError(f"{shown}: clock '{name}': its {counter if element.get(counter) else decimal} is "
                         f"{exc}") from None


def fmu_clocks(xml: bytes, shown: str) -> tuple[Clock, ...]:
    """The clocks of a scheduled-execution FMU's modelDescription, the input clocks in
    priority order, then the output clocks; ValueError naming one the block cannot run."""
    inputs, outputs = [], []
    for element in ET.fromstring(xml).iter("Clock"):
        name, causality = element.get("name"), element.get("causality", "local")
        kind, vr = element.get("intervalVariability"), int(element.get("valueReference"))
        if causality == "output":
            outputs.append(Clock(name, port_name(name), vr, "output"))
            continue
        if causality != "input":
            continue
        priority = int(element.get("priority", 0))
        if kind in ("triggered", "countdown"):
            inputs.append(Clock(name, port_name(name), vr, kind, priority))
            continue
        interval = _time(element, "intervalCounter", "intervalDecimal", shown)
        if kind not in PERIODIC or interval is None or interval <= 0:
            raise ValueError(f"{shown}: the input clock '{name}' is {kind} without an interval the "
                             "modelDescription gives; the FMU block activates periodic, triggered and countdown "
                             "clocks")
        shift = _time(element, "shiftCounter", "shiftDecimal", shown) or Fraction(0)
        inputs.append(Clock(name, port_name(name), vr, "periodic", priority, interval, shift))
    if not inputs:
        raise ValueError(f"{shown} provides scheduled execution without input clocks: nothing activates it")
    return tuple(sorted(inputs, key=lambda c: c.priority)) + tuple(outputs)


def clock_grid(clocks: tuple[Clock, ...]) -> Fraction | None:
    """The grid of the periodic clocks' ticks (the gcd of their intervals and shifts); None without any."""
    periodic = [c for c in clocks if c.kind == "periodic"]
    return fraction_gcd([c.interval for c in periodic] + [c.shift for c in periodic if c.shift]) if periodic else None


def check_period(clocks: tuple[Clock, ...], period: Fraction, shown: str) -> None:
    """ValueError unless every tick of every periodic clock is a hit of a block of ``period``."""
    for c in clocks:
        if c.kind == "periodic" and ((c.interval / period).denominator != 1 or (c.shift / period).denominator != 1):
            raise ValueError(f"the period {float(period):g} s does not divide the interval {float(c.interval):g} s "
                             f"(shift {float(c.shift):g} s) of clock '{c.name}' of {shown}; use a period of "
                             f"{float(clock_grid(clocks)):g} s or a divisor of it")


@dataclass
class ClockRun:
    """What a run of a scheduled-execution FMU block remembers between hits."""

    activated: float | None = None
    """The hit whose clocks were activated last."""
    previous: dict[str, float] = field(default_factory=dict)
    """Per triggered clock's port, its value at the hit before."""
    due: dict[int, Fraction] = field(default_factory=dict)
    """Per countdown clock (value reference), when the FMU asked to activate it."""
