"""The status line redraws in place on a terminal and stays silent elsewhere."""

import io

from blocks.process.status_line import StatusLine
from blocks.sweep.progress import SweepProgress


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_redraws_on_a_terminal_and_ends_with_a_newline():
    out = Terminal()
    line = StatusLine(stream=out)
    line.show("1/2")
    line.show("2/2")
    line.close()
    assert out.getvalue() == "\r1/2 \r2/2 \n"


def test_silent_in_a_pipe_or_when_disabled():
    for line in (StatusLine(stream=io.StringIO()), StatusLine(False, Terminal())):
        line.show("x")
        line.close()
        assert line.stream.getvalue() == ""


def test_sweep_progress_counts_failures():
    out = Terminal()
    progress = SweepProgress(3, stream=out)
    progress.update(True)
    progress.update(False)
    progress.close()
    assert "2/3 done, 1 failed" in out.getvalue() and out.getvalue().endswith("\n")
