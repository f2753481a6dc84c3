"""The ``hierhand`` command's first code: SIGINT and SIGTERM handled before its imports.

The ``hierhand`` console script (``[project.scripts]`` in pyproject.toml, which pip writes
for the interpreter that installs it) and ``python -m hierhand`` call ``main``, whose first
action is to install the stop handlers (``blocks.process.stop.launch``); only then does it
import the command line, so a Ctrl-C while numpy, matplotlib or a diagram load is one line
and exit code 130, not a traceback. A Ctrl-C while Python itself starts, before this code
runs, is Python's own: a KeyboardInterrupt traceback may print. Before anything else the
working folder goes off the module path, for this process and the Python processes it
starts (``hierhand.module_path``, ``blocks.process.module_path``).
"""

from __future__ import annotations

from hierhand.module_path import drop_working_folder

drop_working_folder()

from blocks.process.module_path import protect_children  # noqa: E402  (after the path is safe)
from blocks.process.stop import launch  # noqa: E402


def _command():
    from hierhand.cli import entry

    return entry


def main() -> None:
    protect_children()
    launch("hierhand", _command)
