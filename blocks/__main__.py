"""``python -m blocks``: the framework's generic commands (run, validate, graph, plot, fmu
info, sweep, sweep-plot, blocks) on any diagram.

Python puts the working folder first on the module path for ``-m``, so a ``blocks.py`` or
``numpy.py`` there would be imported instead of the real one: the working folder is taken
off the path before anything else is imported (``python -P -m blocks`` does the same from
the start, and is what protects against a module named ``blocks`` itself there).
"""

import os
import sys

if sys.path and sys.path[0] in ("", os.getcwd()) and not sys.flags.safe_path:
    del sys.path[0]

from blocks.process.module_path import protect_children  # noqa: E402  (after the path is safe)
from blocks.process.stop import launch  # noqa: E402


def _command():
    from blocks.cli import PROGRAM, entry

    return lambda: entry(PROGRAM)


if __name__ == "__main__":
    protect_children()  # the Python processes it starts do not import from their working folder either
    launch("blocks", _command)
