"""``python -m hierhand`` is the ``hierhand`` command.

The working folder, which Python puts first on the module path for ``-m``, is taken off it
by ``hierhand.start`` before anything else is imported, so that a ``numpy.py`` or
``yaml.py`` there is not imported instead of the real one.
"""

from hierhand.start import main

main()
