"""Parameter sweeps: run one diagram at many parameter points and record task measures.

One concept per module: ``points`` (which parameter values to run), ``metrics`` (what
number to keep from each run), ``store`` (the append-only sweep.csv and resuming it),
``runner`` (one point's run, and the serial loop), ``cluster`` (running the points on
Dask, with ``worker_plugin``), ``chunks`` (how many points one Dask task runs), ``plan``
(checking a sweep and executing it), ``progress`` (the terminal progress line) and
``plot`` (line plots and heat maps of a finished sweep).
"""

from .errors import SweepError

__all__ = ["SweepError"]
