"""The sweep's progress on stderr: points done of all, failed, elapsed and the time left.

A ``blocks.process.progress`` bar: shown only on a terminal (like a run's), so logs and
pipes stay clean.
"""

from __future__ import annotations

from typing import TextIO

from blocks.process.progress import progress_bar


class SweepProgress:
    """Advanced after every finished run; the time left assumes the remaining runs take as
    long on average."""

    def __init__(self, total: int, enabled: bool = True, stream: TextIO | None = None):
        self.bar = progress_bar(total, "sweep", unit="point", enabled=enabled, stream=stream)
        self.failed = 0

    def update(self, ok: bool) -> None:
        self.failed += 0 if ok else 1
        self.bar.set_postfix_str(f"{self.failed} failed", refresh=False)
        self.bar.update(1)

    def close(self) -> None:
        self.bar.close()
