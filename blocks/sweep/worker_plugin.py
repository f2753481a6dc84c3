"""The Dask worker plugins of a sweep (their own module so that importing the sweep does not
import distributed)."""

from __future__ import annotations

import signal
import threading

from distributed.diagnostics.plugin import WorkerPlugin


class IgnoreCtrlC(WorkerPlugin):
    """SIGINT ignored in the worker process: Ctrl-C is answered by the sweep's own process.

    Workers forked at the cluster's start already inherit the ignored signal; this covers
    one that its nanny restarts after a crash, forked once the handler was put back.
    """

    def setup(self, worker) -> None:
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, signal.SIG_IGN)


class DiagramFiles(WorkerPlugin):
    """The sweep's diagram and its files (``bundle.DiagramBundle``), written once into a
    private temporary folder of each worker process, before its first task, and removed
    when the plugin is unregistered or the worker closes. The scheduler keeps the plugin,
    so a worker that joins later or is restarted after a crash gets the files too."""

    def __init__(self, bundle, token: str):
        self.bundle = bundle
        self.name = f"blocks-sweep-files-{bundle.hash[:12]}-{token}"

    def setup(self, worker) -> None:
        from .bundle import hold

        hold(self.bundle)

    def teardown(self, worker) -> None:
        from .bundle import release

        release(self.bundle.hash)
