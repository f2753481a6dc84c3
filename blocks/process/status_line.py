"""One status line on stderr, redrawn in place; only on a terminal, so logs and pipes stay clean."""

from __future__ import annotations

import sys
from typing import TextIO


class StatusLine:
    """``show(text)`` redraws the line; ``close()`` ends it with a newline if it was shown."""

    def __init__(self, enabled: bool = True, stream: TextIO | None = None):
        self.stream = stream or sys.stderr
        self.enabled = enabled and self.stream.isatty()
        self.shown = False

    def show(self, text: str) -> None:
        if not self.enabled:
            return
        self.shown = True
        self.stream.write(f"\r{text} ")
        self.stream.flush()

    def close(self) -> None:
        if self.shown:
            self.stream.write("\n")
            self.stream.flush()
