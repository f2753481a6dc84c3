"""What a forked process does first: ask to die with the process that forked it, and
write through standard streams of its own.

A helper (an FMU host, a plot drawer) must not outlive the process it serves, even when
that one is killed by SIGKILL and cannot clean up: on Linux the kernel sends the helper
SIGKILL when its parent exits (PR_SET_PDEATHSIG).

A process forked while another thread of its parent was writing to stdout or stderr
inherits that stream's lock held, by a thread it does not have: its first write or flush
(multiprocessing flushes both as a forked process starts) waits forever. Dask's forked
workers are started from a thread while the scheduler's threads run, so the sweep gives
every forked child new stream objects on the same file descriptors (``own_std_streams``).
"""

from __future__ import annotations

import os
import signal
import sys

from blocks.process.terminal import EscapedStream

_PR_SET_PDEATHSIG = 1


def die_with(parent: int) -> None:
    """Ask for SIGKILL when ``parent`` (the process that forked this one) exits; exit at
    once if it already has (the request came too late to take hold)."""
    import ctypes

    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:
        os._exit(1)


def own_std_streams() -> None:
    """In a forked child: ``sys.stdout`` and ``sys.stderr`` replaced by new streams on the
    same file descriptors (what the old ones still buffer is the parent's to write), and
    every logging handler that wrote to an old one pointed at its replacement."""
    replaced = {}
    for name in ("stdout", "stderr"):
        old = getattr(sys, name)
        try:
            fd = old.fileno()
        except (AttributeError, ValueError, OSError):  # not a file (a test's capture, say)
            continue
        new = open(fd, "w", encoding=getattr(old, "encoding", None), errors=getattr(old, "errors", None),
                   closefd=False, buffering=1 if getattr(old, "line_buffering", False) else -1)
        setattr(sys, name, EscapedStream(new) if isinstance(old, EscapedStream) else new)
        replaced[id(old)] = getattr(sys, name)
    logging = sys.modules.get("logging")
    if logging is None or not replaced:
        return
    loggers = [logging.getLogger(), *(lg for lg in logging.Logger.manager.loggerDict.values()
                                      if isinstance(lg, logging.Logger))]
    for handler in (h for lg in loggers for h in lg.handlers):
        if isinstance(handler, logging.StreamHandler) and id(handler.stream) in replaced:
            handler.stream = replaced[id(handler.stream)]


_registered = False


def own_std_streams_after_fork() -> None:
    """From now on, every child this process forks runs ``own_std_streams`` first."""
    global _registered
    if not _registered:
        os.register_at_fork(after_in_child=own_std_streams)
        _registered = True
