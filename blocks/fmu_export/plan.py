"""What an exported FMU runs: the diagram's op table for stepping, and its blocks' records.

The table is the diagram's own plan (the same events, order and advances as a native run,
so the FMU computes the same samples), compiled without logs and with the programs a
communication point needs: every event's outputs alone, the outputs at t = 0 before the
first step, the outputs between events, and those of lazy blocks the FMU's outputs read.
Its length is open (the importer's stop time ends it). Communication points fall on a
grid: the base tick, or the period of the blocks the table advances in one call (their
advances stop and go on at every communication point, which must be one of their hits).
Where no event cuts the advances (a diagram of advanced blocks alone, such as the plant
export), each communication step advances them in one kernel call: their rows hold the
hits of the default communication step, and of at least ``MIN_SPAN_GRIDS`` grid steps
(an importer stepping longer takes a call per that many).

Every block must run through a compiled kernel that has a record (``Kernel.record``): a
block in Python, or one whose kernel cannot leave Python (an FMU block's), is refused
with one line naming it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from blocks.engine.binding import Binding
from blocks.builder.diagram import Diagram
from ..issues import DiagramError
from blocks.engine.kernel import KernelRecord
from blocks.engine.optable import MAX_TICKS, OpTable, stepping_table
from blocks.engine.schedule import (
    Schedule,
    between_program,
    build_schedule,
    initial_outputs_program,
    lazy_outputs_program,
)
from ..timebase import DurationError, positive_duration

OPEN_END = MAX_TICKS // 2
"""The table's length in base ticks: no end but the importer's stop time."""

MIN_SPAN_GRIDS = 64
"""Without events, the advanced blocks' rows hold at least this many grid steps' hits."""


@dataclass(frozen=True)
class ExportBlock:
    """A block as the FMU rebuilds it: its record, and the state Python gives it (an empty
    array for none); ``built_state``: the kind builds the state from the record
    (``KernelRecord.builds_state``)."""

    name: str
    type_name: str
    record: KernelRecord
    state: np.ndarray
    built_state: bool


@dataclass(frozen=True)
class Plan:
    diagram: Diagram
    schedule: Schedule
    table: OpTable
    blocks: tuple[ExportBlock, ...]
    grid: int
    """Communication steps are whole numbers of this many base ticks."""
    step: Fraction
    """The default communication step, in seconds."""
    initial_outputs: int
    between: int
    lazy: int
    """Programs of the table (-1: none needed)."""


def plan_export(diagram: Diagram, output_blocks: set[str], step=None, advance: bool = True) -> Plan:
    """The plan of ``diagram`` as an FMU whose outputs read ``output_blocks``, with the
    default communication step ``step`` (a duration; default: the grid); DiagramError
    naming every block that cannot leave Python, or for a step off the grid.
    ``advance=False``: no block advanced over spans (scheduled execution's partitions)."""
    schedule = build_schedule(diagram, diagram_length(diagram), advance=advance)
    grid = math.lcm(1, *(schedule.period_ticks[n] for n in schedule.advanced))
    grid_step = grid * schedule.base_tick
    default_step = grid_step if step is None else _step(diagram, step, grid_step)
    span = max(int(default_step / schedule.base_tick), MIN_SPAN_GRIDS * grid)
    initial = initial_outputs_program(diagram, schedule)
    between = between_program(diagram, schedule)
    lazy = lazy_outputs_program(diagram, schedule, output_blocks)
    extra = (initial, between, lazy)
    table, (i_initial, i_between, i_lazy) = stepping_table(diagram, schedule, extra, OPEN_END, span)
    blocks = exported_blocks(diagram, table)
    return Plan(diagram, schedule, table, blocks, grid, default_step, i_initial,
                i_between if between.evaluate else -1, i_lazy if lazy.evaluate else -1)


def _step(diagram: Diagram, step, grid: Fraction) -> Fraction:
    """``step`` (a duration) as seconds; DiagramError unless a positive multiple of ``grid``."""
    try:
        value = positive_duration(step, "step")
    except DurationError as exc:
        raise DiagramError([diagram.issue(None, str(exc))]) from None
    if (value / grid).denominator != 1:
        raise DiagramError([diagram.issue(None, f"the step {step} is not a multiple of the FMU's "
                                          f"internal step {float(grid):g} s", f"use a multiple of {float(grid):g} s")])
    return value


def diagram_length(diagram: Diagram):
    """One hyperperiod: a length the plan's advances divide (the FMU's table is open-ended)."""
    probe = build_schedule(diagram, None)
    return probe.hyperperiod * probe.base_tick


def exported_blocks(diagram: Diagram, table: OpTable) -> tuple[ExportBlock, ...]:
    """Every block's record and initial state, as a run binds them; DiagramError for the
    blocks that would run in Python."""
    binding = Binding(diagram, table)
    issues, out = [], []
    if binding.failure is not None:
        name, exc = binding.failure
        spec = diagram.blocks[name]
        raise DiagramError([diagram.issue_at(spec, f"block '{name}' ({spec.type_name}): its kernel failed: {exc}")])
    for b, name in enumerate(table.names.blocks):
        spec = diagram.blocks[name]
        kernel = binding.kernels[b]
        record = None if kernel is None else kernel.record
        if record is None:
            why = _why_not(spec.block, kernel)
            issues.append(diagram.issue_at(spec, f"block '{name}' ({spec.type_name}) cannot be exported: {why}",
                                           "an exported FMU runs compiled blocks only (library and application "
                                           "blocks with a C kernel)"))
            continue
        state = binding.states[b]
        flat = np.zeros(0) if state is None else np.ascontiguousarray(state, dtype=np.float64).ravel()
        out.append(ExportBlock(name, spec.type_name, record, flat, record.builds_state))
    if issues:
        raise DiagramError(issues)
    return tuple(out)


def _why_not(block: Any, kernel: Any) -> str:
    """Why a block's kernel cannot leave Python."""
    from ..fmu import FMU

    if isinstance(block, FMU):
        return "the FMU an FMU block runs is not carried inside an exported FMU"
    if kernel is not None:
        return "its kernel calls back into Python"
    try:
        made = block.kernel()
    except Exception:  # noqa: BLE001 - a kernel that cannot be made is no kernel
        made = None
    return "it has no compiled kernel" if made is None else "its kernel cannot run it in this diagram"
