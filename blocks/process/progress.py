"""Progress on long work (a run, a sweep, an animation, the paper's tasks): a tqdm bar on
stderr, shown only on a terminal and when not asked to be quiet, so logs and pipes stay clean.

tqdm draws, times and rate-limits the bar (its own ``mininterval``), and writes above it
what is printed through ``bar.write``; ``delay`` keeps a short piece of work silent.
"""

from __future__ import annotations

import sys
from typing import Any, TextIO

from blocks.process.terminal import escape_controls, unescaped


def progress_bar(total: float | None, description: str, unit: str = "it", enabled: bool = True,
                 stream: TextIO | None = None, **options: Any):
    """A ``tqdm`` bar of ``total`` steps on ``stream`` (default: stderr); disabled (it
    draws nothing, updates cost nothing) unless ``enabled`` and the stream is a terminal.
    ``options`` go to tqdm (``delay``, ``bar_format``, ...)."""
    from tqdm import tqdm

    stream = unescaped(stream or sys.stderr)  # tqdm draws with control characters of its own
    shown = shows(enabled, stream)
    return tqdm(total=total, desc=escape_controls(description), unit=unit, file=stream, disable=not shown,
                leave=False,
                dynamic_ncols=True, **options)


def shows(enabled: bool, stream: TextIO | None = None) -> bool:
    """Whether a bar on ``stream`` (default: stderr) is drawn: when ``enabled`` and the
    stream is a terminal (else a caller may skip the bar, and tqdm's import, altogether)."""
    return enabled and (stream or sys.stderr).isatty()


def above(bar, report):
    """``report`` (a function of one line, e.g. ``print``) made to write above ``bar``: the
    bar is cleared while the line is written and drawn again after it."""
    def say(text: str) -> None:
        with bar.external_write_mode():
            report(text)

    return say
