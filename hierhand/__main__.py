"""``python -m hierhand`` is the ``hierhand`` command."""

from hierhand.cli import entry

entry()
