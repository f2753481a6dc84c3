"""The wiring drawn with matplotlib: boxes with their ports, wires routed port to port, loops
in channels, and (expanded) each subsystem a frame around its blocks."""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from blocks.builder.diagram import Diagram
from blocks.engine.schedule import Schedule
from .layout import Layered, group_of, layered
from .ports import input_ports, output_ports
from .rates import tint
from .view import DISABLED, Frame, Picture, picture


# All lengths in inches; y grows downwards while laying out (the axes are flipped).

FONT = 9.0          # port names
TITLE_FONT = 10.0   # block names
SMALL_FONT = 8.0    # type and rate
ROW = 0.25          # one port row
HEADER = 0.62       # name, type and rate above the ports
NOTE_ROW = 0.19     # one line of a box's notes (its parameters), below the ports
DISABLED_COLOUR = "tab:red"
PAD = 0.1           # inside the box, left and right of the port names
V_GAP = 0.45        # between boxes of a layer
WAYPOINT = 0.16     # height a passing wire takes in a layer
LANE = 0.14         # between the vertical runs of the wires that go back
CHANNEL = 0.2       # between the horizontal runs of the wires that go back
FRAME_HEAD = 0.32   # a frame's label above the boxes in it
FRAME_PAD = 0.14    # between a frame and what it holds (and a frame inside it)


@functools.lru_cache(maxsize=4096)
def text_width(text: str, size: float, bold: bool = False) -> float:
    """Width in inches of ``text`` in the default font at ``size`` points (its glyphs'
    advances, as the renderer lays them out; remembered, since a picture asks often)."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import text_to_path

    if not text:
        return 0.0
    prop = FontProperties(size=size, weight="bold" if bold else "normal")
    width, _, _ = text_to_path.get_text_width_height_descent(text, prop, ismath=False)
    return width / 72.0 + 0.02


@dataclass
class Box:
    x: float
    y: float
    w: float
    h: float
    inputs: list[str]
    outputs: list[str]

    def in_anchor(self, port: str) -> tuple[float, float]:
        return self.x, self.y + HEADER + (self.inputs.index(port) + 0.5) * ROW

    def out_anchor(self, port: str) -> tuple[float, float]:
        return self.x + self.w, self.y + HEADER + (self.outputs.index(port) + 0.5) * ROW


@dataclass
class Geometry:
    boxes: dict[str, Box]
    waypoints: dict[tuple[int, int], tuple[float, float, float]]
    """(connection index, layer) -> (x left, x right, y) of a wire passing that layer."""
    column_x: list[tuple[float, float]]
    lanes: dict[tuple[int, str], float]
    """(connection index, "src"|"dst") -> x of a returning wire's vertical run."""
    channels: dict[int, float]
    """connection index -> y of a returning wire's horizontal run."""
    bounds: tuple[float, float, float, float]
    frames: dict[str, tuple[float, float, float, float]] = None
    """subsystem path -> (x, y, w, h) of its frame (expanded pictures)."""


def geometry(picture: Picture, lay: Layered) -> Geometry:
    sizes = {}
    for name, node in picture.nodes.items():
        ins, outs = input_ports(picture, name), output_ports(picture, name)
        in_w = max((text_width(p, FONT) for p in ins), default=0.0)
        out_w = max((text_width(p, FONT) for p in outs), default=0.0)
        head = max(text_width(name, TITLE_FONT, bold=True), text_width(node.type_line, SMALL_FONT),
                   text_width(node.rate_line, SMALL_FONT), *(text_width(n, SMALL_FONT) for n in node.notes))
        w = max(head + 2 * PAD, in_w + out_w + 2 * PAD + 0.35, 1.0)
        h = HEADER + max(len(ins), len(outs), 1) * ROW + 0.08 + (len(node.notes) * NOTE_ROW + 0.04 if node.notes else 0)
        sizes[name] = (w, h, ins, outs)
    conns = picture.wires
    index = {id(c): i for i, c in enumerate(conns)}
    fb = [index[id(c)] for c in lay.feedback]
    n_layers = len(lay.columns)
    # returning wires: above or below, nested so the wider ones run outside
    widths = [max((sizes[it][0] for it in col if isinstance(it, str)), default=0.6) for col in lay.columns]
    gaps_src = [0] * (n_layers + 1)   # lanes right of layer k used by sources there
    gaps_dst = [0] * (n_layers + 1)   # lanes left of layer k used by targets there
    for i in fb:
        gaps_src[lay.layer[conns[i].src_block]] += 1
        gaps_dst[lay.layer[conns[i].dst_block]] += 1
    n_wires = [0] * n_layers
    for i, c in enumerate(conns):
        if i not in fb:
            for k in range(lay.layer[c.src_block], lay.layer[c.dst_block]):
                n_wires[k] += 1
    column_x = []
    x = 0.45 + gaps_dst[0] * LANE if n_layers else 0.0
    for k in range(n_layers):
        column_x.append((x, x + widths[k]))
        if k + 1 < n_layers:
            x += widths[k] + 1.1 + 0.04 * n_wires[k] + (gaps_src[k] + gaps_dst[k + 1]) * LANE
    # vertical placement: each item near the wires that feed it, in the order found
    boxes: dict[str, Box] = {}
    waypoints: dict[tuple[int, int], tuple[float, float, float]] = {}
    anchor_y: dict[object, dict] = {}

    def height(item):
        return sizes[item][1] if isinstance(item, str) else WAYPOINT

    def feed_y(item):
        """The y of the item's wired inputs, relative to its top, and where they come from."""
        own, other = [], []
        for i, c in enumerate(conns):
            if i in fb:
                continue
            if isinstance(item, str) and c.dst_block == item:
                src_item = c.src_block if lay.layer[c.src_block] == lay.layer[item] - 1 else (i, lay.layer[item] - 1)
                own.append(HEADER + (sizes[item][2].index(c.dst_port) + 0.5) * ROW)
            elif not isinstance(item, str) and i == item[0]:
                k = item[1]
                src_item = c.src_block if lay.layer[c.src_block] == k - 1 else (i, k - 1)
                own.append(WAYPOINT / 2)
            else:
                continue
            if src_item in anchor_y:
                other.append(anchor_y[src_item].get(c.src_port if isinstance(src_item, str) else None))
            else:
                own.pop()
        pairs = [(o, t) for o, t in zip(own, other) if t is not None]
        if not pairs:
            return None
        return float(np.mean([t - o for o, t in pairs]))

    def gap(item, below) -> float:
        boxes_both = isinstance(item, str) + isinstance(below, str)
        return (V_GAP, 0.22, 0.04)[2 - boxes_both]

    bands = frame_bands(picture, lay, height, gap) if picture.frames else None
    for k, col in enumerate(lay.columns):
        if bands is not None:
            tops, y, shift = [], None, 0.0
            for j, item in enumerate(col):
                group = group_of(picture, item)
                same = j and group_of(picture, col[j - 1]) == group
                y = y + height(col[j - 1]) + gap(col[j - 1], item) if same else bands[group]
                tops.append(y)
        else:
            desired = []
            for item in col:
                want = feed_y(item) if k else None
                desired.append(want)
            tops, y = [], 0.0
            for j, item in enumerate(col):
                want = desired[j]
                top = y if want is None else max(want, y)
                tops.append(top)
                if j + 1 < len(col):
                    y = top + height(item) + gap(item, col[j + 1])
            placed = [(tops[j] - desired[j]) for j in range(len(col)) if desired[j] is not None]
            shift = float(np.median(placed)) if placed else 0.0
            shift = min(shift, tops[0] - min(0.0, tops[0])) if tops else 0.0
        for j, item in enumerate(col):
            top = tops[j] - shift
            x0, x1 = column_x[k]
            if isinstance(item, str):
                w, h, ins, outs = sizes[item]
                cx = (x0 + x1) / 2
                box = boxes[item] = Box(cx - w / 2, top, w, h, ins, outs)
                anchor_y[item] = {p: box.out_anchor(p)[1] for p in outs}
            else:
                waypoints[item] = (x0, x1, top + WAYPOINT / 2)
                anchor_y[item] = {None: top + WAYPOINT / 2}
    # make the first layers' tops start at 0
    all_tops = [b.y for b in boxes.values()] + [w[2] - WAYPOINT / 2 for w in waypoints.values()]
    lift = min(all_tops, default=0.0)
    for b in boxes.values():
        b.y -= lift
    waypoints = {key: (a, b, y - lift) for key, (a, b, y) in waypoints.items()}
    top = 0.0
    bottom = max((b.y + b.h for b in boxes.values()), default=0.0)
    bottom = max([bottom] + [w[2] + WAYPOINT for w in waypoints.values()])
    # the returning wires' channels and lanes
    lanes: dict[tuple[int, str], float] = {}
    channels: dict[int, float] = {}
    above, below = [], []
    for i in fb:
        c = conns[i]
        ys = (boxes[c.src_block].out_anchor(c.src_port)[1], boxes[c.dst_block].in_anchor(c.dst_port)[1])
        (above if np.mean(ys) - top < bottom - np.mean(ys) else below).append(i)

    def span(i):
        c = conns[i]
        return boxes[c.src_block].x + boxes[c.src_block].w - boxes[c.dst_block].x

    for group, sign, edge in ((above, -1, top), (below, 1, bottom)):
        group.sort(key=span)
        for j, i in enumerate(group):
            channels[i] = edge + sign * (0.3 + j * CHANNEL)
    nested = sorted(fb, key=lambda i: (i in above, span(i)))
    used_src: dict[int, int] = {}
    used_dst: dict[int, int] = {}
    for i in nested:
        c = conns[i]
        ks, kd = lay.layer[c.src_block], lay.layer[c.dst_block]
        lanes[(i, "src")] = column_x[ks][1] + 0.2 + used_src.get(ks, 0) * LANE
        used_src[ks] = used_src.get(ks, 0) + 1
        lanes[(i, "dst")] = column_x[kd][0] - 0.3 - used_dst.get(kd, 0) * LANE
        used_dst[kd] = used_dst.get(kd, 0) + 1
    frames = frame_boxes(picture, boxes, waypoints, lay)
    ys = [top, bottom] + list(channels.values()) + [f[1] for f in frames.values()] + \
        [f[1] + f[3] for f in frames.values()]
    xs = [0.0, column_x[-1][1] if column_x else 1.0] + list(lanes.values()) + [f[0] for f in frames.values()] + \
        [f[0] + f[2] for f in frames.values()]
    return Geometry(boxes, waypoints, column_x, lanes, channels, (min(xs), max(xs), min(ys), max(ys)), frames)


def frame_bands(picture: Picture, lay: Layered, height, gap) -> dict[str, float]:
    """The top of each frame's band (``""``: the boxes outside every frame): the bands are
    stacked in the layout's order of frames, each as tall as its tallest column, with room
    for a frame's label above and its border below."""
    order = [""] + [f.path for f in picture.frames]
    tall = dict.fromkeys(order, 0.0)
    for col in lay.columns:
        run: dict[str, float] = {}
        for j, item in enumerate(col):
            group = group_of(picture, item)
            extra = gap(col[j - 1], item) if j and group_of(picture, col[j - 1]) == group else 0.0
            run[group] = run.get(group, 0.0) + extra + height(item)
        for group, h in run.items():
            tall[group] = max(tall[group], h)
    tops: dict[str, float] = {}
    y = 0.0
    for i, group in enumerate(order):
        y += FRAME_HEAD if group else 0.0
        tops[group] = y
        y += tall[group]
        after = order[i + 1] if i + 1 < len(order) else None
        closing = sum(1 for f in order[1:] if group and (group == f or group.startswith(f + "."))
                      and not (after and (after == f or after.startswith(f + "."))))
        y += V_GAP + closing * FRAME_PAD
    return tops


def frame_boxes(picture: Picture, boxes: dict, waypoints: dict, lay: Layered) -> dict[str, tuple]:
    """Each frame's rectangle: around its boxes (and the wires that pass in its band), a
    frame holding another one ``FRAME_PAD`` further out."""
    out: dict[str, tuple] = {}
    for frame in sorted(picture.frames, key=lambda f: -f.depth):
        parts = [(b.x, b.y, b.x + b.w, b.y + b.h) for n, b in boxes.items() if n in frame.members]
        parts += [(x0, y - WAYPOINT / 2, x1, y + WAYPOINT / 2) for (i, k), (x0, x1, y) in waypoints.items()
                  if picture.wires[i].src_block in frame.members]
        parts += [(x, y, x + w, y + h) for path, (x, y, w, h) in out.items() if path.startswith(frame.path + ".")]
        if not parts:
            continue
        x0, y0 = min(p[0] for p in parts) - FRAME_PAD, min(p[1] for p in parts) - FRAME_HEAD + 0.04
        x1, y1 = max(p[2] for p in parts) + FRAME_PAD, max(p[3] for p in parts) + FRAME_PAD
        out[frame.path] = (x0, y0, x1 - x0, y1 - y0)
    return out


def wire_path(picture: Picture, lay: Layered, geo: Geometry, i: int):
    """The vertices and codes of a matplotlib Path for connection ``i``, and the point
    where its delay mark goes."""
    from matplotlib.path import Path as MPath

    c = picture.wires[i]
    x0, y0 = geo.boxes[c.src_block].out_anchor(c.src_port)
    x1, y1 = geo.boxes[c.dst_block].in_anchor(c.dst_port)
    if i in geo.channels:
        xs, xd, yc = geo.lanes[(i, "src")], geo.lanes[(i, "dst")], geo.channels[i]
        r = 0.08
        sgn_a = 1 if yc > y0 else -1
        sgn_b = 1 if y1 > yc else -1
        pts = [(x0, y0), (xs - r, y0), (xs, y0), (xs, y0 + sgn_a * r), (xs, yc - sgn_a * r), (xs, yc),
               (xs - r, yc), (xd + r, yc), (xd, yc), (xd, yc + sgn_b * r), (xd, y1 - sgn_b * r), (xd, y1),
               (xd + r, y1), (x1, y1)]
        codes = [MPath.MOVETO, MPath.LINETO, MPath.CURVE3, MPath.CURVE3, MPath.LINETO, MPath.CURVE3,
                 MPath.CURVE3, MPath.LINETO, MPath.CURVE3, MPath.CURVE3, MPath.LINETO, MPath.CURVE3,
                 MPath.CURVE3, MPath.LINETO]
        return pts, codes, ((xs + xd) / 2, yc)
    ks, kd = lay.layer[c.src_block], lay.layer[c.dst_block]
    stops = [(x0, y0)]
    for k in range(ks + 1, kd):
        left, right, y = geo.waypoints[(i, k)]
        stops += [(left, y), (right, y)]
    stops.append((x1, y1))
    pts, codes = [stops[0]], [MPath.MOVETO]
    for j in range(0, len(stops) - 1, 2):
        (ax_, ay), (bx, by) = stops[j], stops[j + 1]
        d = (bx - ax_) * 0.5
        pts += [(ax_ + d, ay), (bx - d, by), (bx, by)]
        codes += [MPath.CURVE4] * 3
        if j + 2 < len(stops):
            pts.append(stops[j + 2])
            codes.append(MPath.LINETO)
    (ax_, ay), (bx, by) = stops[0], stops[1]
    mark = ((ax_ + bx) / 2, (ay + by) / 2)
    return pts, codes, mark


def draw(diagram: Diagram, schedule: Schedule, expand: bool = False):
    """The wiring drawn on a new matplotlib Figure (sized in inches to fit its text); a
    subsystem is one box, or with ``expand`` a frame around its blocks.

    Every connection is a patch whose gid is ``wire:`` and the connection's text
    (``plant.q -> reflex.q``), every block (and subsystem box) a patch with gid
    ``block:NAME``, every frame one with gid ``frame:PATH``.
    """
    return draw_picture(picture(diagram, schedule, expand))


def draw_picture(pic: Picture):
    """``draw`` for a picture already made (``blocks.graph.view.picture``)."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.patches import FancyBboxPatch, Patch, PathPatch, Polygon
    from matplotlib.path import Path as MPath

    lay = layered(pic)
    geo = geometry(pic, lay)
    x_min, x_max, y_min, y_max = geo.bounds
    title_h = 0.45
    # legend: one row if it fits, else as many columns as fit
    entries = list(pic.legend)
    has_delay = any(c.delay for c in pic.wires)
    labels = [label for label, _ in entries] + (["delayed one sample (z\u207b\u00b9)"] if has_delay else [])
    entry_w = max((text_width(t, FONT) for t in labels), default=1.0) + 0.65
    content_w = x_max - x_min + 0.6
    width = max(content_w, text_width(pic.name, 12, bold=True) + 0.6, 4.0)
    ncol = max(1, min(len(labels), int((width - 0.3) // entry_w)))
    if ncol * entry_w + 0.3 > width:
        width = ncol * entry_w + 0.3
    legend_rows = -(-len(labels) // ncol) if labels else 0
    legend_h = 0.3 + 0.24 * legend_rows
    height = (y_max - y_min) + title_h + legend_h + 0.5
    fig = Figure(figsize=(width, height))
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_axis_off()
    left = x_min - (width - (x_max - x_min)) / 2
    top = y_min - title_h - legend_h - 0.15
    ax.set_xlim(left, left + width)
    ax.set_ylim(top + height, top)
    ax.text(left + 0.3, top + 0.3, pic.name, fontsize=12, fontweight="bold", va="center", ha="left")
    handles = [Patch(facecolor=tint(colour, 0.3), edgecolor=colour, linewidth=1.6, label=label)
               for label, colour in entries]
    if has_delay:
        handles.append(Line2D([], [], color="0.3", linestyle="--", label=labels[-1]))
    if handles:
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(left + 0.2, top + title_h + 0.05),
                  bbox_transform=ax.transData, ncol=ncol, frameon=False, fontsize=FONT, title="rates",
                  title_fontsize=FONT, alignment="left", handlelength=1.6, columnspacing=1.2, borderaxespad=0)
    for frame in pic.frames:
        if frame.path in geo.frames:
            draw_frame(ax, frame, geo.frames[frame.path])
    for name, box in geo.boxes.items():
        node = pic.nodes[name]
        colour = node.colour
        ax.add_patch(FancyBboxPatch((box.x, box.y), box.w, box.h, boxstyle="round,pad=0,rounding_size=0.05",
                                    facecolor="0.93" if node.disabled else tint(colour), edgecolor=colour,
                                    linewidth=1.8, zorder=2, gid=f"block:{name}",
                                    linestyle=(0, (3, 2)) if node.disabled else "-"))
        notes_y = box.y + HEADER + max(len(box.inputs), len(box.outputs), 1) * ROW + 0.06
        for i, note in enumerate(node.notes):
            off = note == DISABLED or note.endswith(" " + DISABLED)
            ax.text(box.x + PAD, notes_y + (i + 0.5) * NOTE_ROW, note, fontsize=SMALL_FONT, ha="left", va="center",
                    zorder=4, color=DISABLED_COLOUR if off else "0.25", fontweight="bold" if off else "normal",
                    gid=f"note:{name}")
        cx = box.x + box.w / 2
        ax.text(cx, box.y + 0.16, name, fontsize=TITLE_FONT, fontweight="bold", ha="center", va="center", zorder=4)
        ax.text(cx, box.y + 0.34, node.type_line, fontsize=SMALL_FONT, style="italic",
                color="0.3", ha="center", va="center", zorder=4)
        ax.text(cx, box.y + 0.50, node.rate_line, fontsize=SMALL_FONT, color=colour,
                ha="center", va="center", zorder=4)
        ax.plot([box.x, box.x + box.w], [box.y + HEADER - 0.03] * 2, color=colour, linewidth=0.8, alpha=0.6,
                zorder=3)
        wired_in = {c.dst_port for c in pic.wires if c.dst_block == name}
        wired_out = {c.src_port for c in pic.wires if c.src_block == name}
        for p in box.inputs:
            x, y = box.in_anchor(p)
            ax.text(x + PAD, y, p, fontsize=FONT, ha="left", va="center", zorder=4,
                    color="black" if p in wired_in else "0.55")
        for p in box.outputs:
            x, y = box.out_anchor(p)
            ax.text(x - PAD, y, p, fontsize=FONT, ha="right", va="center", zorder=4,
                    color="black" if p in wired_out else "0.55")
            if p in wired_out:
                ax.plot([x], [y], marker="o", markersize=3.5, color=colour, zorder=5)
    nth_from: dict[tuple[str, str], int] = {}
    for i, c in enumerate(pic.wires):
        pts, codes, mark = wire_path(pic, lay, geo, i)
        nth = nth_from[c.src_block, c.src_port] = nth_from.get((c.src_block, c.src_port), -1) + 1
        colour = pic.nodes[c.src_block].colour
        ax.add_patch(PathPatch(MPath(pts, codes), facecolor="none", edgecolor=colour, linewidth=1.3,
                               linestyle=(0, (4, 2.5)) if c.delay else "-", zorder=1, gid=f"wire:{c}",
                               capstyle="round"))
        x1, y1 = pts[-1]
        ax.add_patch(Polygon([(x1, y1), (x1 - 0.11, y1 - 0.045), (x1 - 0.11, y1 + 0.045)], closed=True,
                             facecolor=colour, edgecolor=colour, linewidth=0.5, zorder=5))
        if c.by_element:  # the selections along the wire near its ends, those of one port's wires staggered
            along = MPath(pts, codes).interpolated(40).vertices
            for at, select in ((0.2 + 0.15 * (nth % 3), c.src_select), (0.8, c.dst_select)):
                if select:
                    x, y = along[int(at * (len(along) - 1))]
                    ax.text(x, y, f"[{select}]", fontsize=SMALL_FONT, ha="center", va="center", zorder=6,
                            color=colour, gid=f"elements:{c}", bbox=dict(boxstyle="round,pad=0.1",
                                                                        facecolor="white", edgecolor="none"))
        if c.delay:
            ax.text(mark[0], mark[1], "z\u207b\u00b9", fontsize=SMALL_FONT, ha="center", va="center", zorder=6,
                    color=colour, bbox=dict(boxstyle="round,pad=0.15", facecolor="white", edgecolor=colour,
                                            linewidth=0.9))
    return fig


def draw_frame(ax, frame: Frame, rect: tuple[float, float, float, float]) -> None:
    """A subsystem's frame: a rounded grey rectangle with its path and file at the top left."""
    from matplotlib.patches import FancyBboxPatch

    x, y, w, h = rect
    ax.add_patch(FancyBboxPatch((x, y), w, h, boxstyle="round,pad=0,rounding_size=0.08", facecolor="none",
                                edgecolor="0.45", linewidth=1.1, linestyle=(0, (6, 3)), zorder=0.5,
                                gid=f"frame:{frame.path}"))
    ax.text(x + 0.1, y + 0.16, frame.label, fontsize=SMALL_FONT, fontweight="bold", color="0.35", ha="left",
            va="center", zorder=4)


def svg_text(diagram: Diagram, schedule: Schedule | None = None, expand: bool = False) -> str:
    """The wiring as SVG text (planned over the diagram's own t_end when no schedule is given)."""
    import io

    from blocks.engine.schedule import build_schedule

    fig = draw(diagram, schedule if schedule is not None else build_schedule(diagram, None), expand)
    out = io.StringIO()
    fig.savefig(out, format="svg")
    return out.getvalue()


def render(diagram: Diagram, schedule: Schedule, path: str | Path, expand: bool = False) -> Path:
    """Draw the diagram to an SVG, PNG or PDF file (format from the suffix)."""
    path = Path(path)
    fig = draw(diagram, schedule, expand)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=150)
    return path
