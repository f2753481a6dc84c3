"""A run's plots drawn beside it: a process forked as ``run --plot`` starts imports
matplotlib and loads its fonts while the diagram loads and runs, then draws the saved
results' pages, shared out between a process per core, so that the pictures cost little
more than the run.

In a process of its own the imports overlap the run, and the pages overlap each other,
on a machine with two cores or more. ``PlotProcess.start`` returns None where
processes cannot be forked (not Linux), and the caller draws in its own process.

The plotter and its drawers ignore SIGINT (a Ctrl-C at the terminal reaches them too: the
run's process decides what it means) and ask for SIGKILL when their parent exits; they
form a process group of their own, which ``close`` kills as one. The plotter answers one
request, a line of JSON (the results folder and the plot's path), with one line of JSON:
the files written, or why not (an OSError with its errno, strerror and filename, which
the caller raises again as such, or any other failure's text).
"""

from __future__ import annotations

import contextlib
import gc
import json
import os
import signal
import sys
import time
from collections.abc import Iterator
from pathlib import Path

from blocks.process.forked import die_with

FORKS = sys.platform.startswith("linux")
"""Whether plots are drawn in forked processes here (elsewhere: in the run's process)."""

GONE_SECONDS = 2.0
"""How long ``close`` waits for the killed processes to be gone."""


class PlotProcessError(RuntimeError):
    """The plots could not be drawn in their processes: one failed, or ended unexpectedly."""


class PlotProcess:
    """The plotter, forked by ``start``; ``draw`` once, then ``close`` (also after a failure)."""

    def __init__(self, pid: int, requests: int, replies: int):
        self.pid = pid
        self._requests, self._replies = requests, replies
        self._ended = False

    @classmethod
    def start(cls, warm_page: bool = True) -> "PlotProcess | None":
        """Fork the plotter (None where it cannot be: not Linux, or the fork failed); with
        ``warm_page`` it draws a page into memory while it waits (``_warm``)."""
        if not FORKS:
            return None
        requests = replies = None
        try:
            requests, replies = os.pipe(), os.pipe()
            parent = os.getpid()
            pid = os.fork()
        except OSError:
            for fd in (requests or ()) + (replies or ()):
                os.close(fd)
            return None
        if pid == 0:
            os.close(requests[1])
            os.close(replies[0])
            _plotter(parent, requests[0], replies[1], warm_page)
        os.close(requests[0])
        os.close(replies[1])
        try:  # the child makes its group too: whichever runs first, killpg finds it
            os.setpgid(pid, pid)
        except OSError:
            pass
        return cls(pid, requests[1], replies[0])

    def draw(self, folder: Path, path: Path, signals: list[str] | None = None, markers: bool = True) -> list[Path]:
        """The files of ``plot_signals(results, path, signals, markers=markers)`` for the
        results saved in ``folder``; the OSError or ValueError (a selection of nothing
        logged) a drawer met, or ``PlotProcessError``. A stop request (a signal) while they
        are drawn goes on up; ``close`` then kills them."""
        request = json.dumps({"folder": str(folder), "path": str(path), "signals": signals,
                              "markers": bool(markers)}) + "\n"
        try:
            try:
                os.write(self._requests, request.encode())
            except OSError:  # the plotter is gone: its exit status says why
                pass
            reply = _read_line(self._replies)
            status = self._reap()
        except BaseException:  # stopped: no drawer may write on while the caller cleans up
            self.close()
            raise
        if reply is None:
            raise PlotProcessError(f"the process drawing the plots ended unexpectedly ({status})")
        return _files(json.loads(reply))

    def close(self) -> None:
        """Kill the plotter and its drawers if they are still at work, and wait for them."""
        for fd in (self._requests, self._replies):
            try:
                os.close(fd)
            except OSError:
                pass
        self._requests = self._replies = -1
        if self._ended:
            return
        try:
            os.killpg(self.pid, signal.SIGKILL)
        except OSError:
            pass
        self._reap()
        deadline = time.monotonic() + GONE_SECONDS
        while time.monotonic() < deadline:  # the drawers, which the plotter's death also kills
            try:
                os.killpg(self.pid, 0)
            except OSError:
                break
            time.sleep(0.002)

    def _reap(self) -> str:
        """Wait for the plotter to end: how it ended, in words."""
        if self._ended:
            return "ended"
        try:
            _, status = os.waitpid(self.pid, 0)
        except ChildProcessError:  # reaped already (SIGCHLD ignored by the program)
            self._ended = True
            return "ended"
        self._ended = True
        return _how(status)


@contextlib.contextmanager
def plotter_beside(wanted: bool = True, warm_page: bool = True) -> Iterator[PlotProcess | None]:
    """A started plotter (None if not ``wanted`` or where it cannot be forked), closed at
    the block's end whatever happens; ``warm_page`` as ``PlotProcess.start`` takes it."""
    plotter = PlotProcess.start(warm_page) if wanted else None
    try:
        yield plotter
    finally:
        if plotter is not None:
            plotter.close()


def _how(status: int) -> str:
    if os.WIFSIGNALED(status):
        return f"killed by {signal.Signals(os.WTERMSIG(status)).name}"
    return f"exit code {os.waitstatus_to_exitcode(status)}"


def _read_line(fd: int) -> str | None:
    """One line read from ``fd`` (None if it closes first)."""
    data = b""
    while not data.endswith(b"\n"):
        chunk = os.read(fd, 65536)
        if not chunk:
            return None
        data += chunk
    return data.decode()


def _files(reply: dict) -> list[Path]:
    if "files" in reply:
        return [Path(f) for f in reply["files"]]
    if reply.get("kind") == "OSError":
        raise OSError(reply["errno"], reply["strerror"], reply["filename"])
    if reply.get("kind") == "ValueError":
        raise ValueError(reply["text"])
    raise PlotProcessError(reply["text"])


def _outcome(call) -> dict:
    """``call()``'s files as a reply, or its failure."""
    try:
        return {"files": [str(f) for f in call()]}
    except OSError as exc:
        if exc.errno is None:
            return {"kind": "error", "text": str(exc)}
        return {"kind": "OSError", "errno": exc.errno, "strerror": exc.strerror,
                "filename": None if exc.filename is None else str(exc.filename)}
    except (ValueError, KeyError) as exc:  # what the caller reports as bad input
        return {"kind": "ValueError", "text": exc.args[0] if isinstance(exc, KeyError) and exc.args else str(exc)}
    except BaseException as exc:
        return {"kind": "error", "text": f"{type(exc).__name__}: {exc}"}


def _detached(parent: int) -> None:
    """A helper's first steps: ignore Ctrl-C, take SIGTERM's default, die with ``parent``."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGTTOU, signal.SIG_IGN)  # a warning on the terminal from outside its group
    die_with(parent)


def _plotter(parent: int, requests: int, replies: int, warm_page: bool) -> None:
    """The plotter's life: get ready to draw, answer the request, exit (never returns)."""
    try:
        _detached(parent)
        os.setpgid(0, 0)
        gc.disable()  # a short life, one page each: collections would only cost time (and copy pages)
        _warm(warm_page)
        line = _read_line(requests)
        if line is None:  # the run ended without plots
            os._exit(0)
        request = json.loads(line)
        reply = _outcome(lambda: _draw(Path(request["folder"]), Path(request["path"]), request["signals"],
                                       request["markers"]))
        os.write(replies, (json.dumps(reply) + "\n").encode())
    except BaseException:
        os._exit(1)
    os._exit(0)


def _warm(page: bool) -> None:
    """Import what drawing needs (matplotlib, the installed marker sources too) and, with
    ``page``, draw a small page of every kind of thing a page has, into memory: a first page
    costs more than later ones (the fonts, first calls), here while the run runs. Where
    no run is there to overlap (``plot``) the page would only delay the first real one."""
    import io

    import numpy as np

    from blocks.plot.figure import signal_figure
    from blocks.plot.markers import Marker, marker_sources
    from blocks.plot.pages import SAVE_OPTIONS
    from blocks.plot.select import select
    from blocks.results.signals import Results

    marker_sources()  # what a source that fails to load says comes with the plot
    if not page:
        return
    t = np.linspace(0.0, 1.0, 5000)
    run = Results({"w.y": (t, np.column_stack([np.sin(t), np.cos(t)]))},
                  {"diagram": "warm", "status": "failed at t=1 s: warm", "t_end": 2.0, "t_stop": 1.0,
                   "element_labels": {"w.y": ["a.1", "a.2"]}, "units": {"w.y": "m"}})
    fig = signal_figure(run, [select(run, "w.y")],
                        markers=[Marker(0.2, 0.2, "", "warm"), Marker(0.4, 0.6, "span", "warm")])
    fig.savefig(io.BytesIO(), format="png", **SAVE_OPTIONS[".png"])


def _draw(folder: Path, path: Path, signals: list[str] | None, markers: bool) -> list[Path]:
    """The plot of the results in ``folder``, its pages shared out between the cores: the
    first share drawn here, every other in a forked drawer (a process per page would pay
    for more forks than the cores give back)."""
    from blocks.plot.pages import Pages, balanced
    from blocks.results.signals import Results

    pages = Pages.of(Results.load(folder), path, signals, markers=markers)
    cores = len(os.sched_getaffinity(0))
    shares = balanced(list(range(1, len(pages) + 1)), -(-len(pages) // cores))
    me = os.getpid()
    drawers = []
    for share in shares[1:]:
        read, write = os.pipe()
        pid = os.fork()
        if pid == 0:
            try:
                os.close(read)
                die_with(me)
                reply = _outcome(lambda share=share: [pages.draw(n) for n in share])
                os.write(write, (json.dumps(reply) + "\n").encode())
            except BaseException:
                os._exit(1)
            os._exit(0)
        os.close(write)
        drawers.append((pid, read))
    replies = [_outcome(lambda: [pages.draw(n) for n in shares[0]])]
    for pid, read in drawers:
        line = _read_line(read)
        os.close(read)
        _, status = os.waitpid(pid, 0)
        replies.append(json.loads(line) if line is not None else
                       {"kind": "error", "text": f"the process drawing a page ended unexpectedly ({_how(status)})"})
    files = []
    for reply in replies:
        files += _files(reply)
    return files
