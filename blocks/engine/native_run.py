"""The C core's Python host: a bound table handed to ``blocks._native.Run``, its outcome read back.

The whole run is one call into C (``blocks/csrc/native_run*.c`` over ``core.c``): compiled
blocks through their kernels, Python blocks as callback ops of the same table (their
methods called by the host, with the rules of ``blocks.engine.python_blocks``), logging in C.
What the core reports by numbers (an op, a code, a tick) becomes here the block, phase
and exception of the run's ``Outcome``.
"""

from __future__ import annotations

from typing import Callable

from blocks.engine.binding import Binding
from blocks.engine.compiled import native
from blocks.engine.finite import NONFINITE
from blocks.engine.kernel import END_RUN, RAISED
from blocks.engine.optable import OP_A, OP_CODE, PHASES
from blocks.engine.outcome import Outcome, stopped
from blocks.engine.python_blocks import PythonSide

COMPLETE, FAILED, STOPPED, BAD = range(4)
"""``blk_outcome.status`` (core.h)."""


def python_spec(side: PythonSide, b: int) -> tuple:
    """What the C host calls block ``b`` with: its methods, input mapping, state index, its
    connected inputs (port, arena offset, width, the array its mapping holds) and its
    outputs (port, offset, width)."""
    binding = side.binding
    block, mapping = binding.blocks[b], binding.inputs[b]
    return (block.output, block.update, mapping, b,
            [(port, offset, width, mapping[port]) for port, offset, width in side.inputs[b]],
            list(side.outputs[b]))


def run_native(binding: Binding, progress: Callable[[int], None] | None) -> Outcome:
    """One run of ``binding`` in the C core; ``progress(tick)`` now and then."""
    table = binding.table
    side = PythonSide(binding)
    python = [python_spec(side, b) if k is None else None for b, k in enumerate(binding.kernels)]
    run = native().Run(table.arrays(), binding.arena, binding.logs, binding.counters, binding.kernel_rows(), python,
                       binding.states, side, progress, allow_nonfinite=not binding.check_finite)
    status, end, reached, code, which, op, tick, error, end_op, end_asked, end_reason, message = run.run()
    names = table.names.blocks
    end_request = None if end_op < 0 else (names[int(table.ops[end_op, OP_A])], end_reason.reason, end_asked)
    if status == COMPLETE:
        return Outcome(end, end, end_request=end_request)
    if status == STOPPED:
        if isinstance(error, KeyboardInterrupt):
            return Outcome(None, reached, interrupt=error, end_request=end_request)
        raise error
    if status == BAD:
        raise RuntimeError(f"the op table could not run: {message}")
    b = int(table.ops[op, OP_A])
    phase = PHASES[int(table.ops[op, OP_CODE])]
    if code == NONFINITE:
        return stopped(names[b], phase, tick, binding.nonfinite_error(b, which), reached, False, end_request)
    if code != RAISED and not (code == END_RUN and error is not None):
        error = binding.kernel_error(b, code, which, tick, phase)
    return stopped(names[b], phase, tick, error, reached, binding.kernels[b] is None, end_request)
