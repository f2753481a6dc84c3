"""The one error type of the sweep modules: bad sweep input, reported as one line."""


class SweepError(Exception):
    """Bad sweep input (points, metrics, output folder); the message is one line."""
