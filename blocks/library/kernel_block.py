"""KernelBlock: a library block whose step is defined once, by its C kernel.

Every block of the library has its equations in C (``blocks/csrc/library.c``,
``lib_*.c``), and its Python methods call those same functions through
``blocks._native.call``: one definition of each block, the same bits whether the executor
runs a hit in C or in Python. A block says which kernel it is
(``kernel_name``: ``pid`` names ``pid_output``, ``pid_update`` and, for ``Advancing``
blocks, ``pid_advance``) and what its context holds after the common header
[output width, period] (``context_numbers``); its ``initial_state`` is the flat array
the kernel's state layout describes; ``tunables`` names the context's slots an exported
FMU's importer may set. Failure codes become messages in ``failure_text``. Without the
compiled extension such a block loads and validates, but cannot run.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Any, ClassVar, Iterable, Mapping

import numpy as np

from blocks.engine import compiled
from blocks.block import Block, BlockError, EndRun, Signal
from blocks.engine.kernel import END_RUN, Kernel, Tunable
from blocks.library import _kernels

NOMEM, SINGULAR, OUT_OF_RANGE = 1, 2, 3
"""lib_common.h's failure codes."""

HEADER = 2
"""lib_common.h's LIB_H: the numbers of a context before the block's own [W, T]."""

RESETS = ("none", "rising", "falling", "either", "level")
"""Reset kinds of an optional reset input (lib_common.h's lib_reset): a rising edge (from
negative to zero or positive, or from zero to positive), a falling one, either, or while
the input is non-zero."""


class KernelBlock(Block):
    """A block whose output (and update, advance) are C functions of the library."""

    kernel_name: ClassVar[str]
    period_reason: ClassVar[str | None] = None
    """Why the block needs a period of its own (its equations use it); None: it may inherit."""

    def bind(self, period: Fraction | None) -> None:
        if period is None and self.period_reason is not None:
            raise ValueError(f"{type(self).__name__} needs a period: {self.period_reason}")
        super().bind(period)

    def context_numbers(self) -> Iterable[Any]:
        """The block's numbers after the header, in the kernel's order (scalars, arrays)."""
        return ()

    def tunables(self) -> tuple[Tunable, ...]:
        """The context's slots (counted from its start, header included) that an exported
        FMU's importer may set; none by default."""
        return ()

    def not_ready(self) -> str:
        """Why the block has no kernel yet, when it has the extension and its period."""
        return "the port widths are not known yet"

    def failure_text(self, code: int, which: int) -> str:
        """What a failure code of the kernel means, in a few words."""
        return f"failed with code {code} (detail {which})"

    def end_reason(self, which: int) -> str:
        """The reason of a run ended by the kernel's update (``BLK_END_RUN``)."""
        return "ended the run"

    # -- the compiled kernel ----------------------------------------------------------

    def kernel(self) -> Kernel | None:
        """The C functions and this block's context; None until the widths are known (or
        without the compiled extension)."""
        key = self.cache_key()
        if key is not None:
            widths = (tuple(self.inputs.values()), tuple(self.outputs.values()))
            return _kernels.cached(self, (key, self.period, widths), lambda: self._build(self._context()))
        context = self._context()
        if context is None:
            return None
        return _kernels.cached(self, (context.tobytes(),), lambda: self._build(context))

    def cache_key(self) -> Any:
        """A cheap stand-in for the context's numbers, for blocks whose context is large
        (it must change whenever they would); None, the default: the numbers themselves."""
        return None

    def _context(self) -> np.ndarray | None:
        if any(w is None for w in (*self.inputs.values(), *self.outputs.values())):
            return None
        if self.period is None and self.period_reason is not None:
            return None
        header = (float(sum(self.outputs.values())), float(self.period) if self.period is not None else 0.0)
        parts = [np.asarray(part, dtype=np.float64).ravel() for part in (header, *self.context_numbers())]
        return np.ascontiguousarray(np.concatenate(parts))

    def _build(self, context: np.ndarray | None) -> Kernel | None:
        if context is None:
            return None
        name = self.kernel_name
        stateful = self.initial_state() is not None
        advance = f"{name}_advance" if isinstance(self, Advancing) else None
        return _kernels.make_kernel(context, f"{name}_output", f"{name}_update" if stateful else None, advance,
                                    failures=self.kernel_error, tunables=self.tunables())

    def kernel_error(self, code: int, which: int, t: float, phase: str) -> BaseException:
        """``Kernel.error``: the exception of a failure code (an ``EndRun`` for END_RUN)."""
        if code == END_RUN:
            return EndRun(self.end_reason(which))
        if code == NOMEM:
            return _kernels.error(code, which, t, phase)
        return BlockError(f"{phase} at t={t:.10g} s: {self.failure_text(code, which)}")

    # -- the Python methods: the same C functions -------------------------------------

    def output(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> dict[str, Signal]:
        kernel = self._kernel_for_python()
        out = np.empty(sum(self.outputs.values()))
        code, which = _native().call("output", kernel.output, kernel.context, float(t), state,
                                     self._input_list(inputs), out)
        if code:
            raise kernel.error(code, which, float(t), "output")
        return self._split(out[None, :], row=True)

    def update(self, t: float, state: Any, inputs: Mapping[str, Signal]) -> Any:
        kernel = self._kernel_for_python()
        code, which = _native().call("update", kernel.update, kernel.context, float(t), state,
                                     self._input_list(inputs), None)
        if code == END_RUN:
            raise EndRun(self.end_reason(which), state=state)
        if code:
            raise kernel.error(code, which, float(t), "update")
        return state

    def _kernel_for_python(self) -> Kernel:
        if not _kernels.functions() or _native() is None:
            raise BlockError(f"{type(self).__name__} runs its compiled kernel, and the extension "
                             "blocks._native is missing (pip install -e . builds it)")
        kernel = self.kernel()
        if kernel is None:
            if self.period is None and self.period_reason is not None:
                raise BlockError(f"{type(self).__name__} needs a period: {self.period_reason}")
            raise BlockError(f"{type(self).__name__}: {self.not_ready()}")
        return kernel

    def _input_list(self, inputs: Mapping[str, Signal]) -> list[np.ndarray]:
        """The inputs as the kernel reads them, checked against the declared widths (the C
        side trusts them)."""
        values = []
        for port, width in self.inputs.items():
            value = np.ascontiguousarray(inputs[port], dtype=np.float64)
            if value.shape != (width,):
                raise BlockError(f"input '{port}' has shape {value.shape}, the port has width {width}", port=port)
            values.append(value)
        return values

    def _split(self, rows: np.ndarray, row: bool = False) -> dict[str, np.ndarray]:
        """Output ports of rows of all outputs side by side (``row``: one hit, 1-D values)."""
        split, start = {}, 0
        for port, width in self.outputs.items():
            part = rows[:, start:start + width]
            split[port] = part[0].copy() if row else part
            start += width
        return split


class Advancing(KernelBlock):
    """A KernelBlock whose kernel also advances n hits with its inputs held, in one call."""

    def advance(self, t: float, state: Any, inputs: Mapping[str, Signal], n: int):
        kernel = self._kernel_for_python()
        rows = np.empty((max(n, 0), sum(self.outputs.values())))
        code, done, which = _native().call("advance", kernel.advance, kernel.context, float(t), state,
                                           self._input_list(inputs), rows, max(n, 0))
        if code:
            failure = kernel.error(code, which, float(t), "advance")
            if isinstance(failure, BlockError):
                failure.rows = self._split(rows[:done])
            raise failure
        return state, self._split(rows)


def _native():
    return compiled.native()
