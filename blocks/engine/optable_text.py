"""An op table as text, with the diagram's block and port names (``validate --plan``).

Every row of every table is shown: the arena's places as ``@offset[width]``, the
programs' ops in order with what they log, the events that run each program, the copies
and the log entries, so that what a run does can be read off before running it.
"""

from __future__ import annotations

from blocks.engine.optable import (
    ADVANCE,
    B_FIRST_INPUT,
    B_FIRST_PORT,
    B_N_INPUTS,
    B_N_PORTS,
    B_PERIOD,
    B_ROWS,
    B_ROWS_CAPACITY,
    B_WIDTH,
    C_DST,
    C_SRC,
    C_WIDTH,
    COPY,
    E_PROGRAM,
    E_TICK,
    H_ARENA,
    H_FINAL,
    H_HYPERPERIOD,
    H_INITIAL,
    H_N_TICKS,
    H_TICK_DEN,
    H_TICK_NUM,
    I_OFFSET,
    I_WIDTH,
    L_BLOCK,
    L_CAPACITY,
    L_COLUMN,
    L_DECIMATE,
    L_WIDTH,
    OP_A,
    OP_B,
    OP_C,
    OP_CODE,
    OP_D,
    OUTPUT,
    P_OFFSET,
    P_WIDTH,
    UPDATE,
    OpTable,
)

MAX_TICKS_SHOWN = 6
"""How many of the ticks a program runs at are listed before '...'."""


def describe_table(table: OpTable) -> str:
    """The whole table, one line per row."""
    h = table.header
    lines = [f"op table: {int(h[H_N_TICKS])} ticks of {int(h[H_TICK_NUM])}/{int(h[H_TICK_DEN])} s, "
             f"hyperperiod {int(h[H_HYPERPERIOD])} ticks; {len(table.blocks)} blocks, {len(table.ops)} ops in "
             f"{len(table.programs)} programs, {len(table.events)} events per hyperperiod, "
             f"arena of {int(h[H_ARENA])} values"]
    lines += ["blocks (outputs, then where each input reads):"] + _blocks(table)
    lines += ["programs:"] + _programs(table)
    if len(table.copies):
        lines += ["copies:"] + [f"  {i}  {what}: @{c[C_DST]}[{c[C_WIDTH]}] <- @{c[C_SRC]}"
                                for i, (what, c) in enumerate(zip(table.names.copies, table.copies.tolist()))]
    if len(table.logs):
        lines += ["logs:"] + [f"  {i}  {signal}: {_every(row[L_DECIMATE])}, columns {row[L_COLUMN]}.."
                              f"{row[L_COLUMN] + row[L_WIDTH] - 1} of {table.names.blocks[row[L_BLOCK]]}, "
                              f"at most {row[L_CAPACITY]} rows"
                              for i, (signal, row) in enumerate(zip(table.names.logs, table.logs.tolist()))]
    return "\n".join(lines)


def _every(decimate: int) -> str:
    return "every hit" if decimate == 1 else f"every {decimate}th hit"


def _blocks(table: OpTable) -> list[str]:
    names = table.names
    width = max((len(n) for n in names.blocks), default=1)
    lines = []
    for b, row in enumerate(table.blocks.tolist()):
        first = row[B_FIRST_INPUT]
        ports = table.ports[row[B_FIRST_PORT]:row[B_FIRST_PORT] + row[B_N_PORTS]].tolist()
        outs = [f"{port}@{r[P_OFFSET]}[{r[P_WIDTH]}]" for port, r in zip(names.ports[b], ports)]
        ins = [f"{port}<-@{r[I_OFFSET]}[{r[I_WIDTH]}]" + ("" if feed == "source" else f" ({feed})")
               for port, feed, r in zip(names.inputs[b], names.feeds[b],
                                         table.inputs[first:first + row[B_N_INPUTS]].tolist())]
        period = f"every {row[B_PERIOD]} ticks" if row[B_PERIOD] else "inherited"
        rows = f", advance rows @{row[B_ROWS]}[{row[B_ROWS_CAPACITY]} x {row[B_WIDTH]}]" if row[B_ROWS_CAPACITY] else ""
        lines.append(f"  {b:<3}{names.blocks[b]:<{width}}  {' '.join(outs) or '-'}  in: {', '.join(ins) or '-'}  "
                     f"{period}{rows}")
    return lines


def _programs(table: OpTable) -> list[str]:
    h = table.header
    hyper = int(h[H_HYPERPERIOD])
    ticks: dict[int, list[int]] = {}
    for tick, program in table.events[:, [E_TICK, E_PROGRAM]].tolist():
        ticks.setdefault(program, []).append(tick)
    lines = []
    for p, (first, end, final) in enumerate(table.programs.tolist()):
        what = table.names.programs[p]
        if p in ticks:
            shown = ", ".join(str(t) for t in ticks[p][:MAX_TICKS_SHOWN]) + (", ..." if len(ticks[p]) > MAX_TICKS_SHOWN
                                                                            else "")
            what = f"at ticks {shown} (mod {hyper})"
        elif p == int(h[H_INITIAL]):
            what = "at t = 0"
        elif p == int(h[H_FINAL]):
            what = f"the end, at tick {int(h[H_N_TICKS])}"
        ending = f"; a run a block ends here ends with program {final}" if final >= 0 else ""
        lines.append(f"  {p}  {what}{ending}:")
        lines += [f"       {_op(table, op)}" for op in table.ops[first:end].tolist()] or ["       (nothing)"]
    return lines


def _op(table: OpTable, op: list[int]) -> str:
    names = table.names
    if op[OP_CODE] == COPY:
        return f"copy {names.copies[op[OP_A]]}"
    block = names.blocks[op[OP_A]]
    if op[OP_CODE] == UPDATE:
        return f"update {block}"
    logged = [names.logs[e] for e in range(op[OP_B], op[OP_C])]
    logs = f", logging {', '.join(logged)}" if logged else ""
    if op[OP_CODE] == OUTPUT:
        ports = "" if op[OP_D] < 0 else f"[{', '.join(names.ports[op[OP_A]][j] for j in table.selection(op[OP_D]))}]"
        return f"output {block}{ports}{logs}"
    assert op[OP_CODE] == ADVANCE
    last = " (the event's last advance)" if op[OP_D] else ""
    return f"advance {block} to the next event{logs}{last}"
