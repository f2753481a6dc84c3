"""Parameter sweeps: run one diagram at many parameter points and keep numbers from each run.

Works on any diagram: ``run_sweep(diagram, points, metrics, output)`` from Python, and the
``sweep`` and ``sweep-plot`` commands of the command line (``blocks.cli.sweep``)::

    from blocks.sweep import grid_points, run_sweep

    points = grid_points({"prop.k": [1, 2, 4]})
    summary = run_sweep("diagrams/toy.yaml", points, ["y=final(plant.y)"], "runs/toy-sweep")

One concept per module: ``points`` (which parameter values to run), ``metrics`` (metric
expressions: what number to keep from each run), ``measures`` (the named measures that
applications register through the ``blocks.measures`` entry-point group), ``store`` (the
append-only sweep.csv and resuming it), ``bundle`` (the diagram as content: its text and
every file it reads, sent to the workers and written there once), ``runner`` (one point's
run, and the serial loop), ``local`` (the default's head start: a forked local process
runs points while a cluster starts, or all of them when none would pay off), ``queue``
(the points still to hand out, shared with that process), ``cluster`` (running the
points on Dask, with ``worker_plugin``, and the version check of a running scheduler),
``chunks`` (how many points one Dask task runs), ``plan`` (checking a sweep and executing it),
``progress`` (the terminal progress line) and ``plot`` (line plots and heat maps of a
finished sweep). Importing this package imports neither Dask nor matplotlib.
"""

from .errors import SweepError
from .measures import ENTRY_POINT_GROUP, register_measure, registered_measures, unregister_measure
from .metrics import Metric, parse_metric, parse_metrics
from .plan import SweepInterrupted, SweepSummary, run_sweep
from .points import csv_points, grid_points, random_points
from .store import read_sweep

__all__ = ["ENTRY_POINT_GROUP", "Metric", "SweepError", "SweepInterrupted", "SweepSummary", "csv_points",
           "grid_points", "parse_metric", "parse_metrics", "random_points", "read_sweep",
           "register_measure", "registered_measures", "run_sweep", "unregister_measure"]
