"""Ctrl-C during a call into an FMU stays an interrupt, never an FMU failure.

A SIGINT that arrives while an FMU's C code runs only sets CPython's signal flag; the
KeyboardInterrupt is raised as soon as Python code runs again. If the FMU calls back into
Python before it returns (to log a message), that is inside the callback, where ctypes
cannot pass an exception on: it reports it to ``sys.unraisablehook`` and returns to the
FMU, and the interrupt is lost. The run then goes on, or, if the callback was to hand the
FMU something (memory), the FMU fails with status 'error' or 'fatal' and Ctrl-C looks
like a broken FMU. So the FMU block:

- hands FMUs the C library's calloc and free directly, with no Python in between;
- wraps its Python callbacks with ``callback``: a KeyboardInterrupt raised in one is noted
  instead of lost. One raised at a callback's very first instruction, before any handler
  of its own, reaches ``sys.unraisablehook``; ``arm()`` installs a hook that notes it too
  (and passes everything else to the hook it replaced);
- calls ``check()`` after every call into an FMU, and before it turns an error status
  into a failure: a noted interrupt is raised there as the KeyboardInterrupt it was, so
  the executor stops the run as interrupted and keeps the results so far.

The FMU's compiled kernel (``blocks.fmu.compiled_step``) does the same from C: before a step it
arms again when ``sys.unraisablehook`` is not ``hook``, after each doStep it calls
``check``, and a KeyboardInterrupt raised there ends the run as interrupted.
"""

from __future__ import annotations

import _thread
import functools
import sys
from typing import Any, Callable

_noted: KeyboardInterrupt | None = None
"""The interrupt noted since the last check (kept whole: a StopRequest names its signal)."""
_previous: Callable[[Any], None] | None = None


def hook(unraisable: Any) -> None:
    """``sys.unraisablehook``: note a KeyboardInterrupt lost in one of our callbacks."""
    if issubclass(unraisable.exc_type, KeyboardInterrupt) and getattr(unraisable.object, "fmu_callback", False):
        note(unraisable.exc_value)
        return
    (_previous or sys.__unraisablehook__)(unraisable)


def arm() -> None:
    """Install the hook, again if other code has replaced it since (cheap: call before
    every call into an FMU)."""
    global _previous
    if sys.unraisablehook is not hook:
        _previous = sys.unraisablehook
        sys.unraisablehook = hook


def callback(function: Callable[..., None]) -> Callable[..., None]:
    """``function`` (a callback that returns nothing) made to note a KeyboardInterrupt
    raised in it rather than lose it."""
    @functools.wraps(function)
    def guarded(*args: Any) -> None:
        try:
            function(*args)
        except KeyboardInterrupt as interrupt:
            note(interrupt)

    guarded.fmu_callback = True  # type: ignore[attr-defined]
    return guarded


def note(interrupt: KeyboardInterrupt | None = None) -> None:
    """Remember an interrupt that could not be raised where it happened."""
    global _noted
    _noted = interrupt if interrupt is not None else KeyboardInterrupt()


def check() -> None:
    """Raise the interrupt noted since the last check, if any, as it was raised."""
    global _noted
    if _noted is not None:
        interrupt, _noted = _noted, None
        raise interrupt


def deliver() -> None:
    """Hand a noted interrupt back to Python's own signal handling, where it cannot be
    raised on the spot (freeing an instance from a finalizer)."""
    global _noted
    if _noted is not None:
        _noted = None
        _thread.interrupt_main()
