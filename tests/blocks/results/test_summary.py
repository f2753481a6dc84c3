"""How Results show themselves: a repr with the status and a table of signals, and the
same table as HTML for Jupyter."""

from __future__ import annotations

import numpy as np

from blocks import Results


def results() -> Results:
    return Results({"plant.obj": (np.array([0.0, 0.5, 1.0]), np.zeros((3, 3))),
                    "ctrl.u": (np.array([0.0, 1.0]), np.zeros((2, 1))),
                    "x.<b>": (np.array([]), np.zeros((0, 2)))},
                   {"diagram": "demo", "status": "complete", "t_end": 1.0, "wall_time_s": 0.25,
                    "units": {"plant.obj": ["m", "m", "rad"], "ctrl.u": "N m"}})


def test_repr_is_a_heading_and_an_aligned_table_of_the_signals():
    assert repr(results()).splitlines() == [
        "<Results demo: complete, t_end 1 s, wall 0.25 s, 3 signals>",
        "  signal     width  samples  time      unit",
        "  plant.obj  3      3        0 to 1 s  m, m, rad",
        "  ctrl.u     1      2        0 to 1 s  N m",
        "  x.<b>      2      0        -",
    ]


def test_results_without_signals_or_record_still_say_what_they_are():
    assert repr(Results({}, {})) == "<Results complete, 0 signals>"


def test_jupyter_shows_the_table_as_html_with_names_escaped():
    page = results()._repr_html_()
    assert page.count("<tr>") == 4 and "<th>unit</th>" in page
    assert "<td>m, m, rad</td>" in page and "<td>x.&lt;b&gt;</td>" in page
