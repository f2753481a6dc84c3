"""The ``hierhand`` command's first code: SIGINT and SIGTERM handled before its imports.

The ``hierhand`` console script (``[project.scripts]`` in pyproject.toml, which pip writes
for the interpreter that installs it) and ``python -m hierhand`` call ``main``, whose first
action is to install the stop handlers (``blocks.process.stop.launch``); only then does it
import the command line, so a Ctrl-C while numpy, matplotlib or a diagram load is one line
and exit code 130, not a traceback. A Ctrl-C while Python itself starts, before this code
runs, is Python's own: a KeyboardInterrupt traceback may print.
"""

from __future__ import annotations

from blocks.process.stop import launch


def _command():
    from hierhand.cli import entry

    return entry


def main() -> None:
    launch("hierhand", _command)
