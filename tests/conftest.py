"""Settings every test shares.

Hypothesis's per-example deadline is a wall-clock assertion: on a machine busy with other
work a correct example can take longer than 200 ms and fail. The suite bounds its work by
counts (``max_examples``), never by seconds, so the deadline is off everywhere.
"""

from hypothesis import settings

settings.register_profile("suite", deadline=None)
settings.load_profile("suite")
