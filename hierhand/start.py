"""The ``hierhand`` command's first code: SIGINT and SIGTERM handled before its imports.

The ``hierhand`` executable (the framework's launcher, ``blocks/csrc/launcher.c``, built by
setup.py) and ``python -m hierhand`` call ``main``, which installs the stop handlers
(``blocks.process.stop``) and only then imports the command line, so a Ctrl-C while numpy,
matplotlib or a diagram load is one line and exit code 130, not a traceback. The
executable starts Python with SIGINT and SIGTERM blocked, and ``main`` unblocks them once
they are handled, so that a Ctrl-C while the interpreter itself starts is that line too;
``python -m hierhand`` cannot cover that moment.
"""

from __future__ import annotations

from blocks.process.stop import launch


def _command():
    from hierhand.cli import entry

    return entry


def main() -> None:
    launch("hierhand", _command)
