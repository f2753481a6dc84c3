"""A command started with SIGINT and SIGTERM blocked, as a parent that blocks them starts
it (a blocked mask is inherited across exec), and if asked with one of them already pending.

``blocked(argv)`` is a command line that blocks both signals, sends itself ``pending`` (it
stays pending, as blocked signals do across exec) and then execs ``argv``: blocked and
pending when the program's first code runs, so a test of that moment needs no timing.
"""

from __future__ import annotations

import signal
import sys

STOPS = (signal.SIGINT, signal.SIGTERM)

_EXEC = ("import os, signal, sys; signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM}); "
         "[os.kill(os.getpid(), getattr(signal, name)) for name in sys.argv[1].split(',') if name]; "
         "os.execv(sys.argv[2], sys.argv[2:])")


def blocked(argv: list[str], pending: str = "") -> list[str]:
    """``argv`` run with SIGINT and SIGTERM blocked and the signals named in ``pending``
    (``"SIGINT"``, ``"SIGINT,SIGTERM"``) already sent; ``argv[0]`` is a path."""
    return [sys.executable, "-c", _EXEC, pending, *argv]


def blocked_stops(status_line: str) -> list[str]:
    """The names of SIGINT and SIGTERM if a ``SigBlk:`` line of /proc/PID/status blocks them."""
    mask = int(status_line.split(":", 1)[1], 16)
    return [signum.name for signum in STOPS if mask & (1 << (signum - 1))]
