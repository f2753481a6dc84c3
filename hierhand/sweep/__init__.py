"""Parameter sweeps: run one diagram at many parameter points and record task measures.

One concept per module: ``points`` (which parameter values to run), ``metrics`` (what
number to keep from each run), ``store`` (the append-only sweep.csv and resuming it),
``runner`` (running the points in process or on a Dask cluster), ``progress`` (the
terminal progress line) and ``plot`` (line plots and heat maps of a finished sweep).
"""

from .errors import SweepError

__all__ = ["SweepError"]
