"""Rates as colours: each block's effective period and the Simulink-like colour of each distinct one."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from blocks.builder.diagram import Diagram
from blocks.engine.schedule import Schedule
from ..timebase import format_duration


PALETTE = ("#d62728", "#2ca02c", "#1f77b4", "#17becf", "#8c564b", "#ff7f0e", "#9467bd",
           "#7f7f7f", "#1a55a0", "#a0522d")
"""Colours of the periodic rates, fastest first (Simulink: red, green, blue, ...)."""
CONSTANT_COLOR = "#c2189b"
"""Blocks that fire at t = 0 only (Simulink: magenta for constant)."""
MIXED_COLOR = "#b8a000"
"""Inherited blocks whose hits follow no single period (Simulink: yellow for hybrid)."""


@dataclass(frozen=True)
class Rate:
    """A block's effective rate: ``period`` and ``offset`` in base ticks (None: none)."""

    kind: str  # "periodic", "constant" or "mixed"
    period: int | None = None
    offset: int = 0

    def sort_key(self) -> tuple:
        return ({"periodic": 0, "mixed": 1, "constant": 2}[self.kind], self.period or 0, self.offset)

    def text(self, schedule: Schedule) -> str:
        if self.kind == "constant":
            return "constant (t = 0 only)"
        if self.kind == "mixed":
            return "inherited, mixed rates"
        text = format_duration(self.period * schedule.base_tick)
        if self.offset:
            text += f" + {format_duration(self.offset * schedule.base_tick)}"
        return text


def effective_rate(schedule: Schedule, block: str) -> Rate:
    """The rate ``block`` runs at: its own period, or for an inherited block the period
    its hits follow in the schedule (constant when it fires at t = 0 only)."""
    p = schedule.period_ticks[block]
    if p is not None:
        return Rate("periodic", p, schedule.offset_ticks[block])
    hits = np.flatnonzero(schedule.masks[block])
    if hits.size == 0:
        return Rate("constant")
    steps = np.diff(np.append(hits, hits[0] + schedule.hyperperiod))
    if np.all(steps == steps[0]):
        return Rate("periodic", int(steps[0]), int(hits[0]))
    return Rate("mixed")


@dataclass
class RateColors:
    """Each block's rate and colour, and the legend: one entry per distinct rate."""

    rates: dict[str, Rate]
    colors: dict[str, str]
    legend: list[tuple[str, str]]
    """(label, colour) per distinct rate, fastest first."""


def rate_colors(diagram: Diagram, schedule: Schedule) -> RateColors:
    rates = {name: effective_rate(schedule, name) for name in diagram.blocks}
    distinct = sorted(set(rates.values()), key=Rate.sort_key)
    colour_of: dict[Rate, str] = {}
    legend = []
    periodic = 0
    for rate in distinct:
        if rate.kind == "constant":
            colour = CONSTANT_COLOR
        elif rate.kind == "mixed":
            colour = MIXED_COLOR
        else:
            colour = PALETTE[periodic % len(PALETTE)]
            periodic += 1
        colour_of[rate] = colour
        label = rate.text(schedule)
        own = [n for n, r in rates.items() if r == rate and schedule.period_ticks[n] is not None]
        if rate.kind == "periodic" and not own:
            label = f"inherited ({label})"
        legend.append((label, colour))
    return RateColors(rates, {n: colour_of[r] for n, r in rates.items()}, legend)


def rate_line(schedule: Schedule, rates: RateColors, name: str) -> str:
    """The rate as a block shows it: its own, or ``inherited -> 1 ms``."""
    if schedule.period_ticks[name] is not None:
        return schedule.rate_text(name)
    rate = rates.rates[name]
    if rate.kind == "periodic":
        return "inherited \u2192 " + rate.text(schedule) + (", lazy" if name in schedule.lazy else "")
    return schedule.rate_text(name)


def tint(colour: str, amount: float = 0.14) -> str:
    """``colour`` mixed into white: ``amount`` of it."""
    r, g, b = (int(colour[i:i + 2], 16) for i in (1, 3, 5))
    mix = [round(255 - amount * (255 - v)) for v in (r, g, b)]
    return "#" + "".join(f"{v:02x}" for v in mix)
