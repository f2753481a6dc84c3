"""The FMU launcher, as the run's process sees it: the process that forks its FMU hosts.

A fresh Python process with fmpy and the FMU modules imported takes about half a second
to start; a fork of one that has them, a millisecond or two. So the first hosted FMU
instance of a process starts the launcher (``Launcher.here``), and every host is forked
from it (``spawn``). The launcher:

- runs in a session of its own (so do the hosts it forks), so a Ctrl-C at the terminal
  reaches only the run's process, which decides what happens to its FMUs;
- lives as long as the run's process keeps its end of their socket open: it exits at the
  end-of-file, also when the run's process was killed (SIGKILL included), and every host
  it forked has asked for SIGKILL when the launcher exits (PR_SET_PDEATHSIG), so no host
  outlives the run's process, not even one stuck in an FMU call that never returns;
- reaps its hosts when asked and says how each ended (``ended``: the exit status), which
  the run's process, not their parent, could not learn otherwise.

The launcher's own side is ``forkserver``.

A process forked from the run's process (a sweep's local runner, a forked Dask worker)
starts a launcher of its own when it needs one (``os.register_at_fork``); the hosts it
inherited belong to the process that made them.
"""

from __future__ import annotations

import os
import select
import socket
import subprocess
import sys
import threading
from pathlib import Path

from blocks.block import BlockError
from blocks.process.module_path import protect_children

STARTUP_SECONDS = 120.0
"""How long the launcher may take to start (importing numpy and fmpy on a loaded machine)."""

REAP_SECONDS = 10.0
"""How long the launcher waits for a host to end once its end of the channel is closed."""


class Launcher:
    """The run's side of the launcher of this process."""

    _lock = threading.Lock()
    _here: tuple[int, Launcher] | None = None

    @classmethod
    def here(cls) -> Launcher:
        """This process's launcher, started on first use."""
        with cls._lock:
            if cls._here is None or cls._here[0] != os.getpid() or not cls._here[1].running:
                cls._here = (os.getpid(), cls())
            return cls._here[1]

    @property
    def running(self) -> bool:
        """Whether the launcher still runs (it may have been killed by another program)."""
        if self.alive and self.process.poll() is not None:
            self.alive = False
            self.sock.close()
        return self.alive

    @classmethod
    def forget(cls) -> None:
        """In a process forked from one with a launcher: that launcher is not this process's."""
        if cls._here is not None:
            cls._here[1].sock.close()
        cls._here = None
        cls._lock = threading.Lock()

    def __init__(self):
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        root = str(Path(__file__).resolve().parents[3])  # the folder the blocks package is in
        env = protect_children(dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
                                    MKL_NUM_THREADS="1"))
        env["PYTHONPATH"] = os.pathsep.join([root, *filter(None, [env.get("PYTHONPATH")])])
        command = [sys.executable, "-P", "-c", f"from blocks.fmu.isolation.forkserver import main; main({theirs.fileno()})"]
        try:
            self.process = subprocess.Popen(command, pass_fds=(theirs.fileno(),), start_new_session=True,
                                            stdin=subprocess.DEVNULL, env=env, close_fds=True)
        finally:
            theirs.close()
        self.sock = ours
        self.alive = True
        self._owed = 0
        """Answers to requests whose waiting was interrupted (a signal), to skip."""
        try:
            ready = self._receive(STARTUP_SECONDS)
        except BaseException:  # a signal while it starts: it does not outlive this
            self._stop()
            raise
        if ready != b"ready":
            code = self._stop()
            raise BlockError(f"the process that runs FMUs in processes of their own did not start (exit code "
                             f"{code}); run the FMU in this process with 'isolation: none'")

    def _stop(self) -> int:
        """Kill a launcher that did not start, and reap it: its exit code."""
        self.alive = False
        self.sock.close()
        self.process.kill()
        return self.process.wait()

    def spawn(self, fds: list[int]) -> int:
        """Fork a host that serves the channel of ``fds`` (its socket end, the shared memory);
        its process id."""
        with self._lock:
            try:
                answer = self._ask(lambda: socket.send_fds(self.sock, [b"spawn"], fds), STARTUP_SECONDS)
            except OSError:
                self.alive, answer = False, b""
        if not answer:
            raise BlockError("could not start a process for the FMU: the process that starts them has ended "
                             "(the next run starts it again)")
        if not answer.isdigit():
            raise BlockError(f"could not start a process for the FMU: {answer.decode(errors='replace')}")
        return int(answer)

    def ended(self, pid: int) -> int | None:
        """Reap the host ``pid`` (its end of the channel closed, or killed): its exit status
        (``os.waitstatus_to_exitcode``: the exit code, or minus the signal), None if unknown."""
        with self._lock:
            try:
                answer = self._ask(lambda: self.sock.send(b"reap %d" % pid), REAP_SECONDS + 5.0)
            except OSError:
                self.alive, answer = False, b""
        return int(answer) if answer.lstrip(b"-").isdigit() else None

    def _ask(self, request, seconds: float) -> bytes:
        """Send a request and return its answer, skipping those of requests that a signal
        interrupted before their answer came."""
        while self._owed and self._receive(seconds):
            self._owed -= 1
        request()
        self._owed += 1
        answer = self._receive(seconds)
        if answer:
            self._owed -= 1
        return answer

    def _receive(self, seconds: float) -> bytes:
        """The launcher's next answer ('' if it is gone or silent for ``seconds``)."""
        if not select.select([self.sock], [], [], seconds)[0]:
            return b""
        try:
            answer = self.sock.recv(256)
        except OSError:
            answer = b""
        if not answer:
            self.alive = False
        return answer


os.register_at_fork(after_in_child=Launcher.forget)
