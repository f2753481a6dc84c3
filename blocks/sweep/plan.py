"""A sweep checked before it runs: the points with their hashes, the metrics, the job.

``prepare`` does every check that can fail before the first run: the parameter names
(through the diagram loader, with the first point's values, so a typo gets the loader's
own message and suggestion) and the metrics (against the diagram's logged signals).
A bad *value* of one point is not refused here: that point runs, fails and is recorded
as failed, and the other points go on. ``execute`` appends every finished run to the
store and skips the points the store already holds. ``run_sweep`` does both in one call.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from blocks.builder.api_args import boolean
from ..safepath import link_out_of
from .bundle import bundle_for, discard
from .errors import SweepError
from .metrics import Metric, parse_metrics
from .points import Point, point_json, unique_points
from .progress import SweepProgress
from .cluster import connect, run_dask
from .local import can_run_locally, run_local_first
from .runner import Outcome, SweepJob, SweepReport, run_serial, warm_up
from .store import OK, RUNS, SWEEP_CSV, SweepStore, read_sweep


@dataclass
class SweepPlan:
    """A validated sweep: the job every point runs and the (hash, point) pairs, in order."""

    job: SweepJob
    points: list[tuple[str, Point]]
    parameters: list[str]
    diagram_hash: str
    axes: dict[str, Any] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)
    """The unit of each metric whose unit is known (``Metric.unit``)."""

    def description(self) -> dict[str, Any]:
        """What sweep.json records: enough to read the CSV and to repeat the sweep."""
        bundle = self.job.bundle
        return {
            "diagram": self.job.diagram,
            "diagram_hash": self.diagram_hash,
            "files": {f.ref: f.sha256 for f in bundle.files} if bundle is not None else {},
            "t_end": self.job.t_end,
            "parameters": self.parameters,
            "axes": self.axes,
            "metrics": {m.name: m.text.partition("=")[2].strip() for m in self.job.metrics},
            "units": self.units,
            "points": len(self.points),
        }


def prepare(diagram: str | Path, points: list[Point], metrics: list[Metric], t_end: str | None = None,
            trust: bool = False, axes: dict[str, Any] | None = None,
            origins: dict[str, str] | None = None, keep_results: bool = False, step: str | None = None) -> SweepPlan:
    """Check the points' parameter names and the metrics against the diagram; bundle the
    diagram with every file it reads (``bundle``) and hash the points with the bundle's hash.

    Raises the loader's DiagramError for an unknown block or parameter, SweepError for
    anything else that cannot work. ``origins`` says how the user gave each parameter
    (``points.origins``), for the loader's messages about it.
    """
    from blocks import DiagramError, load_diagram

    if not points:
        raise SweepError("no points: give --grid, --random or --points")
    keys = list(points[0])
    for p in points:
        if list(p) != keys:
            raise SweepError(f"every point must set the same parameters; {point_json(p)} differs from "
                             f"{', '.join(keys)}")
    base = load_diagram(diagram, trust=trust, step=step)
    checked = base
    try:
        checked = load_diagram(diagram, overrides=points[0], trust=trust, origins=origins, step=step)
    except DiagramError as exc:
        if any(i.override for i in exc.issues):
            raise
    for metric in metrics:
        metric.check(checked)
    bundle = bundle_for(diagram, [base, checked], _swept_files(base, points), step=step)
    job = SweepJob(diagram=str(Path(diagram).resolve()), metrics=tuple(metrics), t_end=t_end, trust=trust,
                   origins=tuple((origins or {}).items()), bundle=bundle, keep_results=keep_results)
    units = {m.name: unit for m in metrics if (unit := m.unit(checked)) is not None}
    return SweepPlan(job=job, points=unique_points(points, bundle.hash, t_end), parameters=keys,
                     diagram_hash=bundle.hash, axes=axes or {}, units=units)


def _swept_files(base, points: list[Point]) -> dict[str, Path]:
    """The files that swept path parameters name (``--grid plant.path=a.fmu,b.fmu``), by the
    reference each point gives (from the top diagram's folder, for a block of a subsystem),
    resolved as the loader does; those that are no file are left to fail in their points."""
    found: dict[str, Path] = {}
    for key in points[0]:
        named = base.split_key(key)
        spec = base.blocks.get(named[0]) if named else None
        if spec is None or named[1] not in type(spec.block).path_params:
            continue
        for point in points:
            ref = point[key]
            if isinstance(ref, str) and ref.strip():
                path = spec.scope.path(ref)
                if path.is_file():
                    found[spec.scope.ref(ref)] = path
    return found


def execute(plan: SweepPlan, output: str | Path, workers: int | None = None, scheduler: str | None = None,
            serial: bool = False, progress: bool = True,
            start_method: str | None = None) -> tuple[SweepReport, int, int]:
    """Run the points missing from OUTPUT/sweep.csv and append each as it finishes.

    Returns the execution report, the number of points skipped (already in the file) and
    the number of failed points in the whole sweep (recorded before or now).
    ``start_method`` is how a LocalCluster starts its workers (``cluster.start_method``).
    With neither ``workers`` nor ``scheduler`` nor ``serial`` the points start at once in
    a local process and a LocalCluster takes over when the work left is worth one
    (``local``).
    """
    client = None
    if scheduler and not serial and stored_count(plan, output) < len(plan.points):
        client = connect(scheduler)  # a scheduler that is down or mismatched: said before the file is touched
    try:
        store = SweepStore(output, plan.parameters, [m.name for m in plan.job.metrics])
        done = store.open()
        store.write_description(plan.description())
    except BaseException:
        if client is not None:
            client.close()
        raise
    todo = [(h, p) for h, p in plan.points if h not in done]
    failed_before = sum(1 for h, _ in plan.points if done.get(h, OK) != OK)
    bar = SweepProgress(len(todo), enabled=progress)

    def record(h: str, point: Point, outcome: Outcome) -> None:
        keep_run(output, h, outcome)  # the run's folder first: a row in the CSV has its folder
        store.append(h, point, outcome.status, outcome.error, outcome.wall_s, outcome.values)
        bar.update(outcome.status == OK)

    try:
        if not todo:
            report = SweepReport()
        else:
            warm_up(plan.job, todo[0][1])
            if serial:
                report = run_serial(plan.job, todo, record)
            elif workers is None and scheduler is None and can_run_locally(start_method):
                report = run_local_first(plan.job, todo, record, method=start_method,
                                         keep=functools.partial(keep_run, output))
            else:
                report = run_dask(plan.job, todo, record, workers=workers, scheduler=scheduler,
                                  method=start_method, client=client)
                client = None  # run_dask closed it
    finally:
        bar.close()
        if client is not None:
            client.close()
        if plan.job.bundle is not None:
            discard(plan.job.bundle.hash)  # this process's copy (warm-up, serial runs)
    return report, len(plan.points) - len(todo), failed_before + report.failed


def keep_run(output: str | Path, h: str, outcome: Outcome) -> None:
    """Save a kept run's results into OUTPUT/runs/<point hash>/ (``keep_results``) and let
    go of them; nothing for an outcome without results."""
    if outcome.results is not None:
        outcome.results.info.setdefault("sweep", {})["point_hash"] = h
        if link_out_of(Path(output) / RUNS, h) is not None:
            raise SweepError(f"{Path(output) / RUNS / h} is a symbolic link out of the sweep folder: the sweep "
                             "writes only inside it (hint: remove the link)")
        outcome.results.save(Path(output) / RUNS / h)
        outcome.results = None


def stored_count(plan: SweepPlan, output: str | Path) -> int:
    """How many of the plan's points OUTPUT/sweep.csv holds (finished, ok or failed)."""
    try:
        held = {row["point_hash"] for row in read_sweep(output)[1]}
    except SweepError:
        return 0
    return sum(h in held for h, _ in plan.points)


@dataclass
class SweepSummary:
    """What ``run_sweep`` did: the sweep's points, those run now (``report``), those already
    in the file, the failed points of the whole sweep, and the file."""

    points: int
    report: SweepReport
    skipped: int
    failed: int
    csv: Path
    wall_s: float = 0.0
    """Seconds from opening the file to the last row (the checks before excluded)."""


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped ``run_sweep``: ``stored`` of the ``total`` points are in ``csv``; the
    same call runs the rest."""

    def __init__(self, stored: int, total: int, csv: Path):
        super().__init__(f"sweep interrupted: {stored} of {total} points are in {csv}")
        self.stored, self.total, self.csv = stored, total, csv


def run_sweep(diagram: str | Path, points: list[Point], metrics: list[str | Metric], output: str | Path, *,
              t_end: str | None = None, workers: int | None = None, scheduler: str | None = None,
              serial: bool = False, trust: bool = False, progress: bool = True,
              axes: dict[str, Any] | None = None, origins: dict[str, str] | None = None,
              start_method: str | None = None, keep_results: bool = False, step: str | None = None) -> SweepSummary:
    """Run the diagram file at every point and append one row per run to OUTPUT/sweep.csv.

    ``points``: dicts of ``block.param`` overrides, all naming the same parameters
    (``points.grid_points``, ``random_points``, ``csv_points`` make them); ``metrics``:
    ``"NAME=EXPR"`` texts (``metrics``) or parsed ``Metric`` objects, one column each;
    ``t_end``: every run's end time as the CLI's ``--t-end`` takes it (default: the
    diagram's). The points run on a new LocalCluster of ``workers`` processes, on the
    workers of a running ``scheduler``, or in this process with ``serial`` (or
    ``workers=0``). By default they start at once in a process forked from this one, and a
    LocalCluster of one worker per core takes over when the runs left are worth starting
    one (``local``): a sweep of a fraction of a second never waits for Dask. Points already in the file are skipped, so calling again resumes; a point
    that fails is recorded as failed and the others go on. ``axes`` is recorded in
    sweep.json; ``origins`` says how each parameter was given, for load errors. ``step``:
    for an SSP (a ``.ssp`` archive or a folder), the step of the components whose SSD
    gives none, as ``--step`` gives it.

    The diagram travels as content: its text and every file it reads go to each worker
    once (``bundle``), so workers need the installed packages but none of the client's
    files or folders. With ``keep_results`` each run's signals.npz and run.json (which
    records the point, its status and metrics under ``sweep``) are written by this
    process into OUTPUT/runs/<point hash>/, a failed run's partial results included.

    Raises ``DiagramError`` or ``SweepError`` before anything runs when the sweep cannot
    work, and ``SweepInterrupted`` on Ctrl-C, with only whole rows in the file.
    """
    for name, flag in (("serial", serial), ("trust", trust), ("progress", progress), ("keep_results", keep_results)):
        boolean(name, flag)
    plan = prepare(diagram, points, parse_metrics(metrics), t_end=None if t_end is None else str(t_end),
                   trust=trust, axes=axes, origins=origins, keep_results=keep_results, step=step)
    t0 = time.perf_counter()
    try:
        report, skipped, failed = execute(plan, output, workers=workers, scheduler=scheduler,
                                          serial=serial or workers == 0, progress=progress,
                                          start_method=start_method)
    except KeyboardInterrupt:
        raise SweepInterrupted(stored_count(plan, output), len(plan.points), Path(output) / SWEEP_CSV) from None
    return SweepSummary(len(plan.points), report, skipped, failed, Path(output) / SWEEP_CSV,
                        time.perf_counter() - t0)
