"""The environment of a Python process the tool starts: no import from its working folder.

A child interpreter (the FMU isolation server, a Dask worker started by ``spawn``) would
put its working folder on its module path for ``-c`` and for each empty or relative entry
of ``PYTHONPATH`` (``:/x``). ``protect_children`` makes the environment such that it
does not: ``PYTHONSAFEPATH=1`` (Python 3.11's ``-P``) and ``PYTHONPATH`` with absolute
entries only.
"""

from __future__ import annotations

import os
from typing import MutableMapping


def protect_children(environ: MutableMapping[str, str] = os.environ) -> MutableMapping[str, str]:
    """Set ``environ`` (default: this process's, which every child inherits) so that a
    Python child imports nothing from its working folder; returns it."""
    environ["PYTHONSAFEPATH"] = "1"
    entries = [e for e in environ.get("PYTHONPATH", "").split(os.pathsep) if os.path.isabs(e)]
    if entries:
        environ["PYTHONPATH"] = os.pathsep.join(entries)
    else:
        environ.pop("PYTHONPATH", None)
    return environ
