"""What a forked helper process does first: ask to die with the process that forked it.

A helper (an FMU host, a plot drawer) must not outlive the process it serves, even when
that one is killed by SIGKILL and cannot clean up: on Linux the kernel sends the helper
SIGKILL when its parent exits (PR_SET_PDEATHSIG).
"""

from __future__ import annotations

import os
import signal

_PR_SET_PDEATHSIG = 1


def die_with(parent: int) -> None:
    """Ask for SIGKILL when ``parent`` (the process that forked this one) exits; exit at
    once if it already has (the request came too late to take hold)."""
    import ctypes

    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:
        os._exit(1)
