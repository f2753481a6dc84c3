"""Fixtures of the sweep tests: one real ``dask scheduler`` with two ``dask worker``
processes for the session (starting them is most of what a test on them costs)."""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

import pytest

from blocks.process import scratch


@dataclass(frozen=True)
class DaskProcesses:
    """A scheduler at ``address`` with ``workers`` worker processes whose working folder
    and TMPDIR are ``home``, a folder the client's files are not in."""

    address: str
    workers: int
    home: Path


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def stop(procs: list[subprocess.Popen]) -> None:
    for p in procs:
        if p.poll() is None:
            p.terminate()
    for p in procs:
        try:
            p.wait(timeout=60)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait(timeout=60)


@pytest.fixture(scope="session")
def dask_elsewhere(tmp_path_factory):
    """A running ``dask scheduler`` and two ``dask worker`` processes started in a folder of
    their own (skips without the ``dask`` command)."""
    from distributed import Client

    dask = shutil.which("dask")
    if dask is None:
        pytest.skip("the dask command is not installed")
    root = tmp_path_factory.mktemp("dask")
    home = root / "worker-home"
    home.mkdir()
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = {**{k: v for k, v in os.environ.items() if k != scratch.ENV}, "TMPDIR": str(home)}  # another machine
    log = open(root / "dask.log", "w")
    procs = [subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard",
                              "--dashboard-address", "127.0.0.1:0"],
                              stdout=log, stderr=subprocess.STDOUT, cwd=home)]
    try:
        for _ in range(2):
            procs.append(subprocess.Popen([dask, "worker", address, "--nthreads", "1", "--nworkers", "1",
                                           "--host", "127.0.0.1", "--no-dashboard"],
                                          stdout=log, stderr=subprocess.STDOUT, cwd=home, env=env))
        deadline = time.monotonic() + 60
        with Client(address, timeout=30) as client:
            client.wait_for_workers(2, timeout=max(1.0, deadline - time.monotonic()))
        yield DaskProcesses(address, 2, home)
    finally:
        stop(procs[1:])  # the workers first: without their scheduler they wait 8 s to be killed
        stop(procs[:1])
        log.close()
