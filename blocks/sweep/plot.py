"""Plots of a finished sweep: a metric over one parameter (lines) or two (heat map).

Only rows with status 'ok' and a value for the metric are plotted, but every parameter
value of the sweep keeps its place on the axes. Over one parameter,
each combination of the other parameters gets its own line (labelled with its values) as
long as there are at most MAX_LINES of them; beyond that the plot shows their mean with a
min-max band, and says so in the title. A heat map averages over the other parameters,
also said in the title; cells without a value stay blank, the others carry their value.
Numeric parameter values keep their true places (cells reach halfway to their neighbours);
values that are not numbers (lists, names) are placed in order of appearance and labelled
as written, the axis saying so. A metric's unit, where sweep.json records one, labels it.
"""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from .errors import SweepError
from .store import FIXED_COLUMNS, OK, read_sweep

MAX_LINES = 8


def _value(cell: str) -> Any:
    try:
        return json.loads(cell)
    except (ValueError, RecursionError):  # not JSON, or nested past the parser's depth
        return cell


def _positions(values: list[Any]) -> tuple[np.ndarray, list[str] | None]:
    """Numeric x positions of the distinct values, and tick labels if they are not numbers."""
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return np.array(values, dtype=float), None
    return np.arange(len(values), dtype=float), [json.dumps(v) for v in values]


def _distinct(values: list[Any]) -> list[Any]:
    out, seen = [], set()
    for v in values:
        key = json.dumps(v, sort_keys=True)
        if key not in seen:
            seen.add(key)
            out.append(v)
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in out):
        out.sort()
    return out


def sweep_table(directory: str | Path, params: list[str], metric: str) -> tuple[list[str], list[dict]]:
    """Every row as a dict of parameter values plus 'metric' (NaN for a failed run or no value); and all parameters."""
    description, rows = read_sweep(directory)
    header = list(rows[0]) if rows else []
    metric_names = list(description.get("metrics", {}))
    parameters = description.get("parameters") or [c for c in header if c not in FIXED_COLUMNS
                                                   and c not in metric_names]
    known = ", ".join(parameters) or "none"
    for p in params:
        if p not in parameters:
            raise SweepError(f"{directory}: no parameter '{p}' in this sweep; parameters: {known}")
    if metric not in header or metric in FIXED_COLUMNS[:3] or metric in parameters:
        names = ", ".join(metric_names or [c for c in header if c not in FIXED_COLUMNS]) or "none"
        raise SweepError(f"{directory}: no metric '{metric}' in this sweep; metrics: {names}")
    table = []
    for r in rows:
        entry = {p: _value(r[p]) for p in parameters}
        try:
            entry["metric"] = float(r[metric]) if r["status"] == OK and r[metric] != "" else float("nan")
        except ValueError:
            raise SweepError(f"{directory}: point {r['point_hash'][:16]!r}: its '{metric}' is not a number "
                             f"({r[metric][:40]!r})") from None
        table.append(entry)
    if all(np.isnan(r["metric"]) for r in table):
        raise SweepError(f"{directory}: no finished run has a value for '{metric}' (failed runs, or the "
                         "event never happened)")
    return parameters, table


def plot_sweep(directory: str | Path, x: str, metric: str, output: str | Path, y: str | None = None) -> Path:
    """Write a line plot (``y`` None) or a heat map of ``metric`` to ``output`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if y is not None and y == x:
        raise SweepError("--x and --y name the same parameter")
    parameters, table = sweep_table(directory, [x] + ([y] if y else []), metric)
    units = read_sweep(directory)[0].get("units") or {}
    others = [p for p in parameters if p not in (x, y)]
    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
    if y is None:
        _lines(ax, table, x, others, metric, units)
    else:
        _heat_map(fig, ax, table, x, y, others, metric, units)
    output = Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(output, dpi=120)
    plt.close(fig)
    return output


def _lines(ax, table: list[dict], x: str, others: list[str], metric: str, units: dict[str, str] | None = None) -> None:
    xs = _distinct([r[x] for r in table])
    pos, labels = _positions(xs)
    index = {json.dumps(v, sort_keys=True): i for i, v in enumerate(xs)}
    groups: dict[str, dict[int, list[float]]] = defaultdict(lambda: defaultdict(list))
    for r in table:
        name = ", ".join(f"{p}={json.dumps(r[p])}" for p in others)
        if not np.isnan(r["metric"]):
            groups[name][index[json.dumps(r[x], sort_keys=True)]].append(r["metric"])
    if len(groups) <= MAX_LINES:
        for name, by_x in groups.items():
            idx = sorted(by_x)
            ax.plot(pos[idx], [np.mean(by_x[i]) for i in idx], marker="o", label=name or metric)
        if others:
            ax.legend(fontsize="small")
        ax.set_title(f"{metric} over {x}" + (f", one line per {', '.join(others)}" if others else ""))
    else:
        merged: dict[int, list[float]] = defaultdict(list)
        for by_x in groups.values():
            for i, vals in by_x.items():
                merged[i].extend(vals)
        idx = sorted(merged)
        mean = [np.mean(merged[i]) for i in idx]
        ax.fill_between(pos[idx], [min(merged[i]) for i in idx], [max(merged[i]) for i in idx], alpha=0.25,
                        label="min-max")
        ax.plot(pos[idx], mean, marker="o", label="mean")
        ax.legend(fontsize="small")
        ax.set_title(f"{metric} over {x}, mean over {len(groups)} combinations of {', '.join(others)}")
    if labels:
        ax.set_xticks(pos, labels)
    ax.set_xlabel(x)
    unit = (units or {}).get(metric)
    ax.set_ylabel(metric + (f" ({unit})" if unit else ""))
    ax.grid(True, alpha=0.3)


MAX_CELL_TEXTS = 400
"""Heat maps of at most this many cells write each cell's value in it."""


def _edges(centres: np.ndarray) -> np.ndarray:
    """Cell edges around sorted distinct values: halfway between neighbours, and half a
    step beyond the first and the last (one value: a cell of width 1 around it)."""
    if len(centres) == 1:
        return np.array([centres[0] - 0.5, centres[0] + 0.5])
    mid = (centres[:-1] + centres[1:]) / 2
    return np.concatenate([[2 * centres[0] - mid[0]], mid, [2 * centres[-1] - mid[-1]]])


def _heat_map(fig, ax, table: list[dict], x: str, y: str, others: list[str], metric: str,
              units: dict[str, str] | None = None) -> None:
    """The metric over x and y: numbers at their true places (cells spanning halfway to
    their neighbours, so 100, 200, 300, 500 are not drawn as equal steps), other values as
    labelled categories in order of appearance, and each cell's value written in it."""
    xs, ys = _distinct([r[x] for r in table]), _distinct([r[y] for r in table])
    xi = {json.dumps(v, sort_keys=True): i for i, v in enumerate(xs)}
    yi = {json.dumps(v, sort_keys=True): i for i, v in enumerate(ys)}
    cells: dict[tuple[int, int], list[float]] = defaultdict(list)
    for r in table:
        if not np.isnan(r["metric"]):
            cells[(yi[json.dumps(r[y], sort_keys=True)], xi[json.dumps(r[x], sort_keys=True)])].append(r["metric"])
    grid = np.full((len(ys), len(xs)), np.nan)
    for (i, j), vals in cells.items():
        grid[i, j] = np.mean(vals)
    (px, x_labels), (py, y_labels) = _positions(xs), _positions(ys)
    image = ax.pcolormesh(_edges(px), _edges(py), np.ma.masked_invalid(grid), cmap="viridis", shading="flat")
    unit = (units or {}).get(metric)
    fig.colorbar(image, ax=ax, label=metric + (f" ({unit})" if unit else ""))
    if grid.size <= MAX_CELL_TEXTS:
        low, high = np.nanmin(grid), np.nanmax(grid)
        for (i, j), value in np.ndenumerate(grid):
            if np.isfinite(value):
                bright = high > low and (value - low) / (high - low) > 0.6
                ax.text(px[j], py[i], f"{value:.3g}", ha="center", va="center", fontsize="x-small",
                        color="black" if bright else "white")
    ax.set_xticks(px, x_labels or [f"{v:g}" for v in px], rotation=45 if len(xs) > 6 else 0)
    ax.set_yticks(py, y_labels or [f"{v:g}" for v in py])
    ax.set_xlabel(x + (" (categories, in order of appearance)" if x_labels else ""))
    ax.set_ylabel(y + (" (categories, in order of appearance)" if y_labels else ""))
    ax.set_title(f"{metric} over {x} and {y}" + (f" (mean over {', '.join(others)})" if others else "")
                 + ("; blank: no value" if np.isnan(grid).any() else ""))
