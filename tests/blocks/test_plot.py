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


def described(status: str = "complete", **info) -> Results:
    """q (width 3, rad, elements thumb.1 ...) every 1 ms from 1 ms to 5 ms; pose (x m, y m,
    theta rad) every 2 ms; r (width 1, no units); t_end 5 ms."""
    t_q, t_p = np.arange(1, 6) * 1e-3, np.arange(3) * 2e-3
    signals = {"b.q": (t_q, np.column_stack([t_q, 2 * t_q, 3 * t_q])), "b.pose": (t_p, np.ones((3, 3))),
               "b.r": (t_q, t_q[:, None])}
    return Results(signals, {"diagram": "d", "status": status, "t_end": 0.005,
                             "element_labels": {"b.q": ["thumb.1", "thumb.2", "fore.1"],
                                                "b.pose": ["x", "y", "theta"]},
                             "units": {"b.q": "rad", "b.pose": ["m", "m", "rad"]}, **info})


def legend_texts(ax) -> list[str]:
    return [t.get_text() for t in ax.get_legend().get_texts()]


def test_axes_name_signal_and_unit_and_legends_name_the_elements_outside_the_data():
    fig = figure(described(), ["b.q", "b.pose", "b.r"])
    try:
        q, pose, r = fig.axes
        assert q.get_ylabel() == "b.q\n(rad)"
        assert pose.get_ylabel() == "b.pose\n(m, rad)"
        assert r.get_ylabel() == "b.r" and r.get_legend() is None  # one element, no units: the name alone
        assert legend_texts(q) == ["thumb.1", "thumb.2", "fore.1"]
        assert legend_texts(pose) == ["x (m)", "y (m)", "theta (rad)"]  # each with its unit where they differ
        for ax in (q, pose):
            anchor = ax.get_legend().get_bbox_to_anchor().transformed(ax.transAxes.inverted())
            assert anchor.x0 > 1.0  # right of the axes, off the data
        colours = [line.get_color() for line in q.get_lines()]
        styles = [line.get_linestyle() for line in q.get_lines()]
        assert colours[0] == colours[1] != colours[2] and styles[0] != styles[1]  # thumb.1, thumb.2: one finger
        assert q.get_xlim() == pytest.approx((0.0, 0.005))  # the data's span: no margins
    finally:
        plt.close(fig)
    fig = figure(described(), ["b.q"])
    try:
        assert fig.axes[0].get_xlim() == pytest.approx((0.001, 0.005))  # from the first sample
    finally:
        plt.close(fig)


def test_dimensionless_signals_say_so():
    r = Results({"a.ratio": (np.arange(3.0), np.ones((3, 1)))}, {"diagram": "d", "units": {"a.ratio": "1"}})
    fig = figure(r, ["a.ratio"])
    try:
        assert fig.axes[0].get_ylabel() == "a.ratio\n(dimensionless)"
    finally:
        plt.close(fig)


def test_a_failed_run_marks_the_last_sample_of_every_element():
    fig = figure(described(FAILED, t_stop=0.005), ["b.q", "b.pose"])
    try:
        q, pose = fig.axes
        (dots,) = q.collections
        np.testing.assert_allclose(dots.get_offsets(), [[0.005, 0.005], [0.005, 0.010], [0.005, 0.015]])
        (dots,) = pose.collections
        np.testing.assert_allclose(dots.get_offsets()[:, 0], [0.004] * 3)  # its last sample, before the stop
        assert 0.005 < q.get_xlim()[1] < 0.0052  # a little past the stop, so that the marks show
        assert "failed at t=0.005 s" in fig._suptitle.get_text()
    finally:
        plt.close(fig)


def test_a_complete_run_has_no_marks():
    fig = figure(described(), ["b.q"])
    try:
        assert len(fig.axes[0].collections) == 0 and stop_lines(fig.axes[0]) == []
    finally:
        plt.close(fig)


def test_plot_signals_writes_the_png(tmp_path):
    (written,) = plot_signals(described(), tmp_path / "plots" / "s.png")
    assert written == tmp_path / "plots" / "s.png" and written.read_bytes()[:4] == b"\x89PNG"


def test_an_axis_of_selected_elements_and_one_of_overlaid_signals():
    fig = figure(described(), ["b.q[fore.1]", "b.q[thumb.1,thumb.2],b.r"])
    try:
        one, both = fig.axes
        assert one.get_ylabel() == "b.q[fore.1]\n(rad)" and one.get_legend() is None
        np.testing.assert_allclose(one.get_lines()[0].get_ydata()[:5], 3 * np.arange(1, 6) * 1e-3)
        assert legend_texts(both) == ["b.q[thumb.1]", "b.q[thumb.2]", "b.r"]
        assert both.get_ylabel().startswith("b.q[thumb.1,thumb.2], b.r")
        assert len({line.get_color() for line in both.get_lines()}) == 3
    finally:
        plt.close(fig)


def marker_artists(ax):
    return [a for a in (*ax.get_lines(), *ax.patches, *ax.texts) if a.get_gid() == "marker"]


def test_markers_are_drawn_on_every_axis_and_named_once():
    from blocks.plot_markers import Marker

    events = [Marker(0.001, 0.001, "", "s: step at 0.001 s"), Marker(0.002, 0.004, "moving", "moved")]
    fig = figure(described(), ["b.q", "b.r"], markers=events)
    try:
        top, bottom = fig.axes
        lines = [a for a in marker_artists(bottom) if a in bottom.get_lines()]
        assert [line.get_xdata()[0] for line in lines] == [0.001] and len(bottom.patches) == 1
        assert [t.get_text() for t in marker_artists(top) if t in top.texts] == ["s: step at 0.001 s", "moving"]
        assert not [t for t in bottom.texts if t.get_gid() == "marker"]
        assert stop_lines(bottom) == [0.001]  # a marker line, not a stop: the run is complete
    finally:
        plt.close(fig)


def test_plot_signals_marks_the_runs_steps_unless_asked_not_to(tmp_path, monkeypatch):
    import blocks.plot as plot

    drawn = []
    monkeypatch.setattr(plot, "draw_markers", lambda axes, markers: drawn.append(list(markers)))
    run = described(block_types={"s": "Step"}, parameters={"s": {"time": 0.002}})
    plot_signals(run, tmp_path / "a.png")
    plot_signals(run, tmp_path / "b.png", markers=False)
    assert [[m.start for m in ms] for ms in drawn] == [[0.002], []]


def test_a_signal_of_mixed_units_is_an_axis_per_unit_and_pages_are_balanced(tmp_path, monkeypatch):
    import blocks.plot as plot

    pages = []
    real = plot.figure
    monkeypatch.setattr(plot, "figure", lambda r, page, *a: pages.append(page) or real(r, page, *a))
    many = described()
    many.signals.update({f"c{i}.y": (np.arange(3) * 1e-3, np.ones((3, 1))) for i in range(10)})
    written = plot_signals(many, tmp_path / "p.png")
    axes = [[tr.title for tr in traces] for page in pages for traces in page]
    assert axes[:4] == [["b.q"], ["b.pose[x,y]"], ["b.pose[theta]"], ["b.r"]]  # b.pose: m, then rad
    assert [len(p) for p in pages] == [5, 5, 4] and len(written) == 3  # 14 axes: not 6, 6 and 2


def test_an_axis_per_unit_is_labelled_with_that_unit_alone():
    from blocks.plot_select import by_unit, select

    r = described()
    fig = figure(r, by_unit(r, select(r, "b.pose")))
    try:
        assert [ax.get_ylabel() for ax in fig.axes] == ["b.pose[x,y]\n(m)", "b.pose[theta]\n(rad)"]
        assert legend_texts(fig.axes[0]) == ["x", "y"] and fig.axes[1].get_legend() is None
    finally:
        plt.close(fig)


def test_many_samples_are_thinned_to_what_each_pixel_column_shows():
    from blocks.plot import envelope

    t = np.arange(100_000) * 1e-5
    v = np.column_stack([np.sin(2 * np.pi * 7 * t), (np.arange(100_000) == 51_234).astype(float)])
    tt, vv = envelope(t, v, 500)
    assert len(tt) <= 4 * 500 and tt[0] == t[0] and tt[-1] == t[-1]
    assert np.all(np.diff(tt) >= 0)
    assert vv[:, 0].max() == v[:, 0].max() and vv[:, 0].min() == v[:, 0].min()
    assert vv[:, 1].max() == 1.0  # a one-sample spike still shows
    assert np.array_equal(vv[-1], v[-1])  # the value held at the end
    few_t, few_v = envelope(t[:1000], v[:1000], 500)
    assert np.array_equal(few_t, t[:1000]) and np.array_equal(few_v, v[:1000])  # under 4 a column: as they are
