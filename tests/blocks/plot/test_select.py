"""Plot selections: signals, elements by label, index and slice, overlays, and the one-line
errors for what was not logged."""

from __future__ import annotations

import numpy as np
import pytest

from blocks import Results
from blocks.plot.select import SelectionError, select, split_signals


def results() -> Results:
    t = np.arange(4.0)
    signals = {"plant.q": (t, np.arange(24.0).reshape(4, 6)), "ref.y": (t, np.ones((4, 1))),
               "fmu.y": (t, np.zeros((4, 2))), "ctrl.inner.pi.y": (t, np.zeros((4, 2)))}
    info = {"element_labels": {"plant.q": ["thumb.1", "thumb.2", "fore.1", "fore.2", "1,1", "3"],
                               "fmu.y": ["1", "2"]}}
    return Results(signals, info)


def columns(text):
    return [(tr.signal, tr.columns, tr.labels, tr.title) for tr in select(results(), text)]


def test_a_signal_is_every_element_with_its_labels():
    assert columns("plant.q") == [("plant.q", (0, 1, 2, 3, 4, 5),
                                   ("thumb.1", "thumb.2", "fore.1", "fore.2", "1,1", "3"), "plant.q")]
    assert columns("ref.y") == [("ref.y", (0,), ("[0]",), "ref.y")]


@pytest.mark.parametrize("text, picked", [
    ("plant.q[fore.1]", (2,)), ("plant.q[0]", (0,)), ("plant.q[-1]", (5,)), ("plant.q[1:4]", (1, 2, 3)),
    ("plant.q[::2]", (0, 2, 4)), ("plant.q[thumb.2,fore.2]", (1, 3)), ("plant.q[fore.1, 0]", (2, 0)),
    ("plant.q[1,1]", (4,)),  # a label with a comma is a label
    ("plant.q[3]", (5,)),  # a label wins over an index
    ("fmu.y[1]", (0,)),  # the FMU's y[1] is its first element
    ("ctrl.inner.pi.y[1]", (1,)),  # a signal of a block inside nested subsystems
])
def test_elements_by_label_index_and_slice(text, picked):
    (trace,) = select(results(), text)
    assert trace.columns == picked and trace.title == text and not trace.whole


def test_commas_outside_brackets_overlay_signals():
    assert split_signals("plant.q[1,1],ref.y, fmu.y[2]") == ["plant.q[1,1]", "ref.y", "fmu.y[2]"]
    assert [t[0] for t in columns("plant.q[fore.1],ref.y")] == ["plant.q", "ref.y"]


@pytest.mark.parametrize("text, word", [
    ("nope.y", "signal 'nope.y' was not logged; logged signals: plant.q, ref.y, fmu.y, ctrl.inner.pi.y"),
    ("plant.q[fore.9]", "has no element 'fore.9'; its elements: thumb.1, thumb.2"),
    ("plant.q[6]", "index 6 is out of range"), ("plant.q[4:2]", "selects no element"),
    ("plant.q[::0]", "step must not be 0"), ("plant", "is not a signal"), ("ref.y,", "'' is not a signal"),
])
def test_a_selection_of_nothing_logged_is_one_line(text, word):
    with pytest.raises(SelectionError, match=word.replace("[", r"\[")) as err:
        select(results(), text)
    assert "\n" not in str(err.value)
