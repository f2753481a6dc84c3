"""The ``hierhand`` command's first code: SIGINT and SIGTERM handled before its imports.

The console script and ``python -m hierhand`` call ``main``, which installs the stop
handlers (``blocks.stop``) and only then imports the command line, so a Ctrl-C while
numpy, matplotlib or a diagram load is one line and exit code 130, not a traceback.
"""

from __future__ import annotations

from blocks.stop import launch


def _command():
    from hierhand.cli import entry

    return entry


def main() -> None:
    launch("hierhand", _command)
