"""``python -m hierhand ARGS`` as the tests run it many times: each run a process of its
own, forked from a server that has imported the command line once.

A fresh interpreter spends about two thirds of a short command (``validate`` of a small
diagram) importing numpy, YAML and the framework. The server imports them once; each
command is then a forked child that goes to its folder, takes the files for stdin, stdout
and stderr, and runs the ``hierhand`` module as ``python -m`` runs it: its exit code,
output, a crash (a signal: a negative return code) and a hang (killed at the timeout) are
the child's alone, as they are a fresh process's. What is not the same: the imports have
happened before the command starts, so nothing here tests start-up itself.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

SERVER = r'''
import json, os, runpy, select, signal, sys, time
import hierhand.cli  # noqa: F401  (the imports every command needs)
requests, replies = sys.stdin.buffer, sys.stdout.buffer
for line in requests:
    job = json.loads(line)
    pid = os.fork()
    if pid == 0:
        try:
            os.chdir(job["cwd"])
            for fd, name, mode in ((0, os.devnull, os.O_RDONLY), (1, job["out"], os.O_WRONLY),
                                   (2, job["err"], os.O_WRONLY)):
                os.dup2(os.open(name, mode), fd)
            sys.stdin = open(0, closefd=False)
            sys.stdout = open(1, "w", closefd=False)
            sys.stderr = open(2, "w", closefd=False)
            sys.argv = ["hierhand", *job["argv"]]
            code = 0
            try:
                runpy.run_module("hierhand", run_name="__main__", alter_sys=True)
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
                if not isinstance(exc.code, (int, type(None))):
                    print(exc.code, file=sys.stderr)
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(code)
        except BaseException:
            import traceback
            traceback.print_exc()
            sys.stderr.flush()
            os._exit(1)
    deadline = time.monotonic() + job["timeout"]
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            code = os.waitstatus_to_exitcode(status)
            timed_out = False
            break
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            code, timed_out = -9, True
            break
        time.sleep(0.005)
    replies.write((json.dumps({"code": code, "timed_out": timed_out}) + "\n").encode())
    replies.flush()
'''


class ForkedCLI:
    """The server and its ``run``; ``close()`` ends it."""

    def __init__(self, root: Path):
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(root), os.environ.get("PYTHONPATH")])))
        self.server = subprocess.Popen([sys.executable, "-c", SERVER], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                       env=env, cwd=root)

    def run(self, argv: list[str], cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
        """``python -m hierhand ARGV`` in ``cwd``, as ``subprocess.run(..., capture_output=True,
        text=True, timeout=timeout)`` gives it (TimeoutExpired after ``timeout`` seconds)."""
        with tempfile.TemporaryDirectory(prefix="forked-cli-") as tmp:
            out, err = Path(tmp, "stdout"), Path(tmp, "stderr")
            out.touch()
            err.touch()
            request = {"argv": [str(a) for a in argv], "cwd": str(cwd), "out": str(out), "err": str(err),
                       "timeout": timeout}
            self.server.stdin.write((json.dumps(request) + "\n").encode())
            self.server.stdin.flush()
            reply = json.loads(self.server.stdout.readline())
            stdout, stderr = out.read_text(errors="replace"), err.read_text(errors="replace")
        if reply["timed_out"]:
            raise subprocess.TimeoutExpired(["hierhand", *argv], timeout, stdout, stderr)
        return subprocess.CompletedProcess(["hierhand", *argv], reply["code"], stdout, stderr)

    def close(self) -> None:
        self.server.stdin.close()
        self.server.wait(timeout=120)


_shared: ForkedCLI | None = None


def shared() -> ForkedCLI:
    """The test session's one server, started at first use and ended when the session's
    process exits."""
    global _shared
    if _shared is None:
        import atexit

        _shared = ForkedCLI(Path(__file__).resolve().parents[1])
        atexit.register(_shared.close)
    return _shared
