"""Drawing the hand, the object and the contact forces on a matplotlib axes."""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.patches import Circle, FancyArrow, Polygon

from .hand import Hand

FINGER_COLOURS = ("tab:blue", "tab:orange", "tab:green")


def draw_hand(
    ax: Axes,
    hand: Hand,
    q: np.ndarray,
    obj_pose: np.ndarray,
    forces: Any = None,
    force_scale: float = 0.01,
    normal_forces: Any = None,
) -> dict[str, list]:
    """Draw fingers (links as lines, joints as dots), fingertip circles, the object and
    contact force arrows; return the artists by kind.

    ``forces``: rows ``(x, y, fx, fy)`` (a force on the object and where it acts), or a
    ``ContactWrenches`` (its per-finger force on the object at the contact point).
    Arrows are ``force_scale`` metres long per newton. ``normal_forces``: rows ``(fx, fy)``,
    per row of ``forces`` its normal part, drawn as a thin dark arrow from the same point
    (artists ``"normal_forces"``).
    """
    pts = hand.joint_positions(np.asarray(q, dtype=float))
    artists: dict[str, list] = {"links": [], "joints": [], "tips": [], "object": [], "forces": [],
                                "normal_forces": []}
    corners = hand.object_corners(obj_pose)
    obj = Polygon(corners, closed=True, facecolor="0.85", edgecolor="0.3", linewidth=1.2, zorder=1)
    ax.add_patch(obj)
    artists["object"].append(obj)
    for f, name in enumerate(hand.names):
        colour = FINGER_COLOURS[f % len(FINGER_COLOURS)]
        (line,) = ax.plot(pts[f, :, 0], pts[f, :, 1], "-", color=colour, linewidth=2.5, label=name, zorder=2)
        (dots,) = ax.plot(pts[f, :3, 0], pts[f, :3, 1], "o", color="k", markersize=4, zorder=3)
        tip = Circle(pts[f, 3], hand.tip_radius[f], facecolor="none", edgecolor=colour, linewidth=1.5, zorder=2)
        ax.add_patch(tip)
        artists["links"].append(line)
        artists["joints"].append(dots)
        artists["tips"].append(tip)
    rows = _force_rows(forces)
    normals = None if normal_forces is None else np.asarray(normal_forces, dtype=float).reshape(-1, 2)
    if normals is not None and len(normals) != len(rows):
        raise ValueError(f"normal_forces must have a row per force, got {len(normals)} for {len(rows)}")
    for i, (x, y, fx, fy) in enumerate(rows):
        if not (np.isfinite([x, y, fx, fy]).all() and (fx or fy)):
            continue
        if normals is not None and np.isfinite(normals[i]).all() and normals[i].any():
            part = FancyArrow(
                x, y, normals[i, 0] * force_scale, normals[i, 1] * force_scale,
                width=0.0002, head_width=0.0018, head_length=0.0018,
                length_includes_head=True, color="0.15", alpha=0.8, zorder=5,
            )
            ax.add_patch(part)
            artists["normal_forces"].append(part)
        arrow = FancyArrow(
            x, y, fx * force_scale, fy * force_scale,
            width=0.0006, head_width=0.003, head_length=0.003,
            length_includes_head=True, color="tab:red", zorder=4,
        )
        ax.add_patch(arrow)
        artists["forces"].append(arrow)
    ax.set_aspect("equal")
    ax.autoscale_view()
    return artists


def _force_rows(forces: Any) -> np.ndarray:
    if forces is None:
        return np.zeros((0, 4))
    if hasattr(forces, "on_object") and hasattr(forces, "point"):
        return np.column_stack([forces.point, forces.on_object])
    rows = np.asarray(forces, dtype=float)
    if rows.ndim != 2 or rows.shape[1] != 4:
        raise ValueError(f"forces must be rows (x, y, fx, fy), got shape {rows.shape}")
    return rows
