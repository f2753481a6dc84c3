"""Text from files shown on a terminal as text: control characters written as escapes.

A diagram's name, a block's name, a path or a message quoting a file may hold control
characters (an escape sequence that retitles or clears the terminal, a carriage return
that overwrites what was printed, a right-to-left override that reverses it). The command
line writes stdout and stderr through ``EscapedStream``, the one place every message and
summary passes, which shows each such character as a Python escape (``\\x1b``); line
breaks and tabs pass. The progress bar, which draws with carriage returns and cursor
moves of its own, writes to the stream beneath (``EscapedStream.unescaped``).
"""

from __future__ import annotations

import re

TYPE_CHECKING = False  # typing's constant without importing typing (blocks.cli.program says why)
if TYPE_CHECKING:
    from typing import Any, TextIO

_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028-\u202e\u2066-\u2069]")
"""C0 controls but tab and line feed, DEL, C1 controls, and the bidirectional-text marks,
overrides and isolates (and the line and paragraph separators)."""


def escape_controls(text: str) -> str:
    """``text`` with each control character (``_CONTROL``) written as an escape."""
    return _CONTROL.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), text)


class EscapedStream:
    """A text stream that writes ``escape_controls`` of what it is given to ``unescaped``."""

    def __init__(self, stream: TextIO):
        self.unescaped = stream

    def write(self, text: str) -> int:
        self.unescaped.write(escape_controls(text))
        return len(text)

    def writelines(self, lines: Any) -> None:
        for line in lines:
            self.write(line)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.unescaped, name)


def unescaped(stream: TextIO) -> TextIO:
    """The stream beneath ``stream`` if it escapes, else ``stream``."""
    return getattr(stream, "unescaped", stream)
