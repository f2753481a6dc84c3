"""Plots of a run's signals: what each page shows (its layout) and that the painted pixels
show it: the time span, where a failed or interrupted run stopped, units, legends, markers."""

from __future__ import annotations

import numpy as np
import pytest

from blocks import Results
from blocks.plot.pages import Pages, plot_signals
from blocks.plot.canvas import rgb
from blocks.plot.markers import MARKER_COLOUR
from blocks.plot.page_layout import envelope, layout
from blocks.plot.paint import paint

FAILED = "failed at t=0.005 s: block 'f' (Gain) output: boom"


def results(status: str = "complete", **info) -> Results:
    """a.y every 1 ms up to 5 ms, b.y (width 2) every 2 ms up to 4 ms; t_end 1 s."""
    t_a, t_b = np.arange(6) * 1e-3, np.arange(3) * 2e-3
    signals = {"a.y": (t_a, t_a[:, None] * 10), "b.y": (t_b, np.column_stack([t_b, -t_b]))}
    return Results(signals, {"diagram": "d", "status": status, "t_end": 1.0, **info})


def drawn_until(panel) -> float:
    return max(curve.t[-1] for curve in panel.curves)


@pytest.mark.parametrize("status, info", [
    (FAILED, {"t_stop": 0.005}),
    (FAILED, {}),  # a run.json from before t_stop was recorded: the time comes from the status
    ("interrupted at t=0.005 s by SIGINT", {"t_stop": 0.005}),
])
def test_an_incomplete_run_is_drawn_to_where_it_stopped_and_marked(status, info):
    page = layout(results(status, **info), ["a.y", "b.y"])
    for panel in page.panels:
        assert drawn_until(panel) == pytest.approx(0.005)  # held to the stop, not to t_end = 1 s
        assert panel.xlim[1] < 0.01
    assert page.stop == pytest.approx(0.005) and page.stop_word == status.split(": ")[0]


def test_a_complete_run_is_held_to_its_end_time_without_a_mark():
    page = layout(results(), ["a.y", "b.y"])
    for panel in page.panels:
        assert drawn_until(panel) == pytest.approx(1.0) and panel.dots == []
    assert page.stop is None and page.stop_word == ""


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


def test_axes_name_signal_and_unit_and_legends_name_the_elements_outside_the_data():
    page = layout(described(), ["b.q", "b.pose", "b.r"])
    q, pose, r = page.panels
    assert q.ylabel == "b.q\n(rad)"
    assert pose.ylabel == "b.pose\n(m, rad)"
    assert r.ylabel == "b.r" and r.legend_box is None  # one element, no units: the name alone
    assert q.legend_labels == ["thumb.1", "thumb.2", "fore.1"]
    assert pose.legend_labels == ["x (m)", "y (m)", "theta (rad)"]  # each with its unit where they differ
    for panel in (q, pose):
        assert panel.legend_box[0] > panel.box[2]  # right of the axes, off the data
        assert panel.legend_box[2] <= page.width  # and on the page
    colours = [c.style["color"] for c in q.curves]
    styles = [c.style["ls"] for c in q.curves]
    assert colours[0] == colours[1] != colours[2] and styles[0] != styles[1]  # thumb.1, thumb.2: one finger
    assert q.xlim == pytest.approx((0.0, 0.005))  # the data's span: no margins
    assert layout(described(), ["b.q"]).panels[0].xlim == pytest.approx((0.001, 0.005))  # from the first sample


def test_dimensionless_signals_say_so():
    r = Results({"a.ratio": (np.arange(3.0), np.ones((3, 1)))}, {"diagram": "d", "units": {"a.ratio": "1"}})
    assert layout(r, ["a.ratio"]).panels[0].ylabel == "a.ratio\n(dimensionless)"


def test_a_failed_run_marks_the_last_sample_of_every_element():
    page = layout(described(FAILED, t_stop=0.005), ["b.q", "b.pose"])
    q, pose = page.panels
    ((t, values),) = q.dots
    assert t == 0.005 and np.allclose(values, [0.005, 0.010, 0.015])
    ((t, values),) = pose.dots
    assert t == 0.004 and len(values) == 3  # its last sample, before the stop
    assert 0.005 < q.xlim[1] < 0.0052  # a little past the stop, so that the marks show
    assert "failed at t=0.005 s" in page.title
    pixels = np.asarray(paint(page).image)
    for panel in page.panels:  # each dot and the stop's line drawn in red where they are
        for t, values in panel.dots:
            xs, ys = panel.to_pixels(np.full(len(values), t), values)
            for x, y in zip(xs, ys):
                assert is_colour(pixels[round(y), round(x)], rgb("tab:red"))
        x, _ = panel.to_pixels(page.stop, 0.0)
        column = pixels[round(panel.box[3]) - 40:round(panel.box[3]) - 1, round(x) - 1:round(x) + 2].reshape(-1, 3)
        assert 0 < colour_mask(column, rgb("tab:red")).sum() < len(column) / 3  # dashed


def colour_mask(pixels, colour, tolerance: int = 40) -> np.ndarray:
    """Where ``pixels`` (an array of RGB, of any shape) are ``colour``, within ``tolerance``."""
    return np.all(np.abs(np.asarray(pixels)[..., :3].astype(int) - np.asarray(colour[:3])) <= tolerance, axis=-1)


def is_colour(pixel, colour, tolerance: int = 40) -> bool:
    return bool(colour_mask(pixel, colour, tolerance))


def test_a_complete_run_has_no_marks():
    page = layout(described(), ["b.q"])
    assert page.panels[0].dots == [] and page.stop is None
    pixels = np.asarray(paint(page).image)
    assert not colour_mask(pixels[:, ::3], rgb("tab:red"), 10).any()


def test_plot_signals_writes_the_png(tmp_path):
    (written,) = plot_signals(described(), tmp_path / "plots" / "s.png")
    assert written == tmp_path / "plots" / "s.png" and written.read_bytes()[:4] == b"\x89PNG"


def test_an_axis_of_selected_elements_and_one_of_overlaid_signals():
    one, both = layout(described(), ["b.q[fore.1]", "b.q[thumb.1,thumb.2],b.r"]).panels
    assert one.ylabel == "b.q[fore.1]\n(rad)" and one.legend_box is None
    np.testing.assert_allclose(one.curves[0].v[:5], 3 * np.arange(1, 6) * 1e-3)
    assert both.legend_labels == ["b.q[thumb.1]", "b.q[thumb.2]", "b.r"]
    assert both.ylabel.startswith("b.q[thumb.1,thumb.2], b.r")
    assert len({c.style["color"] for c in both.curves}) == 3


def grey_in(pixels, x0: float, x1: float, y0: float, y1: float) -> int:
    """How many pixels of the box are the markers' grey (their lines and words)."""
    box = pixels[round(y0):round(y1), round(x0):round(x1)].reshape(-1, 3)
    return int(colour_mask(box, rgb(MARKER_COLOUR), 25).sum())


def test_markers_are_drawn_on_every_axis_and_named_once():
    from blocks.plot.markers import Marker

    events = [Marker(0.002, 0.002, "", "s: step at 0.002 s"), Marker(0.003, 0.004, "moving", "moved")]
    page = layout(described(), ["b.q", "b.r"], markers=events)
    assert page.markers == events and page.stop is None  # a marker line, not a stop: the run is complete
    pixels = np.asarray(paint(page).image)
    for panel in page.panels:
        line, _ = panel.to_pixels(0.002, 0.0)
        band = [panel.to_pixels(t, 0.0)[0] for t in (0.003, 0.004)]
        mid = (panel.box[1] + panel.box[3]) / 2
        assert grey_in(pixels, line - 1, line + 2, mid - 20, mid + 20) >= 10  # the dotted line, on every panel
        tint = np.median(pixels[round(mid) - 10:round(mid) + 10, round(band[0]) + 2:round(band[1]) - 2], axis=(0, 1))
        assert 225 < tint.min() < 250 and tint.max() - tint.min() < 5  # the band: a light grey over white
        words = grey_in(pixels, line + 1, line + 16, panel.box[1], panel.box[1] + 60)
        assert (words > 20) == (panel is page.panels[0])  # its words once, on the top panel


def test_plot_signals_marks_the_runs_steps_unless_asked_not_to(tmp_path):
    run = described(block_types={"s": "Step"}, parameters={"s": {"time": 0.002}})
    assert [m.start for m in Pages.of(run, tmp_path / "a.png").page(1).markers] == [0.002]
    assert Pages.of(run, tmp_path / "b.png", markers=False).page(1).markers == []


def test_a_signal_of_mixed_units_is_an_axis_per_unit_and_pages_are_balanced(tmp_path):
    many = described()
    many.signals.update({f"c{i}.y": (np.arange(3) * 1e-3, np.ones((3, 1))) for i in range(10)})
    pages = Pages.of(many, tmp_path / "p.png").axes
    written = plot_signals(many, tmp_path / "p.png")
    axes = [[tr.title for tr in traces] for page in pages for traces in page]
    assert axes[:4] == [["b.q"], ["b.pose[x,y]"], ["b.pose[theta]"], ["b.r"]]  # b.pose: m, then rad
    assert [len(p) for p in pages] == [5, 5, 4] and len(written) == 3  # 14 axes: not 6, 6 and 2


def test_an_axis_per_unit_is_labelled_with_that_unit_alone():
    from blocks.plot.select import by_unit, select

    r = described()
    panels = layout(r, by_unit(r, select(r, "b.pose"))).panels
    assert [p.ylabel for p in panels] == ["b.pose[x,y]\n(m)", "b.pose[theta]\n(rad)"]
    assert panels[0].legend_labels == ["x", "y"] and panels[1].legend_box is None


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


def test_a_curve_is_painted_where_its_values_are_and_only_inside_its_panel():
    t = np.arange(100_001) * 1e-5
    v = (t >= 0.5).astype(float)
    v[25_000] = 3.0  # one sample's spike, 10 us wide: far under a pixel column
    run = Results({"a.y": (t, v[:, None])}, {"diagram": "d", "status": "complete", "t_end": 1.0})
    page = layout(run, ["a.y"])
    (panel,) = page.panels
    pixels = np.asarray(paint(page).image)
    blue = colour_mask(pixels, rgb("C0"))
    x0, y0, x1, y1 = panel.box
    rows = {value: round(float(panel.to_pixels(0.0, value)[1])) for value in (0.0, 1.0, 3.0)}
    left, middle, right = (round(float(panel.to_pixels(s, 0.0)[0])) for s in (0.1, 0.5, 0.9))
    assert blue[rows[0.0], left:middle - 3].all() and blue[rows[1.0], middle + 3:right].all()
    assert blue[rows[1.0]:rows[0.0], middle - 2:middle + 3].any(axis=1).all()  # the step's riser
    assert blue[rows[3.0] - 2:rows[3.0] + 3].any()  # the spike reaches its value
    inside = np.zeros_like(blue)
    inside[round(y0):round(y1) + 1, round(x0):round(x1) + 1] = True
    assert not (blue & ~inside).any()  # nothing of the curve outside its panel


def test_non_finite_values_break_the_curve_and_leave_the_range_to_the_finite_ones():
    t = np.arange(5) * 0.25
    v = np.array([0.0, 1.0, np.nan, np.inf, 2.0])[:, None]
    run = Results({"a.y": (t, v)}, {"diagram": "d", "status": "complete", "t_end": 1.0})
    page = layout(run, ["a.y"])
    assert page.panels[0].ylim == pytest.approx((-0.1, 2.1))
    pixels = np.asarray(paint(page).image)
    blue = colour_mask(pixels, rgb("C0"))
    gap = round(float(page.panels[0].to_pixels(0.625, 0.0)[0]))
    assert not blue[:, gap].any() and blue.any()


@pytest.mark.parametrize("values", [[-1e308, 1e308], [-1.7e308, 1.7e308], [1.7e308, 1.79e308], [1e-320, 2e-320],
                                    [np.inf, -np.inf], [1.0, np.inf], [-0.0, 0.0], [5e15, 5e15 + 1]])
def test_extreme_values_are_drawn_on_a_finite_axis_without_a_warning(values):
    import warnings

    run = Results({"a.y": (np.array([0.0, 0.5]), np.array(values)[:, None])},
                  {"diagram": "d", "status": "complete", "t_end": 1.0})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        page = layout(run, ["a.y"])
        paint(page)
    lo, hi = page.panels[0].ylim
    assert np.isfinite([lo, hi]).all() and lo < hi
    finite = [v for v in values if np.isfinite(v)]
    assert all(lo <= v <= hi for v in finite)


def test_labels_of_any_length_stay_on_the_page_and_leave_room_for_the_data():
    from blocks.plot.canvas import text_size
    from blocks.plot.page_layout import LARGE, SIZE

    t = np.arange(10) * 0.1
    long = "b" * 150
    run = Results({f"{long}.y": (t, np.ones((10, 3))), "a.q": (t, np.ones((10, 2))), "c.v": (t, np.ones((10, 20)))},
                  {"diagram": "d " * 300, "t_end": 1.0, "status": "failed at t=0.5 s: " + "boom " * 300,
                   "t_stop": 0.5, "element_labels": {f"{long}.y": ["x" * 400, "y", "z"],
                                                     "c.v": [f"{k}" + "w" * 300 for k in range(20)]},
                   "units": {"a.q": [f"unit{i} " * 20 for i in range(2)]}})
    page = layout(run, list(run))
    assert max(text_size(line, LARGE)[0] for line in page.title.split("\n")) <= page.width
    assert page.title.count("\n") <= 4
    for panel in page.panels:
        x0, y0, x1, y1 = panel.box
        assert x1 - x0 > 0.5 * page.width  # the data keeps half the page's width at least
        assert max(text_size(line, SIZE)[0] for line in panel.ylabel.split("\n")) <= y1 - y0
        if panel.legend_box is not None:
            assert panel.legend_box[2] <= page.width
    paint(page)
