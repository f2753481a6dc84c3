"""The Dask worker plugin of the sweep's LocalCluster (its own module so that importing the
sweep does not import distributed)."""

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
