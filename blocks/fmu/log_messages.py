"""The log messages of FMU instances: kept per instance for error messages, and logged.

Each instance keeps its ``LOG_LINES`` most recent messages, so that a failure names what
the FMU said before it; every message also goes to the ``blocks.fmu`` logger (warnings are
only seen there).

FMI 2 loggers are variadic C functions, which ctypes cannot receive; fmpy's native proxy
(``fmpy.logging.addLoggerProxy``) formats the message and forwards it to ONE process-wide
Python callback. Ours dispatches on the componentEnvironment (a serial number per
instance, registered in ``fmi2_buffers``) to that instance's message buffer, and is
re-armed (``fmi2_logger``) before every FMU call that can log, in case other code
installed its own. Messages of other FMUs (fmpy's default callbacks) are printed as fmpy
prints them. FMI 3 passes formatted messages to a per-instance callback, which calls
``record``. The callbacks are wrapped by ``interrupt.callback``, so that Ctrl-C in them
is not lost.
"""

from __future__ import annotations

import collections
import logging

from . import interrupt

log = logging.getLogger("blocks.fmu")

LOG_LINES = 20
"""How many of an instance's most recent FMU log messages are kept for error messages."""

ERROR_LOG_LINES = 8
"""How many of them an error message quotes."""

_STATUS = ("ok", "warning", "discard", "error", "fatal", "pending")

fmi2_buffers: dict[int, tuple[collections.deque, str]] = {}
"""Where FMI 2 messages go, by the instance's serial (its componentEnvironment): the
instance's message buffer and who it is, for the log."""

_fmi2_proxy: tuple | None = None


def log_text(lines: list[str]) -> str:
    """An instance's recent log messages (oldest first) as a failure's message ends with them."""
    if not lines:
        return " (the FMU logged no messages)"
    return "; FMU log: " + " | ".join(lines[-ERROR_LOG_LINES:])


def status_name(status: object) -> str:
    """An FMI status code by its name (``'error'``), or the code itself as text."""
    return _STATUS[status] if isinstance(status, int) and 0 <= status < len(_STATUS) else str(status)


def record(buffer: collections.deque | None, status: int, category: bytes | None,
           message: bytes | None, who: str) -> None:
    """Keep a message in ``buffer`` and log it, as coming from ``who``."""
    text = (message or b"").decode("utf-8", "replace").strip()
    cat = (category or b"").decode("utf-8", "replace")
    line = f"[{status_name(status)}] {cat + ': ' if cat else ''}{text}"
    if buffer is not None:
        buffer.append(line)
    # Warnings are only seen here; errors also go into the BlockError of the failing call.
    log.log({0: logging.DEBUG, 1: logging.WARNING}.get(status, logging.INFO), "%s: %s", who, line)


@interrupt.callback
def _fmi2_log(env, instance_name, status, category, message) -> None:
    entry = fmi2_buffers.get(env or 0)
    if entry is None:  # an FMU of other code using fmpy's default callbacks: do what fmpy does
        print(f"[{status_name(status).upper()}] {(message or b'').decode('utf-8', 'replace')}")
        return
    record(entry[0], status, category, message, entry[1])


def fmi2_logger():
    """Make fmpy's native logger proxy forward FMI 2 messages to ``_fmi2_log``; returns
    the ctypes callback to put into an instance's callback functions."""
    global _fmi2_proxy
    if _fmi2_proxy is None:
        from ctypes import byref

        from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
        from fmpy.logging import addLoggerProxy

        callback = fmi2CallbackLoggerTYPE(_fmi2_log)
        scratch = fmi2CallbackFunctions()
        _fmi2_proxy = (addLoggerProxy, scratch, byref(scratch), callback)
    add, scratch, ref, callback = _fmi2_proxy
    scratch.logger = callback
    add(ref)
    return callback


def fmi2_logger_arming() -> tuple[int, int]:
    """``fmi2_logger`` as C can do it before every step: the addresses of fmpy's
    addLoggerProxy and of the callback functions it takes (ours), for the FMU's kernel."""
    import ctypes

    fmi2_logger()
    add, scratch, _, _ = _fmi2_proxy
    return ctypes.cast(add, ctypes.c_void_p).value, ctypes.addressof(scratch)
