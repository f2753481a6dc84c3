"""The FMU block's compiled kernel (``blocks/csrc/fmu_block_step.c``): the steady step in C, the rest in Python.

``fmu_kernel(block)`` offers a kernel for a co-simulation FMU whose ports are all Float64
(FMI 2 Real, FMI 3 Float64); ports of other types keep their range checks and conversions
in Python, so such an FMU runs through the block's Python methods, as does a
model-exchange FMU (whose integration between the hits runs in C of its own, fmu_me_integration.c,
see ``solvers``). The kernel's state is a live
instance, so it has a ``bind``: each run gets a ``KernelRun``, whose int64 table is the C
functions' context (its layout from ``blocks._native.fmu_kernel()``) and whose float64
values hold the FMU's time, step and held outputs.

The C side steps a started, healthy instance at the right time by itself: set the inputs,
doStep, get the outputs. For everything else it calls the ``KernelRun`` (``slow``), which
brings the run's FMUState up to date from the table, runs the block's own Python code from
that point and writes the outcome back: the first call (taking an instance from the pool,
initialising it with the inputs of that moment), a step the Python update would refuse,
a call that returned worse than a warning, a doStep that asks to terminate or returned
early. So messages, EndRun and Ctrl-C are the Python methods' own, and the values that
reach the FMU and come back are the same, to the last bit.

An instance in a process of its own (``hosted.HostedInstance``) has the same kernel: its
table holds the instance's channel instead of the FMU's functions (``attach_hosted``), the
C step writes the inputs into the channel and reads the outputs from it, and a step that
was not a plain success (or whose host ended or timed out, or a signal that came while
it waited) is handed to ``hosted`` with how the waiting ended.
"""

from __future__ import annotations

import ctypes
import functools
from typing import Any

import numpy as np

from blocks.block import EndRun
from blocks.engine.compiled import failure
from blocks.engine.kernel import END_RUN, Kernel, address
from blocks.fmu import interrupt
from blocks.fmu.native import native
from blocks.fmu.isolation.client import HostedInstance
from blocks.fmu.instance import Instance, call_failed
from blocks.fmu.log_messages import fmi2_logger_arming


def fmu_kernel(block: Any) -> Kernel | None:
    """The FMU block's kernel, to ``bind`` to each run's FMUState; None unless the FMU
    runs as co-simulation and every port is Float64."""
    layout = native()
    model = block._model
    if layout is None or model.exchange or any(
            p.kind.name != "Float64" for p in (*model.inputs.values(), *model.outputs.values())):
        return None
    return Kernel(context=0, output=layout["output"], update=layout["update"],
                  bind=functools.partial(KernelRun.bound, block, layout))


HANDLERS = {"output": "output", "update": "update", "arm": "arm", "set": "set_failed", "step": "stepped",
            "get": "get_failed", "hosted": "hosted"}
"""The method of ``KernelRun`` for each kind of ``slow`` call of fmu_block_step.c."""


def _raise(exc: BaseException) -> None:
    raise exc


class KernelRun:
    """One run of an FMU block through its kernel: the context the C functions read and
    write, and the Python side they call (``__call__``) for all but the steady step."""

    def __init__(self, block: Any, state: Any, layout: dict[str, Any]):
        self.block, self.state = block, state
        self.slots: dict[str, int] = layout["slots"]
        self.at: dict[str, int] = layout["values"]
        self.kinds = {code: HANDLERS[kind] for kind, code in layout["kinds"].items()}
        """What ``slow`` is asked to do, by code: a method name (no bound methods, which
        would make the run a reference cycle and keep its instance from the pool)."""
        self.ended: EndRun | None = None
        """The EndRun of the update that ended the run, for the kernel's error factory."""
        self.instance: Instance | None = None
        """The instance whose functions the table holds."""
        width = sum(block.outputs.values())
        self.table = np.zeros(self.slots["ports"] + 2 * (len(block.inputs) + len(block.outputs)), dtype=np.int64)
        self.values = np.zeros(self.at["held"] + width)
        self.values[self.at["step"]] = block._step
        self.set(slow=id(self), check=id(interrupt.check), hook=id(interrupt.hook), values=address(self.values),
                 width=width, n_in=len(block.inputs), n_out=len(block.outputs))

    @classmethod
    def bound(cls, block: Any, layout: dict[str, Any], state: Any) -> Kernel:
        """``Kernel.bind``: the kernel of one run, its context this run's table."""
        run = cls(block, state, layout)
        return Kernel(context=address(run.table), output=layout["output"], update=layout["update"],
                      owners=(run, run.table, run.values, interrupt.check, interrupt.hook), error=run.error)

    def set(self, **slots: int) -> None:
        for name, value in slots.items():
            self.table[self.slots[name]] = value

    def error(self, code: int, which: int, t: float, phase: str) -> BaseException:
        """``Kernel.error``: the EndRun of the update that asked to end the run."""
        if code == END_RUN and self.ended is not None:
            return self.ended
        return failure(code, which, t, phase)

    # -- between the table and the FMUState ---------------------------------------------

    def __call__(self, kind: int, t: float, status: int) -> int:
        """``slow``: the Python side of what the C step does not do itself; 1 when the
        update ended the run (EndRun), else 0. A failure is raised, as by the block."""
        self.load()
        try:
            return getattr(self, self.kinds[kind])(t, status)
        finally:
            self.store()

    def load(self) -> None:
        """The FMUState as the C steps left it: the FMU's time and outputs."""
        if self.table[self.slots["started"]]:
            self.state.time = float(self.values[self.at["time"]])
            held = self.values[self.at["held"]:]
            outputs, first = {}, 0
            for port, width in self.block.outputs.items():
                outputs[port] = held[first:first + width].copy()
                first += width
            self.state.outputs = outputs

    def store(self) -> None:
        """The table as the Python side left the FMUState: time, outputs, whether the C
        step may go on (and, once there is an instance, its functions and buffers)."""
        state = self.state
        started = state.time is not None and state.outputs is not None
        if started:
            self.values[self.at["time"]] = state.time
            held = self.values[self.at["held"]:]
            first = 0
            for port, width in self.block.outputs.items():
                held[first:first + width] = state.outputs[port]
                first += width
        inst = state.instance
        if inst is not None and inst is not self.instance and inst.started:
            self.attach(inst)
        ready = started and inst is not None and inst is self.instance and not inst.broken and state.ended is None
        self.set(started=started, ready=ready)

    def attach(self, inst: Instance | HostedInstance) -> None:
        """Put the instance's component, set / doStep / get functions and buffers in the table
        (for an instance in a process of its own: its channel, whose values are the buffers)."""
        self.instance = inst
        if isinstance(inst, HostedInstance):
            self.attach_hosted(inst)
            return
        self.set(version=inst.model.major, component=inst.component, do_step=inst.do_step_address())
        ports = self.slots["ports"]
        for verb, transfers, names in (("set", inst.writes, self.block.inputs), ("get", inst.reads, self.block.outputs)):
            if not transfers:
                continue
            (x,) = transfers
            self.set(**{verb: x.address, f"{verb}_vrs": ctypes.addressof(x.vrs), f"{verb}_nvr": len(x.vrs),
                        f"{verb}_buf": address(x.view), f"{verb}_count": x.view.size})
            where = {name: (a, b - a) for name, a, b in x.slices}
            for name in names:
                self.table[ports:ports + 2] = where[name]
                ports += 2
        if inst.model.major == 3:
            for i, flag in enumerate(inst.step_flags):
                self.table[self.slots["flags"] + i] = ctypes.addressof(flag)
        else:
            self.set(**dict(zip(("log_arm", "log_arg"), fmi2_logger_arming())))

    def attach_hosted(self, inst: HostedInstance) -> None:
        """The channel of a hosted instance in the table: the C step writes the inputs into
        its values and reads the outputs from them, one round trip a step."""
        region = inst.region
        self.set(channel=region.address, socket=inst.sock.fileno(), set_buf=region.inputs_address,
                 get_buf=region.outputs_address)
        self.values[self.at["timeout"]] = inst.timeout
        ports = self.slots["ports"]
        for names in (inst.model.in_ports, inst.model.out_ports):
            first = 0
            for _, width in names:
                self.table[ports:ports + 2] = (first, width)
                ports += 2
                first += width

    def inputs(self) -> dict[str, np.ndarray]:
        """The values of the inputs the C call was given (copies)."""
        count = len(self.block.inputs)
        pointers = (ctypes.c_int64 * count).from_address(int(self.table[self.slots["inputs"]])) if count else ()
        return {port: np.ctypeslib.as_array((ctypes.c_double * width).from_address(p)).copy()
                for (port, width), p in zip(self.block.inputs.items(), pointers)}

    # -- what the C step hands over ----------------------------------------------------

    def output(self, t: float, status: int) -> int:
        """Outputs before the FMU is initialised: the block's output, which starts it."""
        self.block.output(t, self.state, self.inputs())
        return 0

    def update(self, t: float, status: int) -> int:
        """A step the C side does not take: the block's update, as it is."""
        return self.ending(self.block.update, t, self.state, self.inputs())

    def arm(self, t: float, status: int) -> int:
        interrupt.arm()
        return 0

    def set_failed(self, t: float, status: int) -> int:
        return self.transfer_failed(self.instance.writes[0], t, status)

    def get_failed(self, t: float, status: int) -> int:
        return self.transfer_failed(self.instance.reads[0], t, status)

    def transfer_failed(self, transfer: Any, t: float, status: int) -> int:
        """A set or get call returned ``status``: the failure the block's update raises for it."""
        self.block.step_calls(self.instance, t, _raise, call_failed(transfer.function, status))
        return 0

    def stepped(self, t: float, status: int) -> int:
        """doStep returned ``status`` and it was not a plain success: the rest of the step
        as the block's update does it."""
        inst, block = self.instance, self.block
        return self.ending(block.step_calls, inst, t, self.after_step, t, status)

    def after_step(self, t: float, status: int) -> None:
        self.block.stepped(t, self.state, self.instance, self.instance.outcome(status, t, self.block._step))

    def hosted(self, t: float, waited: int) -> int:
        """A hosted step that was not a plain success (``waited``: how waiting for it ended):
        the rest of the step as the block's update does it."""
        return self.ending(self.block.step_calls, self.instance, t, self.after_hosted, t, waited)

    def after_hosted(self, t: float, waited: int) -> None:
        inst, block = self.instance, self.block
        block.stepped(t, self.state, inst, inst.finish_step(waited, t, block._step))

    def ending(self, call: Any, *args: Any) -> int:
        """``call(*args)``; 1 when it raised EndRun (kept for the error factory), else 0."""
        try:
            call(*args)
        except EndRun as end:
            self.ended = end
            return 1
        return 0
