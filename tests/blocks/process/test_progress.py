"""Progress bars draw on a terminal and stay silent in a pipe or with -q."""

import io

from blocks.cli.run import ProgressBar
from blocks.process.progress import progress_bar
from blocks.sweep.progress import SweepProgress


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_bar_draws_on_a_terminal_and_clears_its_line_at_the_end():
    out = Terminal()
    bar = progress_bar(4, "work", unit="step", stream=out, mininterval=0)
    bar.update(2)
    bar.close()
    drawn = out.getvalue()
    assert "work" in drawn and "2/4" in drawn and "\r" in drawn


def test_silent_in_a_pipe_or_when_disabled():
    for stream, enabled in ((io.StringIO(), True), (Terminal(), False)):
        bar = progress_bar(3, "work", stream=stream, enabled=enabled)
        bar.update(3)
        bar.close()
        assert stream.getvalue() == ""


def test_sweep_progress_counts_failures():
    out = Terminal()
    progress = SweepProgress(3, stream=out)
    progress.bar.mininterval = 0
    progress.update(True)
    progress.update(False)
    progress.close()
    assert "2/3" in out.getvalue() and "1 failed" in out.getvalue()


def test_a_run_s_bar_counts_simulated_seconds(monkeypatch):
    out = Terminal()
    monkeypatch.setattr("sys.stderr", out)
    bar = ProgressBar(2.0, enabled=True)
    bar.bar.delay = bar.bar.mininterval = 0  # shown at once, not after a second of running
    bar(0.5, 0.0)
    bar(1.0, 0.0)
    bar.close()
    assert "t = 1 / 2 s" in out.getvalue() and "t = 2 / 2 s" in out.getvalue()
