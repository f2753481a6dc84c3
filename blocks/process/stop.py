"""SIGINT and SIGTERM as requests to stop, from a program's first instruction to its exit.

The first signal raises ``StopRequest`` wherever the program is: during its imports, while
a diagram loads, inside a simulation (where the executor stops and returns what it
computed, marked interrupted), while plots are drawn. Every later signal, and any signal
while ``held()`` (results being written), is only noted on stderr, so a second Ctrl-C just
after the first, or a SIGTERM while the files are written, cannot lose them; the first
signal decides the exit code (130 for SIGINT, 143 for SIGTERM, 128 + its number as a shell
reports it). SIGTERM is treated as Ctrl-C is, because it is how batch systems, containers
and ``timeout`` stop a program: its partial results are kept the same way.

``launch`` installs the handlers before a command line imports its modules (this module
needs only the standard library, and ``blocks`` imports its parts lazily), so a signal
at start-up is one line and the exit code too, not a traceback. It also unblocks both
signals once its handlers are in place: a program whose parent started it with them
blocked (a blocked mask is inherited across exec) can still be stopped, one that came
while they were blocked is then the same one line, and whatever the program forks or
spawns afterwards starts with them unblocked. Unblocking them is harmless where nothing
blocked them.
"""

from __future__ import annotations

import os
import signal
import sys
from collections.abc import Callable

EXIT_CODES = {"SIGINT": 130, "SIGTERM": 143}
"""128 + the signal's number, as a shell reports a program that a signal ended."""

STOPS = {signal.SIGINT, signal.SIGTERM}
"""The signals that are requests to stop."""


class StopRequest(KeyboardInterrupt):
    """A request to stop a run early, like Ctrl-C, with a ``reason`` for the status
    (a program that turns SIGTERM into a stop raises ``StopRequest("SIGTERM")``)."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


class StopSignals:
    """A context that turns SIGINT and SIGTERM into stop requests (in the main thread only,
    where Python delivers signals). ``received`` names the first signal that came, in this
    context or before it (since ``launch``); notes on stderr begin with ``program``."""

    first: str | None = None
    """The first signal this process received while a StopSignals was installed."""

    def __init__(self, program: str):
        self.program = program
        self._holding = 0
        self._previous: dict[int, object] = {}

    @property
    def received(self) -> str | None:
        return StopSignals.first

    def __enter__(self) -> "StopSignals":
        for signum in (signal.SIGINT, signal.SIGTERM):
            try:
                self._previous[signum] = signal.signal(signum, self._handle)
            except ValueError:  # not the main thread, where Python delivers signals
                break
        return self

    def __exit__(self, *exc_info) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)
        self._previous.clear()

    def held(self) -> "_Held":
        """Within this block signals are noted, not raised: what it writes is written whole."""
        return _Held(self)

    def _handle(self, signum: int, frame) -> None:
        name = signal.Signals(signum).name
        if StopSignals.first is None and not self._holding:
            StopSignals.first = name
            raise StopRequest(name)
        StopSignals.first = StopSignals.first or name
        doing = "while the results are saved: stopping once they are" if self._holding else "(already stopping)"
        os.write(2, f"{self.program}: {name} {doing}\n".encode())


class _Held:
    """``StopSignals.held()``: a context (a class, not contextlib's decorator, which this
    module's start-up would pay to import)."""

    def __init__(self, stops: StopSignals):
        self.stops = stops

    def __enter__(self) -> None:
        self.stops._holding += 1

    def __exit__(self, *exc_info) -> None:
        self.stops._holding -= 1


def exit_code(stop: KeyboardInterrupt | str | None) -> int:
    """The exit code for a stop: that of the first signal received, else of the stop given
    (an interrupt or a signal's name): 143 for SIGTERM, else 130."""
    name = StopSignals.first or (stop.reason if isinstance(stop, StopRequest) else stop)
    return EXIT_CODES["SIGTERM"] if name == "SIGTERM" else EXIT_CODES["SIGINT"]


def launch(program: str, command: Callable[[], Callable[[], object]]) -> None:
    """Run a command line: ``command()`` imports it and returns its entry function, which
    is then called. SIGINT and SIGTERM are stop requests from before the import to the
    exit; one that stops the program outside a command's own handling (during the
    imports, say) ends it with one line and its exit code. Both are unblocked once their
    handlers are installed: one that came while they were blocked (by the program's
    parent) is handled then."""
    with StopSignals(program):
        try:
            signal.pthread_sigmask(signal.SIG_UNBLOCK, STOPS)
            entry = command()
            entry()
        except KeyboardInterrupt as stop:
            print(f"{program}: interrupted", file=sys.stderr)
            sys.exit(exit_code(stop))
