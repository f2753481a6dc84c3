"""The sweep's one-line progress report on stderr: done/total, failed, elapsed and ETA.

Shown only on a terminal (like a run's progress bar), so logs and pipes stay clean.
"""

from __future__ import annotations

import time
from typing import TextIO

from blocks.process.status_line import StatusLine


class SweepProgress:
    """Redrawn after every finished run; the ETA assumes the remaining runs take as long on average."""

    def __init__(self, total: int, enabled: bool = True, stream: TextIO | None = None):
        self.line = StatusLine(enabled, stream)
        self.total = total
        self.done = self.failed = 0
        self.start = time.perf_counter()

    def update(self, ok: bool) -> None:
        self.done += 1
        self.failed += 0 if ok else 1
        elapsed = time.perf_counter() - self.start
        eta = elapsed * (self.total - self.done) / self.done
        self.line.show(f"sweep: {self.done}/{self.total} done, {self.failed} failed, "
                       f"{elapsed:.1f} s elapsed, eta {eta:.1f} s")

    def close(self) -> None:
        self.line.close()
