"""SIGINT and SIGTERM as requests to stop a run, which never cut the saving of its results short.

The first signal raises ``StopRequest`` wherever the program is: inside a simulation the
executor stops and returns what it computed, marked interrupted. Every later signal, and
any signal while ``held()`` (the results being written), is only noted on stderr, so a
second Ctrl-C just after the first, or a SIGTERM while the files are written, cannot lose
them. SIGTERM is treated as Ctrl-C is, because it is how batch systems, containers and
``timeout`` stop a program: the partial results are kept the same way.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from typing import Iterator

from blocks import StopRequest

EXIT_CODES = {"SIGINT": 130, "SIGTERM": 143}
"""128 + the signal's number, as a shell reports a program that a signal ended."""


class StopSignals:
    """A context that turns SIGINT and SIGTERM into stop requests (in the main thread only,
    where Python delivers signals); ``received`` names the first signal that came. Notes on
    stderr begin with ``program``, the command's name."""

    def __init__(self, program: str):
        self.program = program
        self.received: str | None = None
        self._holding = False
        self._previous: dict[int, object] = {}

    def __enter__(self) -> "StopSignals":
        if threading.current_thread() is threading.main_thread():
            for signum in (signal.SIGINT, signal.SIGTERM):
                self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc_info) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)
        self._previous.clear()

    @contextlib.contextmanager
    def held(self) -> Iterator[None]:
        """Within this block signals are noted, not raised: what it writes is written whole."""
        self._holding = True
        try:
            yield
        finally:
            self._holding = False

    def _handle(self, signum: int, frame) -> None:
        name = signal.Signals(signum).name
        if self.received is None and not self._holding:
            self.received = name
            raise StopRequest(name)
        self.received = self.received or name
        os.write(2, f"{self.program}: {name} while the results are saved: stopping once they are\n".encode())


def exit_code(stop: KeyboardInterrupt | str | None) -> int:
    """The exit code for a stop (an interrupt or a signal's name): 143 for SIGTERM, else 130."""
    name = stop.reason if isinstance(stop, StopRequest) else stop
    return EXIT_CODES["SIGTERM"] if name == "SIGTERM" else EXIT_CODES["SIGINT"]
