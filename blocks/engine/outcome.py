"""How one run of an op table went, as both interpreters report it."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Failure:
    """A block's op failed: its block, phase ('output', 'update', 'advance' or, before the
    run, 'kernel'), the tick of the hit that failed and the exception."""

    block: str
    phase: str
    tick: int
    error: BaseException


@dataclass(frozen=True)
class Outcome:
    """``end``: the tick a complete run ended at (None if it did not complete); ``reached``:
    every block was computed up to this tick (an interrupted run's time); ``failure`` or
    ``interrupt`` when it stopped early; ``end_request``: the first block that asked to
    end the run, as (block, reason, tick of its update)."""

    end: int | None
    reached: int
    failure: Failure | None = None
    interrupt: KeyboardInterrupt | None = None
    end_request: tuple[str, str, int] | None = None


def stopped(block: str, phase: str, tick: int, error: BaseException, reached: int, python: bool,
            end_request: tuple[str, str, int] | None) -> Outcome:
    """The outcome of an op that raised: an interrupt (Ctrl-C, ``StopRequest``) stops the
    run where every block got to; any other exception fails the block. What a Python
    block raises that is not an ``Exception`` (``SystemExit``) is not the run's to handle
    and goes on up, as from any Python call."""
    if isinstance(error, KeyboardInterrupt):
        return Outcome(None, reached, interrupt=error, end_request=end_request)
    if python and not isinstance(error, Exception):
        raise error
    return Outcome(None, reached, Failure(block, phase, tick, error), end_request=end_request)
