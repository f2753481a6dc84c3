"""``python -m hierhand`` is the ``hierhand`` command.

The working folder, which Python puts first on the module path for ``-m``, is taken off it
before anything else is imported, so that a ``numpy.py`` or ``yaml.py`` there is not
imported instead of the real one (``python -P -m hierhand`` does the same from the start).
"""

import os
import sys

if sys.path and sys.path[0] in ("", os.getcwd()) and not sys.flags.safe_path:
    del sys.path[0]

from hierhand.start import main  # noqa: E402  (after the path is safe)

main()
