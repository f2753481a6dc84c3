"""Parameter points of a sweep: grids, random samples and points files.

A point maps ``block.param`` keys to values, exactly what ``load_diagram(overrides=...)``
takes. Grid values are read as YAML (``1e-3``, ``[1, 2]``, ``true``), split at top-level
commas only, so list values survive. A point's hash identifies it across runs of the same
sweep command, which is what resuming relies on.
"""

from __future__ import annotations

import csv
import hashlib
import io
import itertools
import json
import math
import re
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from blocks.limits import MAX_SWEEP_POINTS
from blocks.diagram_file.yaml_source import YamlSourceError, load_yaml_value, read_yaml_file

from .errors import SweepError

Point = dict[str, Any]

_KEY = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*\.[A-Za-z_][A-Za-z0-9_]*(\.([A-Za-z_][A-Za-z0-9_]*|[0-9]+))*$")
"""``block.param``, then keys or list indices as ``--set`` takes them: ``plant.fingers.1.links.0.length``."""
_DIST = re.compile(r"^\s*(uniform|normal)\s*\(\s*([^,()]+?)\s*,\s*([^,()]+?)\s*\)\s*$")
_FLOAT = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)[eE][-+]?\d+$")
"""Exponent numbers YAML 1.1 leaves as strings ('1e-3'): read as the floats they mean."""
DISTRIBUTIONS = ("uniform(a,b)", "normal(mean,std)")


def check_key(key: str, option: str) -> str:
    """``key`` stripped, if it has the ``block.param`` form; else a SweepError naming ``option``."""
    key = key.strip()
    if not _KEY.match(key):
        raise SweepError(f"{option}: {key!r} is not BLOCK.PARAM, e.g. prop.k")
    return key


def parse_value(text: str, where: str) -> Any:
    """One value read as YAML (as ``run --set`` does), '1e-3' included as a number."""
    try:
        value = load_yaml_value(text, where) if text.strip() else None
    except ValueError as exc:
        raise SweepError(str(exc)) from None
    if value is None:
        raise SweepError(f"{where}: empty value")
    if isinstance(value, str) and _FLOAT.match(value):
        return float(value)
    return value


def split_top_level(text: str) -> list[str]:
    """Split at commas that are outside brackets, braces and quotes: '1,[2,3]' -> ['1', '[2,3]']."""
    parts, depth, quote, start = [], 0, "", 0
    for i, ch in enumerate(text):
        if quote:
            quote = "" if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch in "[{(":
            depth += 1
        elif ch in "]})":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return parts


def parse_grid(items: Sequence[str]) -> dict[str, list[Any]]:
    """``["a.k=1,2", "b.x=[0,1],[1,0]"]`` -> {"a.k": [1, 2], "b.x": [[0, 1], [1, 0]]}."""
    axes: dict[str, list[Any]] = {}
    for item in items:
        key, eq, text = item.partition("=")
        if not eq:
            raise SweepError(f"--grid {item!r}: expected BLOCK.PARAM=V1,V2,..., e.g. --grid prop.k=1,2,4")
        key = check_key(key, f"--grid {item!r}")
        if key in axes:
            raise SweepError(f"--grid {item!r}: {key} is already an axis")
        axes[key] = [parse_value(v, f"--grid {key}") for v in split_top_level(text)]
    return axes


def check_count(count: int, what: str) -> None:
    """Refuse a sweep of more than MAX_SWEEP_POINTS points before any is made."""
    if count > MAX_SWEEP_POINTS:
        raise SweepError(f"{what} make {count:.4g} points, more than a sweep may have ({MAX_SWEEP_POINTS}) "
                         "(hint: fewer values per axis, or split the study into several sweeps)")


def grid_points(axes: dict[str, list[Any]]) -> list[Point]:
    """The cartesian product of the axes, the last axis varying fastest (at most
    MAX_SWEEP_POINTS points)."""
    check_count(math.prod(len(v) for v in axes.values()), f"the --grid axes ({' x '.join(str(len(v)) for v in axes.values())})")
    keys = list(axes)
    return [dict(zip(keys, values)) for values in itertools.product(*(axes[k] for k in keys))]


def parse_random(items: Sequence[str]) -> dict[str, tuple[str, float, float]]:
    """``["a.k=uniform(0, 2)"]`` -> {"a.k": ("uniform", 0.0, 2.0)}."""
    dists: dict[str, tuple[str, float, float]] = {}
    for item in items:
        key, eq, text = item.partition("=")
        where = f"--random {item!r}"
        if not eq:
            raise SweepError(f"{where}: expected BLOCK.PARAM=uniform(a,b) or BLOCK.PARAM=normal(mean,std)")
        key = check_key(key, where)
        m = _DIST.match(text)
        if not m:
            raise SweepError(f"{where}: unknown distribution {text.strip()!r}; use {' or '.join(DISTRIBUTIONS)}")
        try:
            a, b = float(m.group(2)), float(m.group(3))
        except ValueError:
            raise SweepError(f"{where}: the distribution's arguments must be numbers") from None
        if not (math.isfinite(a) and math.isfinite(b)) or (m.group(1) == "uniform" and not math.isfinite(b - a)):
            raise SweepError(f"{where}: the distribution's arguments must be finite numbers whose difference "
                             "is finite too")
        if m.group(1) == "uniform" and not a < b:
            raise SweepError(f"{where}: uniform(a,b) needs a < b")
        if m.group(1) == "normal" and not b > 0:
            raise SweepError(f"{where}: normal(mean,std) needs std > 0")
        if key in dists:
            raise SweepError(f"{where}: {key} is already sampled")
        dists[key] = (m.group(1), a, b)
    return dists


def random_points(dists: dict[str, tuple[str, float, float]], samples: int, seed: int) -> list[Point]:
    """``samples`` points drawn independently per parameter; the same seed gives the same points.

    Each parameter draws its whole column in the order given, so adding a parameter after
    the others leaves their values unchanged.
    """
    if samples < 1:
        raise SweepError(f"--samples must be at least 1, got {samples}")
    check_count(samples, f"--samples {samples}")
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise SweepError(f"--seed must be a whole number of 0 or more, got {seed!r}")
    rng = np.random.default_rng(seed)
    columns = {}
    for key, (kind, a, b) in dists.items():
        draw = rng.uniform(a, b, samples) if kind == "uniform" else rng.normal(a, b, samples)
        columns[key] = [float(v) for v in draw]
    return [{k: columns[k][i] for k in dists} for i in range(samples)]


def csv_points(path: Path) -> list[Point]:
    """Points from a CSV file whose header names ``block.param`` columns; cells read as YAML."""
    try:
        reader = csv.reader(io.StringIO(read_yaml_file(path, "CSV"), newline=""))
        rows = list(reader)
    except FileNotFoundError:
        raise SweepError(f"--points {path}: no such file") from None
    except YamlSourceError as exc:
        where = f"{path}:{exc.line}" if exc.line else str(path)
        raise SweepError(f"--points {where}: {exc.message}" + (f" (hint: {exc.hint})" if exc.hint else "")) from None
    except csv.Error as exc:
        raise SweepError(f"--points {path}:{reader.line_num}: not CSV: {exc} (hint: a cell holds one "
                         "value; quote cells that contain commas)") from None
    if not rows or not any(cell.strip() for cell in rows[0]):
        raise SweepError(f"--points {path}: empty file; the first line names the BLOCK.PARAM columns")
    keys = [check_key(k, f"--points {path}: column") for k in rows[0]]
    if len(set(keys)) != len(keys):
        raise SweepError(f"--points {path}: a column name appears twice")
    points = []
    for n, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) != len(keys):
            raise SweepError(f"--points {path}:{n}: {len(row)} values for {len(keys)} columns")
        check_count(len(points) + 1, f"--points {path}: the rows")
        points.append({k: parse_value(v, f"--points {path}:{n}: column {k}") for k, v in zip(keys, row)})
    if not points:
        raise SweepError(f"--points {path}: no rows after the header")
    return points


def origins(grid: Sequence[str], random: Sequence[str], points_file: Path | None,
            points: Sequence[Point]) -> dict[str, str]:
    """How the user gave each swept parameter, for the loader's messages about it (instead
    of '--set'): the ``--grid`` or ``--random`` item as typed, or the points file's header
    line and column that name it."""
    if points_file is not None:
        return {key: f"--points {points_file}:1: column '{key}'" for key in (points[0] if points else ())}
    return {item.partition("=")[0].strip(): f"{option} {item}"
            for option, items in (("--grid", grid), ("--random", random)) for item in items}


def combine(grid: list[Point], sampled: list[Point]) -> list[Point]:
    """Every grid point with every random sample (either list may be empty)."""
    if not grid:
        return sampled
    if not sampled:
        return grid
    check_count(len(grid) * len(sampled), f"{len(grid)} grid points crossed with {len(sampled)} samples")
    return [{**g, **s} for g in grid for s in sampled]


def point_json(point: Point) -> str:
    """A point as canonical JSON: sorted keys, no spaces; values JSON cannot hold become strings."""
    return json.dumps(point, sort_keys=True, separators=(",", ":"), default=str)


def point_hash(diagram_hash: str, point: Point, t_end: str | None = None) -> str:
    """sha256 of the diagram's hash, the sorted point as JSON and the ``--t-end`` given, if any.

    The end time is part of the identity because the same parameters run for a different
    time are a different result.
    """
    text = diagram_hash + point_json(point) + ("" if t_end is None else f"|t_end={t_end}")
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def unique_points(points: list[Point], diagram_hash: str, t_end: str | None) -> list[tuple[str, Point]]:
    """(hash, point) pairs in order, repeated points kept once."""
    seen: dict[str, Point] = {}
    for p in points:
        seen.setdefault(point_hash(diagram_hash, p, t_end), p)
    return list(seen.items())
