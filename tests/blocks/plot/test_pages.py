"""Signal plots drawn with matplotlib: what each page's axes show (the time span, units,
legends, markers, where a failed or interrupted run stopped), that long signals keep their
envelope, that the drawn pixels are where the values are, and the files they are written
as (PNG, SVG, PDF)."""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Polygon, Rectangle

from blocks import Results
from blocks.plot.curves import LARGEST, envelope
from blocks.plot.figure import STOP_COLOUR, STOP_GID
from blocks.plot.markers import MARKER_GID, Marker
from blocks.plot.pages import Pages, plot_signals

FAILED = "failed at t=0.005 s: block 'f' (Gain) output: boom"


def results(status: str = "complete", **info) -> Results:
    """a.y every 1 ms up to 5 ms, b.y (width 2) every 2 ms up to 4 ms; t_end 1 s."""
    t_a, t_b = np.arange(6) * 1e-3, np.arange(3) * 2e-3
    signals = {"a.y": (t_a, t_a[:, None] * 10), "b.y": (t_b, np.column_stack([t_b, -t_b]))}
    return Results(signals, {"diagram": "d", "status": status, "t_end": 1.0, **info})


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


def curves(ax) -> list:
    """The axis's data lines: its step curves (not the markers' or the stop's lines)."""
    return [line for line in ax.get_lines() if line.get_drawstyle() == "steps-post"]


def with_gid(ax, gid: str) -> list:
    return [a for a in ax.get_children() if a.get_gid() == gid]


def lines_with_gid(ax, gid: str) -> list[Line2D]:
    return [a for a in with_gid(ax, gid) if isinstance(a, Line2D)]


def legend_labels(ax) -> list[str]:
    legend = ax.get_legend()
    return [] if legend is None else [t.get_text() for t in legend.get_texts()]


@pytest.mark.parametrize("status, info", [
    (FAILED, {"t_stop": 0.005}),
    (FAILED, {}),  # a run.json from before t_stop was recorded: the time comes from the status
    ("interrupted at t=0.005 s by SIGINT", {"t_stop": 0.005}),
])
def test_an_incomplete_run_is_drawn_to_where_it_stopped_and_marked(status, info):
    fig = results(status, **info).plot("a.y", "b.y")
    for ax in fig.axes:
        assert max(line.get_xdata()[-1] for line in curves(ax)) == pytest.approx(0.005)  # not to t_end = 1 s
        assert ax.get_xlim()[1] < 0.01
        (stop_line,) = [a for a in lines_with_gid(ax, STOP_GID) if a.get_linestyle() == "--"]
        assert stop_line.get_xdata()[0] == pytest.approx(0.005) and stop_line.get_color() == STOP_COLOUR
    words = [t.get_text() for t in fig.axes[0].texts if t.get_gid() == STOP_GID]
    assert words == [status.split(": ")[0]]
    assert status.split(": ")[0] in fig.texts[0].get_text()  # the title says it too


def test_a_complete_run_is_held_to_its_end_time_without_a_mark():
    fig = results().plot("a.y", "b.y")
    for ax in fig.axes:
        assert max(line.get_xdata()[-1] for line in curves(ax)) == pytest.approx(1.0)
        assert with_gid(ax, STOP_GID) == []
    assert "[" not in fig.texts[0].get_text()


def test_a_failed_run_marks_the_last_sample_of_every_element():
    q, pose = described(FAILED, t_stop=0.005).plot("b.q", "b.pose[x,y]").axes
    (dots,) = [a for a in lines_with_gid(q, STOP_GID) if a.get_marker() == "o"]
    assert np.allclose(dots.get_xdata(), 0.005) and np.allclose(dots.get_ydata(), [0.005, 0.010, 0.015])
    (dots,) = [a for a in lines_with_gid(pose, STOP_GID) if a.get_marker() == "o"]
    assert np.allclose(dots.get_xdata(), 0.004) and len(dots.get_ydata()) == 2  # its last sample, before the stop
    assert 0.005 < q.get_xlim()[1] < 0.0052  # a little past the stop, so that the marks show


def test_axes_name_signal_and_unit_and_legends_name_the_elements_outside_the_data():
    fig = described().plot("b.q", "b.pose", "b.r")
    q, pose_m, pose_rad, r = fig.axes  # b.pose: an axis per unit
    assert q.get_ylabel() == "b.q\n(rad)"
    assert pose_m.get_ylabel() == "b.pose[x,y]\n(m)" and pose_rad.get_ylabel() == "b.pose[theta]\n(rad)"
    assert r.get_ylabel() == "b.r" and r.get_legend() is None  # one element, no units: the name alone
    assert legend_labels(q) == ["thumb.1", "thumb.2", "fore.1"]
    assert legend_labels(pose_m) == ["x", "y"] and pose_rad.get_legend() is None
    renderer = fig.canvas.get_renderer()
    for ax in (q, pose_m):
        box = ax.get_legend().get_window_extent(renderer)
        assert box.x0 > ax.get_window_extent(renderer).x1  # right of the axes, off the data
        assert box.x1 <= fig.bbox.x1  # and on the page
    lines = curves(q)
    assert lines[0].get_color() == lines[1].get_color() != lines[2].get_color()  # thumb.1, thumb.2: one finger
    assert lines[0].get_linestyle() != lines[1].get_linestyle()
    assert q.get_xlim() == pytest.approx((0.0, 0.005))  # the data's span: no margins
    assert described().plot("b.q").axes[0].get_xlim() == pytest.approx((0.001, 0.005))  # from the first sample


def test_a_legend_names_each_element_with_its_unit_where_they_differ():
    (axis,) = described().plot("b.pose[x,theta]").axes  # elements chosen: one axis, as asked
    assert legend_labels(axis) == ["x (m)", "theta (rad)"] and axis.get_ylabel() == "b.pose[x,theta]\n(m, rad)"


def test_dimensionless_signals_say_so():
    r = Results({"a.ratio": (np.arange(3.0), np.ones((3, 1)))}, {"diagram": "d", "units": {"a.ratio": "1"}})
    assert r.plot().axes[0].get_ylabel() == "a.ratio\n(dimensionless)"


def test_an_axis_of_selected_elements_and_one_of_overlaid_signals():
    one, both = described().plot("b.q[fore.1]", "b.q[thumb.1,thumb.2],b.r").axes
    assert one.get_ylabel() == "b.q[fore.1]\n(rad)" and one.get_legend() is None
    np.testing.assert_allclose(curves(one)[0].get_ydata()[:5], 3 * np.arange(1, 6) * 1e-3)
    assert legend_labels(both) == ["b.q[thumb.1]", "b.q[thumb.2]", "b.r"]
    assert both.get_ylabel().startswith("b.q[thumb.1,thumb.2], b.r")
    assert len({line.get_color() for line in curves(both)}) == 3


def test_markers_are_drawn_on_every_axis_and_named_once():
    events = [Marker(0.002, 0.002, "", "s: step at 0.002 s"), Marker(0.003, 0.004, "moving", "moved")]
    fig = described().plot("b.q", "b.r", markers=events)
    for k, ax in enumerate(fig.axes):
        drawn = with_gid(ax, MARKER_GID)
        lines = [a for a in drawn if isinstance(a, Line2D)]
        spans = [a for a in drawn if isinstance(a, (Polygon, Rectangle))]
        assert [line.get_xdata()[0] for line in lines] == [0.002] and lines[0].get_linestyle() == ":"
        (span,) = spans
        xs = span.get_xy()[:, 0] if isinstance(span, Polygon) else [span.get_x(), span.get_x() + span.get_width()]
        assert min(xs) == pytest.approx(0.003) and max(xs) == pytest.approx(0.004)
        words = [t.get_text() for t in ax.texts if t.get_gid() == MARKER_GID]
        assert words == (["s: step at 0.002 s", "moving"] if k == 0 else [])  # named once, on the top axis


def test_the_runs_steps_are_marked_unless_asked_not_to(tmp_path):
    run = described(block_types={"s": "Step"}, parameters={"s": {"time": 0.002}})
    assert [m.start for m in Pages.of(run, tmp_path / "a.png").events] == [0.002]
    assert any(with_gid(run.plot("b.q").axes[0], MARKER_GID))
    assert Pages.of(run, tmp_path / "b.png", markers=False).events == []
    assert not with_gid(run.plot("b.q", markers=False).axes[0], MARKER_GID)


def test_a_signal_of_mixed_units_is_an_axis_per_unit_and_pages_are_balanced(tmp_path):
    many = described()
    many.signals.update({f"c{i}.y": (np.arange(3) * 1e-3, np.ones((3, 1))) for i in range(10)})
    pages = Pages.of(many, tmp_path / "p.png")
    axes = [[tr.title for tr in traces] for page in pages.axes for traces in page]
    assert axes[:4] == [["b.q"], ["b.pose[x,y]"], ["b.pose[theta]"], ["b.r"]]  # b.pose: m, then rad
    assert [len(p) for p in pages.axes] == [5, 5, 4]  # 14 axes: not 6, 6 and 2
    assert [len(pages.page(n).axes) for n in (1, 2, 3)] == [5, 5, 4]
    written = plot_signals(many, tmp_path / "p.png")
    assert [p.name for p in written] == ["p-1.png", "p-2.png", "p-3.png"]
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in written)
    assert len(many.plot().axes) == 14  # in Python: one figure of every axis


def test_many_samples_are_thinned_to_what_each_pixel_column_shows():
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


def test_a_long_signal_is_drawn_by_its_envelope():
    t = np.arange(10_000) * 1e-4
    v = np.sin(2 * np.pi * 50 * t) + (np.arange(10_000) == 7_777) * 5.0  # fast: many periods a pixel column
    run = Results({"a.y": (t, v[:, None])}, {"diagram": "d", "t_end": 1.0})
    (line,) = curves(run.plot().axes[0])
    drawn = line.get_ydata()
    assert len(drawn) < len(t) / 2  # thinned
    assert drawn.max() == v.max() and drawn.min() == v.min()  # the spike and the troughs kept


def rgba(fig: Figure) -> np.ndarray:
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())


def blue_mask(pixels: np.ndarray) -> np.ndarray:
    """Where the first line colour (C0, #1f77b4) is drawn."""
    return np.all(np.abs(pixels[..., :3].astype(int) - [0x1F, 0x77, 0xB4]) <= 40, axis=-1)


def test_a_curve_is_drawn_where_its_values_are_and_only_inside_its_axis():
    t = np.arange(100_001) * 1e-5
    v = (t >= 0.5).astype(float)
    v[25_000] = 3.0  # one sample's spike, 10 us wide: far under a pixel column
    run = Results({"a.y": (t, v[:, None])}, {"diagram": "d", "status": "complete", "t_end": 1.0})
    fig = run.plot()
    (ax,) = fig.axes
    blue = blue_mask(rgba(fig))
    height = blue.shape[0]

    def pixel(x, y):
        px, py = ax.transData.transform((x, y))
        return round(px), round(height - py)

    (left, low), (middle, high), (right, _), (_, spike) = (pixel(0.1, 0.0), pixel(0.5, 1.0), pixel(0.9, 1.0),
                                                          pixel(0.25, 3.0))
    assert blue[low - 1:low + 2, left:middle - 3].any(axis=0).all()  # 0 until t = 0.5
    assert blue[high - 1:high + 2, middle + 3:right].any(axis=0).all()  # then 1
    assert blue[high:low, middle - 2:middle + 3].any(axis=1).all()  # the step's riser
    assert blue[spike - 2:spike + 3].any()  # the spike reaches its value
    box = ax.get_window_extent()
    inside = np.zeros_like(blue)
    inside[round(height - box.y1) - 1:round(height - box.y0) + 2, round(box.x0) - 1:round(box.x1) + 2] = True
    assert not (blue & ~inside).any()  # nothing of the curve outside its axis


def test_non_finite_values_break_the_curve_and_leave_the_range_to_the_finite_ones():
    t = np.arange(5) * 0.25
    v = np.array([0.0, 1.0, np.nan, np.inf, 2.0])[:, None]
    fig = Results({"a.y": (t, v)}, {"diagram": "d", "status": "complete", "t_end": 1.0}).plot()
    (ax,) = fig.axes
    assert ax.get_ylim() == pytest.approx((-0.1, 2.1))
    blue = blue_mask(rgba(fig))
    gap = round(ax.transData.transform((0.625, 0.0))[0])
    assert not blue[:, gap].any() and blue.any()


@pytest.mark.parametrize("values", [[-1e308, 1e308], [-1.7e308, 1.7e308], [1.7e308, 1.79e308], [1e-320, 2e-320],
                                    [np.inf, -np.inf], [1.0, np.inf], [-0.0, 0.0], [5e15, 5e15 + 1]])
def test_extreme_values_are_drawn_on_a_finite_axis_without_a_warning(values):
    run = Results({"a.y": (np.array([0.0, 0.5]), np.array(values)[:, None])},
                  {"diagram": "d", "status": "complete", "t_end": 1.0})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = run.plot()
        rgba(fig)
    lo, hi = fig.axes[0].get_ylim()
    assert np.isfinite([lo, hi]).all() and lo < hi
    for v in (v for v in values if np.isfinite(v)):
        assert lo <= v <= hi or (v > hi == LARGEST) or (v < lo == -LARGEST)  # a diverged value runs off the edge


def test_labels_of_any_length_stay_on_the_page_and_leave_room_for_the_data():
    t = np.arange(10) * 0.1
    long = "b" * 150
    run = Results({f"{long}.y": (t, np.ones((10, 3))), "a.q": (t, np.ones((10, 2))), "c.v": (t, np.ones((10, 20)))},
                  {"diagram": "d " * 300, "t_end": 1.0, "status": "failed at t=0.5 s: " + "boom " * 300,
                   "t_stop": 0.5, "element_labels": {f"{long}.y": ["x" * 400, "y", "z"],
                                                     "c.v": [f"{k}" + "w" * 300 for k in range(20)]},
                   "units": {"a.q": [f"unit{i} " * 20 for i in range(2)]}})
    fig = run.plot()
    renderer = fig.canvas.get_renderer()
    fig.canvas.draw()
    page = fig.bbox
    assert fig.texts[0].get_text().count("\n") <= 4
    for ax in fig.axes:
        box = ax.get_window_extent(renderer)
        assert box.width > 0.5 * page.width  # the data keeps half the page's width at least
        texts = [ax.yaxis.label] + ([ax.get_legend()] if ax.get_legend() else [])
        for text in texts + [fig.texts[0]]:
            extent = text.get_window_extent(renderer)
            assert page.x0 - 1 <= extent.x0 and extent.x1 <= page.x1 + 1 and extent.y1 <= page.y1 + 1
        label = ax.yaxis.label.get_window_extent(renderer)
        assert label.height <= box.height + 1  # an axis label no longer than its axis


def test_a_dollar_sign_in_a_name_is_text():
    run = Results({"a.y": (np.arange(3.0), np.ones((3, 2)))},
                  {"diagram": "cost in $", "element_labels": {"a.y": ["$x", "y$"]}})
    fig = run.plot()
    rgba(fig)  # mathtext would fail on '$x' and 'y$' together
    assert legend_labels(fig.axes[0]) == ["$x", "y$"]


def test_svg_and_pdf_are_vector_files(tmp_path):
    run = described(FAILED, t_stop=0.005)
    (svg,) = plot_signals(run, tmp_path / "s.svg")
    root = ET.parse(svg).getroot()
    assert root.tag == "{http://www.w3.org/2000/svg}svg"
    assert len(root.findall(".//{http://www.w3.org/2000/svg}path")) > 10
    assert root.findall(".//{http://www.w3.org/2000/svg}image") == []  # nothing rasterised
    (pdf,) = plot_signals(run, tmp_path / "s.pdf")
    data = pdf.read_bytes()
    assert data.startswith(b"%PDF-") and data.rstrip().endswith(b"%%EOF")
    assert plot_signals(run, tmp_path / "again.svg")[0].read_bytes() == svg.read_bytes()  # no date: the same file
    assert plot_signals(run, tmp_path / "again.pdf")[0].read_bytes() == data


def test_another_kind_of_file_is_refused_before_anything_is_drawn(tmp_path):
    with pytest.raises(ValueError, match=r"\.png, \.svg or \.pdf"):
        plot_signals(described(), tmp_path / "plots" / "s.jpg")
    assert not (tmp_path / "plots").exists()


def test_results_plot_is_a_figure_a_notebook_shows():
    fig = described().plot("b.q", "b.r", title="mine")
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    assert fig.texts[0].get_text() == "mine"
    assert fig._repr_png_()[:8] == b"\x89PNG\r\n\x1a\n"


def test_results_plot_needs_no_pyplot(tmp_path):
    import subprocess
    import sys

    code = ("import sys, numpy as np; from blocks import Results\n"
            "r = Results({'a.y': (np.arange(3.0), np.ones((3, 1)))}, {'diagram': 'd'})\n"
            f"r.plot().savefig({str(tmp_path / 'f.png')!r})\n"
            "print('matplotlib.pyplot' in sys.modules)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False" and (tmp_path / "f.png").read_bytes()[:4] == b"\x89PNG"
