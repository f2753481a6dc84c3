"""draw_hand puts every part of the scene on the axes."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.patches import Circle, FancyArrow, Polygon  # noqa: E402

from hierhand.model.draw import draw_hand  # noqa: E402

from .sim import make_plant, pinch_torques  # noqa: E402


def test_draws_fingers_tips_object_and_contact_forces():
    plant = make_plant()
    hand = plant.hand
    state, _ = plant.advance(0.0, plant.initial_state(), {"tau": pinch_torques(hand, 2.0, 1.47)}, 300)
    views = plant.views(state)
    fig, ax = plt.subplots()
    try:
        artists = draw_hand(ax, hand, views.q, views.obj, forces=plant.contact_wrenches(state))
        fig.canvas.draw()
        assert len(artists["links"]) == len(artists["joints"]) == len(artists["tips"]) == 3
        assert all(a in ax.lines for a in artists["links"] + artists["joints"])
        tips = [p for p in ax.patches if isinstance(p, Circle)]
        assert len(tips) == 3
        assert np.allclose([t.center for t in tips], hand.tip_positions(views.q))
        (square,) = [p for p in ax.patches if isinstance(p, Polygon) and not isinstance(p, FancyArrow)]
        assert np.allclose(square.get_xy()[:4], hand.object_corners(views.obj))
        assert len(artists["forces"]) == 2  # thumb and fore touch, middle does not
        assert all(isinstance(a, FancyArrow) and a in ax.patches for a in artists["forces"])
        x0, x1 = ax.get_xlim()
        assert x0 < -0.05 and x1 > 0.05
    finally:
        plt.close(fig)


def test_force_rows_and_no_forces():
    hand = make_plant().hand
    fig, ax = plt.subplots()
    try:
        artists = draw_hand(ax, hand, hand.q0, hand.object_pose0)
        assert artists["forces"] == []
        artists = draw_hand(ax, hand, hand.q0, hand.object_pose0, forces=[[0.0, 0.06, 1.0, 0.5], [0.0, 0.0, 0.0, 0.0]])
        assert len(artists["forces"]) == 1
        with pytest.raises(ValueError, match=r"rows \(x, y, fx, fy\)"):
            draw_hand(ax, hand, hand.q0, hand.object_pose0, forces=[1.0, 2.0])
    finally:
        plt.close(fig)
