"""Plots of a run's signals: their time span, and where a failed or interrupted run stopped."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from blocks import Results  # noqa: E402
from blocks.plot import figure, plot_signals  # noqa: E402

FAILED = "failed at t=0.005 s: block 'f' (Gain) output: boom"


def results(status: str = "complete", **info) -> Results:
    """a.y every 1 ms up to 5 ms, b.y (width 2) every 2 ms up to 4 ms; t_end 1 s."""
    t_a, t_b = np.arange(6) * 1e-3, np.arange(3) * 2e-3
    signals = {"a.y": (t_a, t_a[:, None] * 10), "b.y": (t_b, np.column_stack([t_b, -t_b]))}
    return Results(signals, {"diagram": "d", "status": status, "t_end": 1.0, **info})


def drawn_until(ax) -> float:
    return max(line.get_xdata()[-1] for line in ax.get_lines() if len(line.get_xdata()) > 2)


def stop_lines(ax) -> list[float]:
    return [line.get_xdata()[0] for line in ax.get_lines() if len(line.get_xdata()) == 2]


@pytest.mark.parametrize("status, info", [
    (FAILED, {"t_stop": 0.005}),
    (FAILED, {}),  # a run.json from before t_stop was recorded: the time comes from the status
    ("interrupted at t=0.005 s by SIGINT", {"t_stop": 0.005}),
])
def test_an_incomplete_run_is_drawn_to_where_it_stopped_and_marked(status, info):
    fig = figure(results(status, **info), ["a.y", "b.y"])
    try:
        for ax in fig.axes:
            assert drawn_until(ax) == pytest.approx(0.005)  # held to the stop, not to t_end = 1 s
            assert stop_lines(ax) == [pytest.approx(0.005)]
            assert ax.get_xlim()[1] < 0.01
        assert [t.get_text() for t in fig.axes[0].texts] == [status.split(": ")[0]]
    finally:
        plt.close(fig)


def test_a_complete_run_is_held_to_its_end_time_without_a_mark():
    fig = figure(results(), ["a.y", "b.y"])
    try:
        for ax in fig.axes:
            assert drawn_until(ax) == pytest.approx(1.0)
            assert stop_lines(ax) == [] and list(ax.texts) == []
    finally:
        plt.close(fig)


def test_plot_signals_writes_one_png_per_page(tmp_path):
    many = Results({f"s{i}.y": (np.arange(3.0), np.ones((3, 1))) for i in range(9)},
                   {"diagram": "d", "status": FAILED})
    written = plot_signals(many, tmp_path / "p.png")
    assert [p.name for p in written] == ["p-1.png", "p-2.png"]
    assert all(p.read_bytes()[:4] == b"\x89PNG" for p in written)
