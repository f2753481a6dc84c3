"""sweep-plot's pictures: heat map cells at the parameters' true values, with their values
written in, categorical axes labelled as such, and the metric's unit."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import QuadMesh  # noqa: E402

from blocks.sweep.plot import _heat_map  # noqa: E402


def heat(table, **kw):
    fig, ax = plt.subplots()
    _heat_map(fig, ax, table, "s.S_a", "s.S_b", [], "sep", **kw)
    return fig, ax


def test_numeric_values_keep_their_true_spacing_and_each_cell_its_value():
    table = [{"s.S_a": a, "s.S_b": b, "metric": a / 100 + b} for a in (100, 200, 300, 500) for b in (0.01, 0.03)]
    fig, ax = heat(table, units={"sep": "s"})
    try:
        (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
        xs = np.unique(mesh.get_coordinates()[..., 0])
        np.testing.assert_allclose(xs, [50, 150, 250, 400, 600])  # 500 sits two steps past 300
        assert [t.get_text() for t in ax.get_xticklabels()] == ["100", "200", "300", "500"]
        texts = sorted(t.get_text() for t in ax.texts)
        assert len(texts) == 8 and "5.03" in texts and "1.01" in texts
        assert ax.get_xlabel() == "s.S_a" and fig.axes[-1].get_ylabel() == "sep (s)"
    finally:
        plt.close(fig)


def test_values_that_are_not_numbers_are_labelled_categories_and_missing_cells_stay_blank():
    table = [{"s.S_a": mode, "s.S_b": b, "metric": (np.nan if (mode, b) == ("b", 2) else 1.0)}
             for mode in ("a", "b") for b in (1, 2)]
    fig, ax = heat(table)
    try:
        assert ax.get_xlabel() == "s.S_a (categories, in order of appearance)"
        assert [t.get_text() for t in ax.get_xticklabels()] == ['"a"', '"b"']
        assert len(ax.texts) == 3 and "blank: no value" in ax.get_title()
        assert fig.axes[-1].get_ylabel() == "sep"
    finally:
        plt.close(fig)
