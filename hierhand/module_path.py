"""The working folder taken off the module path before the command imports anything of its own.

Python puts the working folder on ``sys.path`` in several ways: ``''`` (``-c``, an
interactive session), the folder itself (``python -m``), and every empty or relative entry
of ``PYTHONPATH`` (``PYTHONPATH=:/x`` means the working folder, then ``/x``). A folder a
user runs the command in may hold anything (an unpacked download with a ``blocks/``
package or a ``yaml.py``), so none of these may import from it. Only the folder that
``hierhand`` itself was imported from is kept, where that is the working folder: the
command runs from its own source tree.
"""

from __future__ import annotations

import os
import sys


def drop_working_folder() -> None:
    """Remove every ``sys.path`` entry that is, or resolves to, the working folder (see the
    module's docstring)."""
    try:
        here = os.path.realpath(os.getcwd())
    except OSError:  # the working folder was deleted: nothing can be imported from it
        here = None
    own = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))
    sys.path[:] = [entry for entry in sys.path
                   if entry not in ("", ".") and (os.path.realpath(entry) != here or here == own)]
