"""A page's pixels: an RGB image with the few things a signal plot draws on it (text in
DejaVu Sans at any of four quarter turns, lines solid or dashed, boxes and dots, with
alpha), written as PNG.

Signal plots are drawn with Pillow rather than matplotlib: every line of a step plot is
horizontal or vertical, so nothing needs more than Pillow's lines and FreeType's text,
and a page costs a tenth of matplotlib's time (its import alone took as long as a short
run). The font is matplotlib's DejaVu Sans, found without importing matplotlib, so the
pages read like the project's other figures; Pillow's own font stands in without it.
"""

from __future__ import annotations

import functools
import importlib.util
from pathlib import Path
from typing import BinaryIO

import numpy as np
from PIL import Image, ImageDraw, ImageFont

DPI = 110
"""Pixels per inch of a page (its PNG says so too)."""

PNG = {"compress_level": 3}
"""PNG settings: a faster deflate than the default 6, for a few percent more bytes."""

MOST_DASHES = 40_000
"""A dashed line of more dashes than this is drawn solid: its dashes could not be told apart."""

Colour = tuple[int, int, int] | tuple[int, int, int, int]

TAB10 = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
         "#bcbd22", "#17becf"]
NAMED = {"black": "#000000", "white": "#ffffff", "dimgray": "#696969", "tab:red": "#d62728",
         "grid": "#b0b0b0"}


def rgb(colour: str, alpha: float = 1.0) -> Colour:
    """A colour (``C0``..``C9``, a name of ``NAMED``, ``#rrggbb``) as RGB, or RGBA below alpha 1."""
    if len(colour) == 2 and colour[0] == "C" and colour[1].isdigit():
        colour = TAB10[int(colour[1])]
    colour = NAMED.get(colour, colour)
    value = tuple(int(colour[i:i + 2], 16) for i in (1, 3, 5))
    return value if alpha >= 1.0 else (*value, round(255 * alpha))


def points(size_pt: float) -> float:
    """A length in points (1/72 inch) in pixels."""
    return size_pt * DPI / 72.0


def font_file() -> Path | None:
    """matplotlib's DejaVu Sans, located without importing matplotlib (None if absent)."""
    spec = importlib.util.find_spec("matplotlib")
    for folder in (spec.submodule_search_locations or []) if spec else []:
        path = Path(folder, "mpl-data", "fonts", "ttf", "DejaVuSans.ttf")
        if path.is_file():
            return path
    return None


@functools.lru_cache(maxsize=None)
def font(size_pt: float) -> ImageFont.FreeTypeFont | ImageFont.ImageFont:
    """The page's font at ``size_pt`` points."""
    pixels = round(points(size_pt))
    path = font_file()
    if path is None:
        return ImageFont.load_default(pixels)
    return ImageFont.truetype(str(path), pixels, layout_engine=ImageFont.Layout.BASIC)


LINE_SPACING = 1.2
"""A text's line pitch in units of its size."""


def text_size(text: str, size_pt: float) -> tuple[float, float]:
    """(width, height) in pixels of ``text`` (lines split at newlines), unrotated."""
    f = font(size_pt)
    lines = text.split("\n")
    return max(f.getlength(line) for line in lines), _pitch(size_pt) * len(lines)


ELLIPSIS = "\u2026"


def fit(text: str, width: float, size_pt: float, lines: int = 1) -> str:
    """``text`` wrapped (at spaces where it can, within words where it must) into lines
    at most ``width`` pixels wide, at most ``lines`` of them, the last cut short with an
    ellipsis if the text is longer: what fits where a label has to go."""
    f = font(size_pt)
    out: list[str] = []
    rest = " ".join(text.split())
    while rest and len(out) < lines:
        if f.getlength(rest) <= width:
            out.append(rest)
            rest = ""
            break
        cut = _longest_fitting(rest, width, f)
        space = rest.rfind(" ", 0, cut + 1)
        if space > 0:
            cut = space
        out.append(rest[:cut].rstrip())
        rest = rest[cut:].lstrip()
    if rest:
        last = out[-1] if out else ""
        while last and f.getlength(last + ELLIPSIS) > width:
            last = last[:-1]
        out[-1:] = [last.rstrip() + ELLIPSIS]
    return "\n".join(out)


def _longest_fitting(text: str, width: float, f) -> int:
    """How many of ``text``'s first characters fit in ``width`` pixels (at least one)."""
    lo, hi = 1, len(text)
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if f.getlength(text[:mid]) <= width:
            lo = mid
        else:
            hi = mid - 1
    return lo


def _pitch(size_pt: float) -> float:
    return LINE_SPACING * points(size_pt)


class Canvas:
    """An RGB page of ``width`` x ``height`` pixels, white, drawn on in pixel coordinates
    (x right, y down)."""

    def __init__(self, width: int, height: int):
        self.image = Image.new("RGB", (width, height), "white")
        self._draw = ImageDraw.Draw(self.image, "RGBA")

    def box(self, x0: float, y0: float, x1: float, y1: float, fill: Colour | None = None,
            outline: Colour | None = None, width: int = 1) -> None:
        """A rectangle from (x0, y0) to (x1, y1), filled and/or outlined."""
        self._draw.rectangle([round(x0), round(y0), round(x1), round(y1)], fill=fill, outline=outline, width=width)

    def dot(self, x: float, y: float, radius: float, fill: Colour) -> None:
        self._draw.ellipse([x - radius, y - radius, x + radius, y + radius], fill=fill)

    def line(self, xy: np.ndarray, colour: Colour, width: int = 1, dashes: tuple[float, ...] | None = None) -> None:
        """A polyline through the rows of ``xy`` (pixels, rounded to the nearest: Pillow
        would truncate); rows with a non-finite coordinate break it. ``dashes``: lengths on, off (, on, off) in pixels."""
        for piece in _finite_pieces(xy):
            for run in (_dashed(piece, dashes) if dashes else [piece]):
                if len(run) >= 2:
                    self._draw.line(np.rint(run).ravel().tolist(), fill=colour, width=width, joint="curve" if width > 1 else None)

    def text(self, x: float, y: float, text: str, size_pt: float, colour: Colour = (0, 0, 0),
             ha: str = "left", va: str = "top", rotation: int = 0, backdrop: Colour | None = None) -> tuple[float, ...]:
        """``text`` (lines split at newlines, each centred in a centred block) placed so
        that its box's ``ha`` (left, center, right) and ``va`` (top, center, bottom) edge
        is at (x, y), turned ``rotation`` degrees counterclockwise (0 or 90); on a
        ``backdrop`` box if given. Returns the box it took (x0, y0, x1, y1)."""
        w, h = text_size(text, size_pt)
        bw, bh = (w, h) if rotation == 0 else (h, w)
        x0 = x - {"left": 0.0, "center": bw / 2, "right": bw}[ha]
        y0 = y - {"top": 0.0, "center": bh / 2, "bottom": bh}[va]
        if backdrop is not None:
            pad = points(1.0)
            self.box(x0 - pad, y0 - pad, x0 + bw + pad, y0 + bh + pad, fill=backdrop)
        if rotation == 0:
            self._lines(self._draw, x0, y0, text, size_pt, colour, w, ha)
        else:
            mask = Image.new("L", (max(1, round(w)), max(1, round(h))), 0)
            self._lines(ImageDraw.Draw(mask), 0.0, 0.0, text, size_pt, 255, w, "center")
            mask = mask.transpose(Image.Transpose.ROTATE_90)
            self.image.paste(Image.new("RGB", mask.size, colour[:3]), (round(x0), round(y0)), mask)
        return x0, y0, x0 + bw, y0 + bh

    @staticmethod
    def _lines(draw: ImageDraw.ImageDraw, x0: float, y0: float, text: str, size_pt: float, colour,
               width: float, align: str) -> None:
        f = font(size_pt)
        pitch = _pitch(size_pt)
        for k, line in enumerate(text.split("\n")):
            lw = f.getlength(line)
            dx = {"left": 0.0, "center": (width - lw) / 2, "right": width - lw}[align]
            draw.text((x0 + dx, y0 + k * pitch + pitch / 2), line, fill=colour, font=f, anchor="lm")

    def paste(self, other: "Canvas", x: int, y: int) -> None:
        self.image.paste(other.image, (x, y))

    def crop(self, x0: int, y0: int, x1: int, y1: int) -> "Canvas":
        """A new canvas of this one's pixels in the box: drawn on, then pasted back, it
        clips what is drawn to the box."""
        part = Canvas.__new__(Canvas)
        part.image = self.image.crop((x0, y0, x1, y1))
        part._draw = ImageDraw.Draw(part.image, "RGBA")
        return part

    def save(self, file: Path | BinaryIO) -> None:
        """The page as PNG, into a file or a binary stream."""
        self.image.save(file, format="PNG", dpi=(DPI, DPI), **PNG)


def _finite_pieces(xy: np.ndarray) -> list[np.ndarray]:
    """The runs of rows of ``xy`` whose coordinates are all finite."""
    good = np.isfinite(xy).all(axis=1)
    if good.all():
        return [xy]
    edges = np.flatnonzero(np.diff(np.r_[False, good, False].astype(np.int8)))
    return [xy[a:b] for a, b in zip(edges[::2], edges[1::2])]


def _dashed(xy: np.ndarray, dashes: tuple[float, ...]) -> list[np.ndarray]:
    """The 'on' runs of a polyline cut by a dash pattern (lengths on, off, ...), or the
    polyline whole if it would be more than MOST_DASHES dashes."""
    steps = np.hypot(*np.diff(xy, axis=0).T)
    along = np.r_[0.0, np.cumsum(steps)]
    period = float(sum(dashes))
    total = along[-1]
    if total <= 0 or period <= 0 or total / period * len(dashes) > MOST_DASHES:
        return [xy]
    starts = np.cumsum((0.0,) + tuple(dashes[:-1]))
    cuts = (np.arange(int(total // period) + 1)[:, None] * period + starts[None, :]).ravel()
    s = np.union1d(along, cuts[cuts < total])
    pts = np.column_stack([np.interp(s, along, xy[:, 0]), np.interp(s, along, xy[:, 1])])
    phase = np.searchsorted(np.cumsum(dashes), ((s[:-1] + s[1:]) / 2) % period, side="right")
    on = (phase % 2 == 0) & (np.diff(s) > 0)
    edges = np.flatnonzero(np.diff(np.r_[False, on, False].astype(np.int8)))
    return [pts[a:b + 1] for a, b in zip(edges[::2], edges[1::2])]
