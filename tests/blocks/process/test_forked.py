"""Forked children: they write through standard streams of their own, so a stream that a
parent's thread held at the fork cannot stop them."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork, and Linux's pipe ioctls")

REPO = Path(__file__).resolve().parents[3]

SCENARIO = r'''
import fcntl, logging, os, sys, termios, threading, time

from blocks.process.forked import own_std_streams_after_fork

if sys.argv[1] == "own":
    own_std_streams_after_fork()
read, write = os.pipe()
size = fcntl.fcntl(write, 1032)  # F_GETPIPE_SZ
sys.stderr = stuck = open(write, "w", encoding="utf-8")
handler = logging.StreamHandler(sys.stderr)
logging.getLogger("scenario").addHandler(handler)
threading.Thread(target=lambda: (stuck.write("x" * (4 * size)), stuck.flush()), daemon=True).start()
while int.from_bytes(fcntl.ioctl(read, termios.FIONREAD, b"\0\0\0\0"), sys.byteorder) < size:
    time.sleep(0.001)  # the readiness sign: the pipe is full, the writer blocked holding the stream
pid = os.fork()
if pid == 0:
    sys.stderr.flush()  # multiprocessing does this as a forked process starts
    os._exit(0 if handler.stream is sys.stderr else 3)
deadline = time.monotonic() + float(sys.argv[2])
while time.monotonic() < deadline:
    done, status = os.waitpid(pid, os.WNOHANG)
    if done:
        print(os.waitstatus_to_exitcode(status))
        os._exit(0)
    time.sleep(0.01)
os.kill(pid, 9)
print("hung")
os._exit(0)
'''


@pytest.mark.parametrize("streams, within, outcome", [("own", 60, "0"), ("inherited", 2, "hung")])
def test_a_child_forked_while_a_thread_is_stuck_writing_to_stderr_can_flush_and_log(streams, within, outcome):
    """With its own streams the child flushes (it has nothing to write) and its logging
    handler follows the new stderr; with the parent's it hangs, which is the hazard."""
    proc = subprocess.run([sys.executable, "-c", SCENARIO, streams, str(within)], capture_output=True, text=True,
                          timeout=120, env={**os.environ, "PYTHONPATH": str(REPO)})
    assert proc.stdout.strip() == outcome, proc
