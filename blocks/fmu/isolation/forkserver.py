"""The FMU launcher's own process (``launcher``): it forks the FMU hosts of one run's process.

Started by ``launcher.Launcher`` with one end of a socket pair, it imports what every host
needs (``_preload``: the host's modules, fmpy, the compiled extension, SUNDIALS), freezes
the imported objects for the garbage collector (so that the hosts' collections do not copy
their pages), says it is ready, and then serves requests until the run's process closes
its end: ``spawn`` (with the host's two file descriptors: fork a host that serves them,
answer its process id) and ``reap PID`` (answer how that host ended). It ignores SIGINT,
and each host asks for SIGKILL when the launcher exits.
"""

from __future__ import annotations

import gc
import os
import select
import signal
import socket

from blocks.process.forked import die_with
from blocks.fmu.isolation.launcher import REAP_SECONDS

def main(fd: int) -> None:
    """The launcher's life: import what the hosts need, then fork one per request until the
    run's process closes its end (or dies)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    sock = socket.socket(fileno=fd)
    host = _preload()
    gc.freeze()  # the hosts' garbage collections leave the imported objects (and their pages) alone
    sock.send(b"ready")
    while True:
        try:
            message, fds, _, _ = socket.recv_fds(sock, 256, 4)
        except OSError:
            break
        if not message:
            break
        op, _, arg = message.partition(b" ")
        if op == b"spawn":
            sock.send(_fork(sock, host, fds))
        elif op == b"reap":
            sock.send(_reap(int(arg)))
    os._exit(0)


def _preload():
    """Import (and load) once what every host needs, so that each fork has it: the host's
    modules, fmpy, the compiled extension, SUNDIALS' libraries for model exchange."""
    from blocks.fmu.isolation import server as host
    from blocks.fmu import sundials
    from blocks.fmu.isolation.channel import native
    from blocks.fmu.model import import_fmpy

    import_fmpy()
    native()
    try:
        sundials.functions()
    except RuntimeError:  # no CVode here: a model-exchange host says so when it needs it
        pass
    return host


def _fork(sock: socket.socket, host, fds: list[int]) -> bytes:
    """Fork the host of the channel ``fds``: its process id, or why not."""
    launcher = os.getpid()
    try:
        pid = os.fork()
    except OSError as exc:
        for f in fds:
            os.close(f)
        return f"fork failed: {exc.strerror}".encode()
    if pid == 0:
        code = 0
        try:
            sock.close()
            die_with(launcher)
            host.serve(*fds)
        except BaseException:
            code = 1
        os._exit(code)
    for f in fds:
        os.close(f)
    return str(pid).encode()


def _reap(pid: int) -> bytes:
    """Wait (at most REAP_SECONDS) for the host ``pid`` to end: its exit status."""
    try:
        handle = os.pidfd_open(pid)
    except OSError:
        handle = None
    try:
        if handle is not None and not select.select([handle], [], [], REAP_SECONDS)[0]:
            return b"unknown"
        _, status = os.waitpid(pid, 0)
    except ChildProcessError:
        return b"unknown"
    finally:
        if handle is not None:
            os.close(handle)
    return str(os.waitstatus_to_exitcode(status)).encode()
