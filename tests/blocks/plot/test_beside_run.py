"""Plots drawn in forked processes (blocks/plot/beside_run.py): the pages of ``plot_signals``,
a failure brought back as the caller would meet it here, and nothing left running."""

from __future__ import annotations

import errno
import os
import signal

import numpy as np
import pytest

from blocks import Results
from blocks.plot.pages import plot_signals
from blocks.plot.beside_run import FORKS, PlotProcess, PlotProcessError

pytestmark = pytest.mark.skipif(not FORKS, reason="plots are drawn in forked processes on Linux only")


def saved(folder, signals: int = 7):
    """A complete run of ``signals`` logged ramps saved in ``folder`` (two pages of plots)."""
    t = np.arange(5) * 0.1
    r = Results({f"r{i}.y": (t, i * t[:, None]) for i in range(signals)},
                {"status": "complete", "diagram": "ramps", "t_end": 0.4})
    r.save(folder)
    return r


def running(pid: int) -> bool:
    try:
        os.killpg(pid, 0)
        return True
    except OSError:
        return False


def test_the_pages_are_those_drawn_here(tmp_path):
    results = saved(tmp_path / "run")
    here = plot_signals(Results.load(tmp_path / "run"), tmp_path / "here" / "s.png")
    plotter = PlotProcess.start()
    try:
        there = plotter.draw(tmp_path / "run", tmp_path / "there" / "s.png")
    finally:
        plotter.close()
    assert [p.name for p in there] == [p.name for p in here] == ["s-1.png", "s-2.png"]
    assert all(a.read_bytes() == b.read_bytes() for a, b in zip(here, there))
    assert len(results) == 7 and not running(plotter.pid)


def test_a_folder_without_results_is_the_plotters_error_in_words(tmp_path):
    (tmp_path / "empty").mkdir()
    plotter = PlotProcess.start()
    try:
        with pytest.raises(PlotProcessError, match="empty"):
            plotter.draw(tmp_path / "empty", tmp_path / "s.png")
    finally:
        plotter.close()


def test_an_os_error_in_a_drawer_is_raised_here_as_that_os_error(tmp_path):
    saved(tmp_path / "run")
    (tmp_path / "file").write_text("not a folder")
    plotter = PlotProcess.start()
    try:
        with pytest.raises(OSError) as info:
            plotter.draw(tmp_path / "run", tmp_path / "file" / "s.png")
    finally:
        plotter.close()
    assert info.value.errno in (errno.ENOTDIR, errno.EEXIST) and "file" in str(info.value.filename)


def test_a_drawer_killed_by_a_signal_fails_the_plots_naming_the_signal(tmp_path, monkeypatch):
    import blocks.plot.pages

    saved(tmp_path / "run", signals=13)  # three pages: the last in a drawer of its own on two cores
    draw = blocks.plot.pages.Pages.draw

    def dies_on_page_3(pages, number):
        if number == 3:
            os.kill(os.getpid(), signal.SIGKILL)
        return draw(pages, number)

    monkeypatch.setattr(blocks.plot.pages.Pages, "draw", dies_on_page_3)  # the forks inherit it
    plotter = PlotProcess.start()
    drawer = "a page" if len(os.sched_getaffinity(0)) > 1 else "the plots"  # one core: all in the plotter
    try:
        with pytest.raises(PlotProcessError, match=rf"drawing {drawer} ended unexpectedly \(killed by SIGKILL\)"):
            plotter.draw(tmp_path / "run", tmp_path / "plots" / "s.png")
    finally:
        plotter.close()


def test_a_plotter_killed_by_a_signal_is_named_and_closing_leaves_nothing(tmp_path):
    saved(tmp_path / "run")
    plotter = PlotProcess.start()
    os.kill(plotter.pid, signal.SIGKILL)
    try:
        with pytest.raises(PlotProcessError, match=r"ended unexpectedly \(killed by SIGKILL\)"):
            plotter.draw(tmp_path / "run", tmp_path / "s.png")
    finally:
        plotter.close()
    assert not running(plotter.pid)


def test_closing_an_unused_plotter_ends_it(tmp_path):
    plotter = PlotProcess.start()
    plotter.close()
    plotter.close()
    assert not running(plotter.pid)
    with pytest.raises(ProcessLookupError):
        os.kill(plotter.pid, 0)
