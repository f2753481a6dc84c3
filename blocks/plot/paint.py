"""A laid-out page (``blocks.plot.page_layout``) in pixels: grid, bands and lines of the diagram's
events, step curves clipped to their panel, frames, ticks and labels, legends, and a
failed run's stop with its last samples, in the order that keeps the data on top of the
grid and bands and under nothing but the frame."""

from __future__ import annotations

import numpy as np

from blocks.plot.canvas import Canvas, fit, points, rgb
from blocks.plot.markers import MARKER_COLOUR
from blocks.plot.page_layout import (
    LABEL_PAD,
    LARGE,
    LEGEND_COLUMN,
    LEGEND_HANDLE,
    LEGEND_PAD,
    LEGEND_PITCH,
    SIZE,
    SMALL,
    TICK_LENGTH,
    TICK_PAD,
    X_SMALL,
    Page,
    Panel,
)

BLACK = (0, 0, 0)
GRID = rgb("grid", 0.3)
BAND = rgb(MARKER_COLOUR, 0.08)
RED = rgb("tab:red")
DOT_RADIUS = 2.4   # points: a stop's dot on an element's last sample
DASHES = {"-": None, "--": (3.7, 1.6), ":": (1.0, 1.65), "-.": (6.4, 1.6, 1.0, 1.6)}
"""Dash patterns in units of the line's width, matplotlib's (a little longer: lines are thinner)."""


def paint(page: Page) -> Canvas:
    """The page drawn."""
    canvas = Canvas(page.width, page.height)
    for panel in page.panels:
        _panel(canvas, page, panel)
    first = page.panels[0]
    for m in page.markers:
        x, _ = first.to_pixels(m.start, 0.0)
        if first.box[0] <= x <= first.box[2]:
            label = fit(m.label, first.box[3] - first.box[1] - points(4), X_SMALL)
            canvas.text(x + points(2), first.box[1] + points(2), label, X_SMALL, rgb(MARKER_COLOUR),
                        ha="left", va="top", rotation=90, backdrop=rgb("white", 0.7))
    if page.stop is not None:
        x, _ = first.to_pixels(page.stop, 0.0)
        canvas.text(x, first.box[1] - points(3), page.stop_word, SMALL, RED, ha="right", va="bottom")
    canvas.text(page.width / 2, points(0.12 * 72), page.title, LARGE, ha="center", va="top")
    return canvas


def _panel(canvas: Canvas, page: Page, panel: Panel) -> None:
    x0, y0, x1, y1 = (round(c) for c in panel.box)
    inner = canvas.crop(x0, y0, x1 + 1, y1 + 1)
    shift = np.array([x0, y0], dtype=float)
    xt, _ = panel.to_pixels(panel.xticks.values, 0.0)
    _, yt = panel.to_pixels(0.0, panel.yticks.values)
    for x in xt:
        inner.box(x - x0, 0, x - x0, y1 - y0, fill=GRID)
    for y in yt:
        inner.box(0, y - y0, x1 - x0, y - y0, fill=GRID)
    for m in page.markers:
        a, _ = panel.to_pixels(m.start, 0.0)
        if m.instant:
            inner.line(np.array([[a, y0], [a, y1]]) - shift, rgb(MARKER_COLOUR), 1, _dashes(":", 1))
        else:
            b, _ = panel.to_pixels(m.end, 0.0)
            inner.box(a - x0, 0, b - x0, y1 - y0, fill=BAND)
    for curve in panel.curves:
        x, y = panel.to_pixels(curve.t, curve.v)
        steps = np.column_stack([np.repeat(x, 2)[1:], np.repeat(y, 2)[:-1]]) - shift
        width = line_width(curve.style["lw"])
        inner.line(np.clip(steps, -1e5, 1e5), rgb(curve.style["color"]), width, _dashes(curve.style["ls"], width))
    if page.stop is not None:
        a, _ = panel.to_pixels(page.stop, 0.0)
        inner.line(np.array([[a, y0], [a, y1]]) - shift, RED, 1, _dashes("--", 1.5))
    canvas.paste(inner, x0, y0)
    canvas.box(x0, y0, x1, y1, outline=BLACK)
    _ticks(canvas, page, panel, xt, yt)
    for t, values in panel.dots:
        xs, ys = panel.to_pixels(np.full(len(values), t), values)
        for x, y in zip(xs, ys):
            if np.isfinite(y):
                canvas.dot(x, y, points(DOT_RADIUS), RED)
    if panel.legend_box is not None:
        _legend(canvas, panel)


def _ticks(canvas: Canvas, page: Page, panel: Panel, xt: np.ndarray, yt: np.ndarray) -> None:
    x0, y0, x1, y1 = panel.box
    length, pad = points(TICK_LENGTH), points(TICK_LENGTH + TICK_PAD)
    for x in xt:
        canvas.box(x, y1, x, y1 + length, fill=BLACK)
    widest = 0.0
    for y, label in zip(yt, panel.yticks.labels):
        canvas.box(x0 - length, y, x0, y, fill=BLACK)
        box = canvas.text(x0 - pad, y, label, SIZE, ha="right", va="center")
        widest = max(widest, box[2] - box[0])
    if panel.yticks.offset:
        canvas.text(x0, y0 - points(2), panel.yticks.offset, SIZE, ha="left", va="bottom")
    canvas.text(x0 - pad - widest - points(LABEL_PAD), (y0 + y1) / 2, panel.ylabel, SIZE,
                ha="right", va="center", rotation=90)
    if panel.time_labels:
        bottom = y1 + pad
        for x, label in zip(xt, panel.xticks.labels):
            box = canvas.text(x, y1 + pad, label, SIZE, ha="center", va="top")
            bottom = max(bottom, box[3])
        if panel.xticks.offset:
            canvas.text(x1, bottom, panel.xticks.offset, SIZE, ha="right", va="top")
        canvas.text((x0 + x1) / 2, bottom + points(LABEL_PAD), page.time_label, SIZE, ha="center", va="top")


def _legend(canvas: Canvas, panel: Panel) -> None:
    left, top, _, _ = panel.legend_box
    em = points(SMALL)
    rows = -(-len(panel.legend) // panel.legend_columns)
    column = (panel.legend_box[2] - left + LEGEND_COLUMN * em) / panel.legend_columns
    for k, curve in enumerate(panel.legend):
        x = left + (k // rows) * column
        y = top + (k % rows + 0.5) * LEGEND_PITCH * em
        width = line_width(curve.style["lw"])
        canvas.line(np.array([[x, y], [x + LEGEND_HANDLE * em, y]]), rgb(curve.style["color"]), width,
                    _dashes(curve.style["ls"], width))
        canvas.text(x + (LEGEND_HANDLE + LEGEND_PAD) * em, y, curve.label, SMALL, ha="left", va="center")


def line_width(lw: float) -> int:
    """A line width in points as whole pixels (at least one): 2.2 points is 3 pixels,
    1.6 is 2, 1.0 is 1, so that lines drawn wider under narrower ones still show."""
    return max(1, round(points(lw) - 0.3))


def _dashes(style: str, width: float) -> tuple[float, ...] | None:
    pattern = DASHES[style]
    return None if pattern is None else tuple(1.4 * d * max(width, 1.5) for d in pattern)
