"""The FMU host: one FMU instance in a process of its own, answering the run that uses it.

A host is forked by the launcher (``launcher``) for each hosted instance and runs
``serve`` until the run frees the instance or its process is gone. It makes the instance
as the run's process would (``pool.new_instance``'s classes: the same fmpy calls, the same
checks and messages), so results are the same to the last bit; what it adds is:

- tracing: before each call into the FMU it writes the FMU function's name into the
  channel (``Region.mark``; the C loops do the same, ``fmi_step_calls.h`` and ``fmu_me_integration.c``), so
  that when the FMU kills its process the run can say in which call;
- the log: the FMU's messages also go into the channel, where the run reads them after
  a failure, even one the host did not survive;
- the steady step in C: for a co-simulation FMU whose ports are all Float64 the channel's
  C loop (``serve`` of fmu_channel.c) sets the inputs, steps and gets the outputs itself, on
  the channel's values, and comes back here only for a step that was not a plain success.

Requests are the messages of ``channel``: ``("instantiate", binary, inputs, outputs)``,
``("start", t, assignments, tolerance)``, ``("write", t)`` (set the channel's inputs: an FMU
read with ``feedthrough``), ``("read", t)``, ``("stop",)`` (terminate), ``("end",)``
(freeInstance after a run: the binary stays loaded, the process runs on, and the next run
instantiates again), ``("free",)`` (the host ends);
a step is the channel's HOST_STEP. Every answer is ``("ok", value)``, ``("error",
exception)`` or, for a step, ``("outcome", outcome, read error)``.
"""

from __future__ import annotations

import collections
import ctypes
import functools
import os
import socket
from typing import Any, Callable

from blocks.fmu import native as compiled
from blocks.fmu.isolation.channel import Region, encode, native, ports_of, put_ports, receive, send
from blocks.fmu.cosimulation import CoSimulation
from blocks.fmu.exchange import ModelExchange
from blocks.fmu.instance import Binary, Instance, call_failed
from blocks.fmu.log_messages import LOG_LINES
from blocks.fmu.pool import instance_class

LOADING = "loading the binary"
"""What the host traces while the FMU's binary is loaded (its constructors run then)."""


class SharedLog(collections.deque):
    """An instance's log messages, also kept in the channel for the run to read."""

    def __init__(self, region: Region):
        super().__init__(maxlen=LOG_LINES)
        self.region = region

    def append(self, line: str) -> None:
        super().append(line)
        self.region.log(line)

    def clear(self) -> None:
        super().clear()
        self.region.clear_log()


class Traced:
    """One of the FMU's functions (an fmpy ctypes function) that names itself in the
    channel before each call; ``traced`` is the function itself (``instance.function_address``
    reads its address there), and its ctypes attributes are the function's, which fmpy's
    calls read."""

    __slots__ = ("mark", "name", "traced", "restype", "argtypes", "argnames")

    def __init__(self, mark: Callable[[str], None], name: str, function: Any):
        self.mark, self.name, self.traced = mark, name, function
        self.restype, self.argtypes = function.restype, function.argtypes
        self.argnames = getattr(function, "argnames", None)

    def __call__(self, *args: Any) -> Any:
        self.mark(self.name)
        return self.traced(*args)


@functools.cache
def hosted_class(cls: type) -> type:
    """The instance class ``cls`` as a host makes it: its log kept in the channel, and every
    call into the FMU from Python traced, from the moment the binary is loaded (the
    instance's value transfers, doStep and continuous-time functions are made from the
    fmpy functions traced here)."""
    class Hosted(cls):
        region: Region

        def _load(self, fmpy: Any, kwargs: dict[str, str]) -> Any:
            self.messages = SharedLog(self.region)
            self.region.mark(LOADING)
            slave = super()._load(fmpy, kwargs)
            for name, function in list(slave._functions.items()):
                slave._functions[name] = Traced(self.region.mark, name, function)
            return slave

    Hosted.__name__ = Hosted.__qualname__ = f"Hosted{cls.__name__}"
    return Hosted


class Host:
    """One hosted instance and its channel: the loop of ``serve``."""

    def __init__(self, sock: socket.socket, region: Region):
        self.sock, self.region = sock, region
        self.codes = native()["codes"]
        self.inst: Instance | None = None
        self.inputs: list[tuple[str, int]] = []
        self.outputs: list[tuple[str, int]] = []
        self.input_views: dict[str, Any] = {}
        """The input ports' values in the channel (views), as the instance reads them."""
        self.table: Any = None
        """The FMU_* table of the steady step in C (fmu_step_table.h), for a co-simulation FMU with
        Float64 ports only; None for one that steps here."""
        self._me_names: Any = None
        self._step_names: dict[str, Any] = {}
        """The C names of the traced calls (kept alive for the C loops)."""
        self.done = False

    def run(self) -> None:
        serve, answer = native()["serve"], native()["answer"]
        address, fd = self.region.address, self.sock.fileno()
        while not self.done:
            table = self.table.ctypes.data if self.table is not None else 0
            command, kind, status = serve(address, fd, table)
            if command == self.codes["orphan"]:
                return
            reply = self.step(kind, status) if command == self.codes["step"] else self.handle(receive(self.sock))
            if reply is None:  # a step that was a plain success: the outputs are in the channel
                answer(address, self.codes["done"])
                continue
            answer(address, self.codes["message"])
            send(self.sock, reply)

    # -- requests -------------------------------------------------------------------------

    REQUESTS = ("instantiate", "start", "write", "read", "stop", "end", "free")
    """The messages the run sends, each answered by the method of its name."""

    def handle(self, request: tuple) -> tuple:
        what, *args = request
        try:
            if what not in self.REQUESTS:
                raise ValueError(f"the FMU host got an unknown request {what!r}")
            return ("ok", getattr(self, what)(*args))
        except Exception as exc:
            self.ready(False)
            return ("error", encode(exc))

    def instantiate(self, binary: Binary, inputs: list[tuple[str, int]], outputs: list[tuple[str, int]]) -> None:
        """The instance: made (its binary loaded) the first time, made again on the loaded
        binary after a run ended the last one (``end``)."""
        self.ready(False)
        self.table = None
        if self.inst is None:
            cls = hosted_class(instance_class(binary))
            cls.region = self.region
            self.inputs, self.outputs = inputs, outputs
            self.input_views = ports_of(self.region.inputs, inputs)
            self.inst = inst = cls(binary)
        else:
            inst = self.inst
            inst.renew()
        self._trace(inst)
        if isinstance(inst, CoSimulation) and all(x.kind.name == "Float64" for x in (*inst.writes, *inst.reads)):
            self.table = self._fast_table(inst)

    def start(self, t: float, assignments: list, tolerance: float | None) -> tuple | None:
        self.ready(False)
        self.inst.start(t, assignments, tolerance, self.input_views)
        error = self._read(t)
        self.ready(error is None)
        return error

    def write(self, t: float) -> None:
        self.inst.write(self.input_views, t)

    def read(self, t: float) -> tuple | None:
        return self._read(t)

    def stop(self) -> bool:
        self.ready(False)
        self.inst.stop()
        return self.inst.broken

    def end(self) -> None:
        """The run is over: free the FMU's instance (freeInstance), keeping its binary
        loaded and this process running for the next run (``instantiate``)."""
        self.ready(False)
        self.table = None
        self.inst.end()

    def free(self) -> None:
        self.ready(False)
        self.done = True
        if self.inst is not None:
            self.inst.free()

    def step(self, kind: int, status: int) -> tuple | None:
        """A step that the C loop did not finish (``kind``: the call that was not a plain
        success, 0 for a step it did not take) and what it came to: None for a plain success
        (the outputs at the step's end are in the channel), else the answer to send."""
        inst, kinds = self.inst, compiled.native()["kinds"]
        t, h = self.region.asked
        read_error = None
        try:
            if kind == 0:
                outcome = inst.step(self.input_views, t, h)
            elif kind == kinds["set"]:
                raise call_failed(inst.writes[0].function, status)
            elif kind == kinds["step"]:
                outcome = inst.outcome(status, t, h)
            else:
                outcome, read_error = (False, False, t + h), encode(call_failed(inst.reads[0].function, status))
        except Exception as exc:
            self.ready(False)
            return ("error", encode(exc))
        terminate, early, last = outcome
        if read_error is None and not early:
            read_error = self._read(last if terminate else t + h)
        if not (terminate or early or read_error is not None):
            return None
        self.ready(False)
        return ("outcome", outcome, read_error)

    # -- helpers ----------------------------------------------------------------------------

    def _read(self, t: float) -> tuple | None:
        """The outputs at ``t`` into the channel; the error reading them raised, if any."""
        try:
            got = self.inst.read(t)
        except Exception as exc:
            self.ready(False)
            return encode(exc)
        put_ports(self.region.outputs, self.outputs, got)
        return None

    def ready(self, ready: bool) -> None:
        """Whether the C loop may answer the next steps by itself."""
        if self.table is not None:
            self.table[compiled.native()["slots"]["ready"]] = int(ready)

    def _trace(self, inst: Instance) -> None:
        """The C loops of a model-exchange instance name their calls too (fmu_me_integration.c's ME_TRACE)."""
        if not isinstance(inst, ModelExchange):
            return
        calls = inst.calls
        names = [b""] * (max(calls.layout["calls"].values()) + 1)
        for key, code in calls.layout["calls"].items():
            names[code] = calls.names[key].encode()
        self._me_names = (ctypes.c_char_p * len(names))(*names)
        slots = calls.layout["slots"]
        calls.table[slots["trace"]] = self.region.call_address
        calls.table[slots["trace_names"]] = ctypes.addressof(self._me_names)

    def _fast_table(self, inst: CoSimulation) -> Any:
        """The FMU_* table (fmu_step_table.h) of the C loop's steady step, on the channel's values."""
        import numpy as np

        slots = compiled.native()["slots"]
        table = np.zeros(slots["ports"], dtype=np.int64)
        names = {}
        for verb, transfers, buf in (("set", inst.writes, self.region.inputs_address),
                                     ("get", inst.reads, self.region.outputs_address)):
            if not transfers:
                continue
            (x,) = transfers
            table[slots[verb]] = x.address
            table[slots[f"{verb}_vrs"]] = ctypes.addressof(x.vrs)
            table[slots[f"{verb}_nvr"]] = len(x.vrs)
            table[slots[f"{verb}_buf"]] = buf
            table[slots[f"{verb}_count"]] = x.view.size
            names[verb] = x.function
        names["step"] = f"fmi{inst.model.major}DoStep"
        self._step_names = {verb: ctypes.create_string_buffer(name.encode()) for verb, name in names.items()}
        for verb, buffer in self._step_names.items():
            table[slots[f"trace_{verb}"]] = ctypes.addressof(buffer)
        table[slots["trace"]] = self.region.call_address
        table[slots["version"]] = inst.model.major
        table[slots["component"]] = inst.component
        table[slots["do_step"]] = inst.do_step_address()
        if inst.model.major == 3:
            for i, flag in enumerate(inst.step_flags):
                table[slots["flags"] + i] = ctypes.addressof(flag)
        return table


def serve(sock_fd: int, region_fd: int) -> None:
    """The host's life: serve the run through the channel of ``sock_fd`` (its end of the
    socket pair) and ``region_fd`` (the shared memory) until the instance is freed or the
    run's process is gone. Called in the forked host process; returns when done."""
    sock = socket.socket(fileno=sock_fd)
    region = Region(region_fd)
    os.set_blocking(sock_fd, True)
    Host(sock, region).run()
