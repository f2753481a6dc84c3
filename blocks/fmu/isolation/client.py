"""An FMU instance hosted in a process of its own, seen from the run that uses it.

``HostedInstance`` has the surface of ``instance.Instance`` that the block, its kernel and
the pool use (``start``, ``write``, ``read``, ``step``, ``stop``, ``free``, ``log_text``, ``broken``),
and does each through the channel (``channel``) to its host (``host``), forked by the
launcher (``launcher``). A steady step is one round trip through shared memory (the
inputs and outputs stay there); everything else is a message.

What the host does not survive, the run does. When the host's process ends inside a call
(the FMU crashed: a segmentation fault, an abort, a stack overflow, a bus error from a
truncated binary; or it called ``exit``), or a call takes longer than the block's
``call_timeout`` (the host is then killed), the call raises ``HostFailure``, a BlockError
that names the FMU, the FMU function it was in (traced by the host), the time, and the
signal, exit code or timeout, with the FMU's last log messages; the run fails there with
its results so far. A signal that stops the run (Ctrl-C, SIGTERM) while it waits for the
host is raised as it came; the host, left inside a call, is killed when the instance is
next touched or freed. Terminate and freeInstance run when a run gives its instance back at its end
(``FMU.finish``), before its results are made: a host that dies in either fails the run at
its end time, naming the call. The host's process runs on with the FMU's binary loaded,
pooled for the block's next run, which instantiates the FMU again there (a message, no
new process). A run's state given back only when it is dropped (a run that failed
already) terminates and frees the same way, and a host that dies then is reported on the
``blocks.fmu`` logger as a warning, as is one that dies when the block ends its idle
hosts (``close``, or at exit).
"""

from __future__ import annotations

import os
import select
import signal
import socket
from collections.abc import Mapping
from typing import Any

from blocks.block import BlockError, Signal
from blocks.fmu import interrupt
from blocks.fmu.isolation.channel import (
    ChannelClosed,
    Region,
    decode,
    native,
    ports_of,
    put_ports,
    receive,
    send,
)
from blocks.fmu.instance import Binary
from blocks.fmu.isolation.launcher import Launcher
from blocks.fmu.log_messages import log, log_text

SIGNALS = {
    "SIGSEGV": "a segmentation fault: an invalid memory access, or a stack overflow",
    "SIGBUS": "a bus error: e.g. a truncated or changed binary file",
    "SIGABRT": "an abort: e.g. a failed assertion in the FMU",
    "SIGFPE": "a floating-point exception",
    "SIGILL": "an illegal instruction: e.g. a binary for another processor",
    "SIGKILL": "killed: out of memory, or by another program",
}
"""What the signals that end FMU processes usually mean, for messages."""


class HostFailure(BlockError):
    """The FMU's process ended inside a call, or a call did not return in time."""


class HostedInstance:
    """An FMU instance in a process of its own, with the surface of ``Instance``."""

    hosted = True

    def __init__(self, model: Binary):
        self.model = model
        self.timeout = model.timeout
        self.started = self.used = self.broken = self.freed = False
        self.ended = False
        """Whether the last run ended the FMU's instance (freeInstance in the host, whose
        process runs on): the next run instantiates it again."""
        self.killed = False
        """Whether the host was killed (left inside a call, or too late)."""
        self.status: int | None = None
        """How the host ended once reaped: its exit code, or minus the signal that ended it."""
        self.reaped = False
        self.owner = os.getpid()
        self._outputs_at: float | None = None
        """The time of the outputs in the channel (read with the last step), if any."""
        self._read_error: Exception | None = None
        n_in = sum(width for _, width in model.in_ports)
        n_out = sum(width for _, width in model.out_ports)
        self.region = Region.create(n_in, n_out)
        functions = native()
        self._post, self._wait, self._codes = functions["post"], functions["wait"], functions["codes"]
        ours, theirs = socket.socketpair()
        try:
            self.launcher = Launcher.here()
            self.pid = self.launcher.spawn([theirs.fileno(), self.region.fd])
        except BaseException:
            ours.close()
            self.region.close()
            raise
        finally:
            theirs.close()
        self.sock = ours
        self.sock.settimeout(self.timeout)
        try:
            self._message(("instantiate", model, model.in_ports, model.out_ports), "instantiating it")
        except BaseException:
            self.free()  # the host of an FMU that did not instantiate ends (and is reaped) here
            raise

    # -- the surface of Instance ------------------------------------------------------------

    @property
    def inherited(self) -> bool:
        """Whether this is a copy in a process forked from the one that made it (whose host
        is not this process's)."""
        return self.owner != os.getpid()

    @property
    def usable(self) -> bool:
        """Whether a pooled instance can serve another run: this process's, and its host
        alive (one that ended while idle, killed by another program or with its launcher,
        is broken)."""
        if self.inherited or self.broken:
            return False
        if not self.launcher.running or select.select([self.sock], [], [], 0)[0]:  # readable: its end closed
            self.broken = True
            return False
        return True

    def arm(self) -> None:
        """Nothing to arm: the FMU's callbacks run in its own process."""

    def log_text(self) -> str:
        return log_text(self.region.log_lines())

    def start(self, t: float, assignments: list, tolerance: float | None, inputs: Mapping[str, Signal]) -> None:
        self._usable()
        if self.ended:
            self._message(("instantiate", self.model, self.model.in_ports, self.model.out_ports), "instantiating it")
            self.ended = False
        self.used = True
        put_ports(self.region.inputs, self.model.in_ports, inputs)
        error = self._message(("start", t, assignments, tolerance), f"initialising it at t={t:.9g} s")
        self.started = True
        self._outputs(t, error)

    def write(self, inputs: Mapping[str, Signal], t: float) -> None:
        """Set the inputs at ``t`` (an FMU read with ``feedthrough``): the outputs then read afresh."""
        self._usable()
        put_ports(self.region.inputs, self.model.in_ports, inputs)
        self._outputs_at = None
        self._message(("write", t), f"setting its inputs at t={t:.9g} s")

    def read(self, t: float) -> dict[str, Signal]:
        """The outputs at ``t``: those the last step or start left in the channel, else read."""
        if self._outputs_at != t:
            self._usable()
            self._outputs(t, self._message(("read", t), f"reading its outputs at t={t:.9g} s"))
        if self._read_error is not None:
            raise self._read_error
        values = self.region.outputs.copy()
        return ports_of(values, self.model.out_ports)

    def step(self, inputs: Mapping[str, Signal], t: float, h: float) -> tuple[bool, bool, float]:
        """The step from ``t`` over ``h``: one round trip; (terminate requested, returned
        early, the time reached), as ``Instance.step``."""
        self._usable()
        put_ports(self.region.inputs, self.model.in_ports, inputs)
        self.region.step(t, h)
        self._post(self.region.address)
        try:
            waited = self._wait(self.region.address, self.sock.fileno(), self.timeout)
        except BaseException:
            self._abandon()
            raise
        return self.finish_step(waited, t, h)

    @staticmethod
    def _step_text(t: float, h: float) -> str:
        return f"the step from t={t:.9g} s to {t + h:.9g} s"

    def finish_step(self, waited: int, t: float, h: float) -> tuple[bool, bool, float]:
        """What the step from ``t`` came to, once waiting for it ended with ``waited``
        (HOST_ANSWERED, HOST_GONE, HOST_LATE; the kernel waits in C and hands over here)."""
        codes = self._codes
        if waited == codes["gone"]:
            raise self._gone(self._step_text(t, h))
        if waited == codes["late"]:
            raise self._late(self._step_text(t, h))
        if self.region.answer == codes["done"]:
            self._outputs(t + h, None)
            return False, False, t + h
        reply = self._reply(self._step_text(t, h))
        if reply[0] == "error":
            raise decode(reply[1])
        _, outcome, error = reply
        terminate, early, last = outcome
        if not early:
            self._outputs(last if terminate else t + h, error)
        return terminate, early, last

    def stop(self, report: bool = False) -> None:
        """End a started run: terminate the FMU's simulation, then free its instance
        (freeInstance) in the host, whose process runs on with the binary loaded for the
        next run; an instance whose terminate fails is broken. Called when a run gives the
        instance back: with ``report`` (at the end of the run, before its results are made)
        a host that dies in either call raises its HostFailure, else (a run's state dropped
        later) it is a warning."""
        if not self.started or self.broken or self.inherited:
            return
        self.started = False
        if self.region.pending:
            self._abandon()
            return
        if not self.launcher.running:  # killed from outside, and the host with it: not the FMU's doing
            self.broken = True
            return
        try:
            broken = bool(self._message(("stop",), "terminating it after its run"))
            self._message(("end",), "freeing it after its run")
            self.broken, self.ended = broken, True
        except HostFailure as exc:
            self.broken = True
            if report:
                raise
            log.warning("%s (after the run; its results are complete)", exc)
        except KeyboardInterrupt as exc:
            interrupt.note(exc)
            interrupt.deliver()
        except Exception:
            self.broken = True

    def free(self) -> None:
        """End the host (freeing the FMU's instance there first if no run's end did) and
        close the channel; a host that dies there is a warning: the runs are over."""
        if self.freed:
            return
        self.freed = True
        if self.inherited:
            self._close()
            return
        if not self.broken and not self.killed and not self.region.pending:
            try:
                self._message(("free",), "freeing it")
            except HostFailure as exc:
                log.warning("%s (after the run; its results are complete)", exc)
            except KeyboardInterrupt as exc:
                self._abandon()
                interrupt.note(exc)
                interrupt.deliver()
            except Exception as exc:
                log.debug("%s: freeing the FMU instance failed: %s", self.model.shown, exc)
        self._end()

    # -- the channel ------------------------------------------------------------------------

    def _usable(self) -> None:
        """BlockError unless the instance can take another call: not a copy from another
        process, and not left inside a call that was stopped (its host is killed then)."""
        if self.inherited:
            raise BlockError(f"{self.model.shown}: this FMU instance belongs to the process that made it")
        if self.reaped:
            raise BlockError(f"{self.model.shown}: the FMU's process has ended")
        if self.killed or self.region.pending:
            self._abandon()
            raise BlockError(f"{self.model.shown}: the FMU was stopped inside a call and cannot be used again")

    def _message(self, request: tuple, during: str) -> Any:
        """Send ``request`` and return the value of its answer (an error raised as it was);
        ``during`` says what the request is, for a failure's message."""
        region = self.region
        region.command = self._codes["message"]
        try:
            self._post(region.address)
            send(self.sock, request)
        except BaseException as exc:
            if isinstance(exc, OSError) and not isinstance(exc, TimeoutError):
                raise self._gone(during) from None
            self._abandon()
            if isinstance(exc, TimeoutError):
                raise self._late(during) from None
            raise
        reply = self._reply(during)
        if reply[0] == "error":
            raise decode(reply[1])
        return reply[1]

    def _reply(self, during: str) -> tuple:
        """The host's answer message to the last request (``during``: what it was)."""
        try:
            return receive(self.sock)
        except (ChannelClosed, ConnectionError):
            raise self._gone(during) from None
        except TimeoutError:
            raise self._late(during) from None
        except BaseException:
            self._abandon()
            raise

    def _outputs(self, t: float, error: tuple | None) -> None:
        self._outputs_at = t
        self._read_error = decode(error) if error is not None else None

    # -- failures ---------------------------------------------------------------------------

    def _where(self, during: str) -> str:
        """Where the host was, for messages: the FMU function it traced last, and ``during``
        (the request: 'instantiating it', 'the step from t=... s to ... s', ...)."""
        call = self.region.call
        if call == "loading the binary":
            return f"loading its binary ({during})"
        return f"{call} ({during})" if call else during

    def _gone(self, during: str) -> HostFailure:
        """The failure for a host whose process ended inside a call."""
        where, logged = self._where(during), self.log_text()
        status = self._end()
        shown = self.model.shown
        if status is not None and status < 0:
            try:
                name = signal.Signals(-status).name
            except ValueError:
                name = f"signal {-status}"
            meaning = SIGNALS.get(name)
            text = (f"{shown} crashed in {where}: {name}" + (f" ({meaning})" if meaning else "")
                    + " ended the process that ran it")
        elif status is not None:
            text = (f"{shown} called exit({status}) in {where}, which ended the process that ran it (an FMU "
                    "must return an error status instead)")
        else:
            text = f"{shown}: the process that ran the FMU ended in {where}"
        return HostFailure(text + logged)

    def _late(self, during: str) -> HostFailure:
        """The failure for a call that did not return within the timeout (its host is killed)."""
        where, logged = self._where(during), self.log_text()
        self._abandon()
        self._end()
        return HostFailure(f"{self.model.shown}: {where} did not return within {self.timeout:g} s, so the FMU was "
                           f"stopped{logged} (hint: if the FMU needs longer for one call, raise the block's "
                           "'call_timeout', e.g. 'call_timeout: 1 h')")

    def _abandon(self) -> None:
        """The host is left inside a call (or its state is unknown): kill it, break the instance."""
        self.broken = True
        if not self.killed and not self.inherited and not self.reaped:  # a reaped host's pid may be another's
            self.killed = True
            try:
                os.kill(self.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass

    def _end(self) -> int | None:
        """Close the channel and reap the host: how it ended (``status``; None if unknown)."""
        self.broken = True
        if not self.reaped and not self.inherited:
            self.reaped = True
            self._close()
            try:
                self.status = self.launcher.ended(self.pid)
            except (OSError, BlockError):
                self.status = None
        return self.status

    def _close(self) -> None:
        if self.sock.fileno() >= 0:
            self.sock.close()
        self.region.close()

    def __repr__(self) -> str:
        return f"HostedInstance({self.model.shown}, pid {getattr(self, 'pid', None)})"

