"""One FMU instance: an fmpy instance made ready for the per-step calls of a run.

An instance loads the FMU's binary from the extracted archive, instantiates it with our
callbacks (the C library's calloc and free, with no Python in between that Ctrl-C could
break, and the log callback of ``log_messages``) and preallocates its value transfers:
for each group of ports of one FMI type, the value references, the C buffer and a numpy
view of it, bound with the instance into one call (``Transfer``). The per-step calls,
``write`` and ``read`` around the interface's ``step``, then only move values: they call
the FMU's C functions directly and check the status here, because fmpy's Python wrappers
cost more than the call; a failing call raises fmpy's own ``FMICallException``, as the
wrappers would.

Values are checked on their way: an integer or Boolean input takes only values its type
holds, and a 64-bit integer output that a float64 port cannot hold exactly (beyond 2^53)
stops the run, each as a BlockError naming port, value and time.

``FMI2Instance`` and ``FMI3Instance`` hold what differs between the FMI versions: the
fmpy class, instantiation with its callbacks and initialisation. What differs between the
interfaces, a step from one hit to the next, is in ``cosimulation`` (doStep) and
``exchange`` (the model integrated between the hits). Instances are pooled and reused by
``pool.PooledModel``.
"""

from __future__ import annotations

import collections
import functools
import itertools
import os
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..block import BlockError, Signal
from . import interrupt
from .log_messages import LOG_LINES, fmi2_buffers, fmi2_logger, log, log_text, record
from .model import import_fmpy
from .port_types import EXACT_INTEGERS, KINDS, PortKind, float64_holds
from .ports import Group
from .start_values import Assignment

_serials = itertools.count(1)
_loading = threading.Lock()
"""Held while fmpy loads a binary: it changes the process's working folder into the
binary's and back, so two threads loading at once would leave it in one of theirs."""


@dataclass
class Binary:
    """What an instance needs to know about its FMU (kept apart from the pool, so that
    pooled instances do not keep the pool's owner alive)."""

    shown: str
    major: int
    identifier: str
    guid: str
    dir: Path
    library: Path
    in_groups: list[Group]
    out_groups: list[Group]
    exchange: bool = False
    """Whether the instance runs the FMU's model-exchange interface (else co-simulation)."""
    integration: Any = None
    """How a model-exchange FMU is integrated (``solvers.Integration``)."""
    states: int = 0
    indicators: int = 0
    completed_step: bool = False
    """Model exchange: the numbers of continuous states and event indicators, and whether
    the FMU needs completedIntegratorStep."""
    in_ports: list[tuple[str, int]] = field(default_factory=list)
    out_ports: list[tuple[str, int]] = field(default_factory=list)
    """The block's input and output ports (name, width), in the block's order."""
    isolation: str = "none"
    """Where instances run: 'none' (in this process) or 'process' (a process of their own)."""
    timeout: float = 0.0
    """Isolation 'process': how long one call into the FMU may take, in seconds."""
    scheduled: bool = False
    """Whether the instance runs the FMU's scheduled-execution interface (FMI 3)."""


@dataclass
class Transfer:
    """One preallocated get or set call of an instance: ``call()`` moves a group's values
    between the FMU and the C buffer that ``view`` shows (in the variables' own type) and
    returns the FMI status of ``function``; ``slices`` says where each port's values lie,
    ``check`` whether values need checking on their way (an input type narrower than
    float64, an output type with integers beyond 2^53). ``address`` and ``vrs`` are the C
    function and its value references, for a compiled kernel that makes the same call."""

    function: str
    call: Callable[[], int]
    view: np.ndarray
    slices: list[tuple[str, int, int]]
    kind: PortKind
    check: bool
    address: int
    vrs: Any


def function_address(function: Any) -> int:
    """The C address of one of the FMU's functions (``slave._functions``), also of one the
    FMU host traces (``host.Traced``, which keeps the function as ``traced``)."""
    import ctypes

    return ctypes.cast(getattr(function, "traced", function), ctypes.c_void_p).value


def call_failed(function: str, status: int) -> Exception:
    """The exception for an FMI call that returned ``status`` (worse than warning): fmpy's,
    as its own wrappers raise it."""
    from fmpy.fmi1 import FMICallException

    return FMICallException(function=function, status=status)


class Instance:
    """One fmpy instance with its preallocated value transfers and its recent log messages."""

    value_counts = False
    """Whether the get and set functions also take the number of values (FMI 3)."""
    usable = True
    """Whether a pooled instance can serve another run (always, for one in this process's memory)."""

    def __init__(self, model: Binary):
        fmpy = import_fmpy()
        self.model = model
        self.serial = next(_serials)
        self.messages: collections.deque[str] = collections.deque(maxlen=LOG_LINES)
        self.started = False
        self.used = False
        self.broken = False
        self.freed = False
        self.slave = None
        name = f"{model.identifier}#{self.serial}"
        kwargs = {"guid": model.guid, "modelIdentifier": model.identifier,
                  "unzipDirectory": str(model.dir), "instanceName": name}
        with _loading:
            cwd = os.getcwd()
            try:  # fmpy changes into the binary's folder to load it, and not back if that fails
                slave = self._load(fmpy, kwargs)
            except Exception as exc:
                raise BlockError(f"cannot load the binary of {model.shown} "
                                 f"(binaries/{model.library.parent.name}/{model.library.name}): {exc}") from None
            finally:
                if os.getcwd() != cwd:
                    os.chdir(cwd)
        self.slave = slave
        self._make()

    def _make(self) -> None:
        """Instantiate the FMU on its loaded binary and preallocate the value transfers."""
        model, slave = self.model, self.slave
        interrupt.arm()
        try:
            self._instantiate(f"{model.shown} ({slave.instanceName})")
        except Exception as exc:
            fmi2_buffers.pop(self.serial, None)
            slave.freeLibrary()
            self.freed = True
            interrupt.check()
            raise BlockError(f"{model.shown}: instantiating the FMU failed: {exc}{self.log_text()}") from None
        self.component = slave.component
        self.reads = self._transfers(model.out_groups, "Get")
        self.writes = self._transfers(model.in_groups, "Set")

    # -- what differs between FMI 2 and FMI 3, and between the interfaces ------------------

    fmpy_class = ""
    """The name of the fmpy class of the instance (``FMU2Slave``, ``FMU3Model``, ...)."""

    def _load(self, fmpy: Any, kwargs: dict[str, str]) -> Any:
        """The fmpy instance, its binary loaded."""
        module = fmpy.fmi2 if self.model.major == 2 else fmpy.fmi3
        return getattr(module, self.fmpy_class)(**kwargs)

    def _instantiate(self, who: str) -> None:
        """Instantiate, the log messages going to ``self.messages`` as ``who``'s."""
        raise NotImplementedError

    def _initialise(self, t: float, tolerance: float | None) -> None:
        """Enter initialisation mode with start time ``t``."""
        raise NotImplementedError

    def step(self, inputs: Mapping[str, Signal], t: float, h: float) -> tuple[bool, bool, float]:
        """From the hit at ``t`` to the next, ``t + h``, with ``inputs`` held over it:
        (terminate requested, returned early, the time reached). Raises fmpy's
        FMICallException (or another exception) for a call that failed."""
        raise NotImplementedError

    def arm(self) -> None:
        """Before a call into the FMU: the interrupt hook in place."""
        interrupt.arm()

    # -- setting up -------------------------------------------------------------------------

    def _transfers(self, groups: list[Group], verb: str) -> list[Transfer]:
        import ctypes

        out = []
        for g in groups:
            function = f"fmi{self.model.major}{verb}{g.kind.function}"
            vrs = (ctypes.c_uint * len(g.vrs))(*g.vrs)
            buf = (getattr(ctypes, g.kind.ctype) * g.count)()
            args = (self.component, vrs, len(g.vrs), buf) + ((g.count,) if self.value_counts else ())
            call = functools.partial(self.slave._functions[function], *args)
            check = not g.kind.is_float if verb == "Set" else g.kind.exceeds_float64
            address = function_address(self.slave._functions[function])
            out.append(Transfer(function, call, np.frombuffer(buf, dtype=g.kind.dtype), g.slices, g.kind, check,
                                address, vrs))
        return out

    def log_text(self) -> str:
        return log_text(list(self.messages))

    # -- the life cycle -------------------------------------------------------------------

    def start(self, t: float, assignments: list[Assignment], tolerance: float | None,
              inputs: Mapping[str, Signal]) -> None:
        """Reset if used before, set the start values, initialise at start time ``t`` with
        ``inputs`` set before initialisation ends (as FMI and fmpy do)."""
        s = self.slave
        if self.used:
            s.reset()
        self.used = True
        self.messages.clear()
        self.arm()
        setters = {name: getattr(s, "set" + kind.function) for name, kind in KINDS[self.model.major].items()}
        setters["String"] = s.setString
        for a in assignments:
            setters[a.kind]([a.vr], a.values)
        self._initialise(t, tolerance)
        self.write(inputs, t)
        s.exitInitializationMode()
        self.started = True
        self._initialised(t, inputs)

    def _initialised(self, t: float, inputs: Mapping[str, Signal]) -> None:
        """After initialisation mode, at start time ``t``: what the interface does next."""

    def read(self, t: float) -> dict[str, Signal]:
        """Fresh float64 outputs at time ``t``: one copy per group, each port a view of it."""
        out: dict[str, Signal] = {}
        for x in self.reads:
            status = x.call()
            if status > 1:
                raise call_failed(x.function, status)
            values = x.view.astype(np.float64)
            if x.check:
                self._check_exact(x, values, t)
            for name, a, b in x.slices:
                out[name] = values[a:b]
        return out

    def _check_exact(self, x: Transfer, values: np.ndarray, t: float) -> None:
        """BlockError if a 64-bit integer output does not survive the trip to float64."""
        big = np.flatnonzero(np.abs(values) >= EXACT_INTEGERS)
        for i in big:
            exact = int(x.view[i])
            if not float64_holds(exact):
                name, a, b = next(sl for sl in x.slices if sl[1] <= i < sl[2])
                element = f" element {i - a}" if b - a > 1 else ""
                raise BlockError(f"{self.model.shown}: output '{name}'{element} ({x.kind.name}) is {exact} at "
                                 f"t={t:.9g} s, which a float64 port cannot hold exactly (integers are "
                                 f"exact up to 2^53)", port=name)

    def write(self, inputs: Mapping[str, Signal], t: float) -> None:
        """Set the inputs to the values of ``inputs`` at time ``t``."""
        for x in self.writes:
            if x.check:
                for name, a, b in x.slices:
                    x.view[a:b] = self._checked(x.kind, name, inputs[name], t)
            else:
                for name, a, b in x.slices:
                    x.view[a:b] = inputs[name]
            status = x.call()
            if status > 1:
                raise call_failed(x.function, status)

    def _checked(self, kind: PortKind, name: str, value: np.ndarray, t: float) -> np.ndarray:
        """``value`` if every element is one the input's type holds, else BlockError."""
        if kind.name == "Boolean":
            bad = (value != 0) & (value != 1)
        else:
            bad = ~((value >= kind.low) & (value < kind.high + 1) & (np.floor(value) == value))
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            element = f" element {i}" if value.size > 1 else ""
            raise BlockError(f"{self.model.shown}: input '{name}'{element} ({kind.name}) got {float(value[i]):.17g} at "
                             f"t={t:.9g} s; it takes {kind.input_rule()}", port=name)
        return value

    def stop(self, report: bool = False) -> None:
        """End a started run's simulation (terminate); an instance that fails to is broken
        (in this process an FMU's crash ends the process, so ``report`` changes nothing)."""
        if self.started and not self.broken:
            self.started = False
            try:
                self.arm()
                self.slave.terminate()
            except Exception:
                self.broken = True
            interrupt.deliver()

    def end(self) -> None:
        """Free the FMU's instance (freeInstance) and keep its binary loaded, to be
        instantiated again by ``renew`` (an FMU host does so after each run, so that a crash
        in freeInstance fails the run it ends). A failing call raises."""
        if self.freed or self.component is None:
            return
        component, self.component = self.component, None
        self.started = False
        self.arm()
        try:
            self.slave._functions[f"fmi{self.model.major}FreeInstance"](component)
        finally:
            fmi2_buffers.pop(self.serial, None)
        interrupt.deliver()

    @property
    def ended(self) -> bool:
        """Whether ``end`` freed the FMU's instance (and ``renew`` has not made another)."""
        return self.component is None and not self.freed

    def renew(self) -> None:
        """A new instance of the FMU on the binary loaded, after ``end``: as it was made
        (BlockError if instantiating fails)."""
        self.used = self.started = self.broken = False
        self.messages.clear()
        self._make()

    def free(self) -> None:
        if self.freed or self.slave is None:
            return
        if self.component is None:  # ended: the instance is freed, the binary goes with the process
            self.freed = True
            return
        self.freed = True
        try:
            self.arm()
            self.slave.freeInstance()
        except Exception as exc:  # freeing must not raise from a finalizer
            log.debug("%s: freeing the FMU instance failed: %s", self.model.shown, exc)
        finally:
            fmi2_buffers.pop(self.serial, None)
        interrupt.deliver()


class FMI2Instance(Instance):
    """An FMI 2.0 instance: instantiated with our callbacks, logging through fmpy's proxy."""

    def _instantiate(self, who: str) -> None:
        import ctypes

        from fmpy import calloc, free
        from fmpy.fmi2 import fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions
        from fmpy.logging import addLoggerProxy

        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2_logger()
        # the C library's own functions: no Python (which Ctrl-C could break) in between
        callbacks.allocateMemory = ctypes.cast(calloc, fmi2CallbackAllocateMemoryTYPE)
        callbacks.freeMemory = ctypes.cast(free, fmi2CallbackFreeMemoryTYPE)
        callbacks.componentEnvironment = self.serial
        addLoggerProxy(ctypes.byref(callbacks))
        fmi2_buffers[self.serial] = (self.messages, who)
        self.slave.instantiate(callbacks=callbacks)

    def arm(self) -> None:
        """Before a call into the FMU: the interrupt hook and our logger in place."""
        interrupt.arm()
        fmi2_logger()

    def _initialise(self, t: float, tolerance: float | None) -> None:
        self.slave.setupExperiment(tolerance=tolerance, startTime=t)
        self.slave.enterInitializationMode()


class FMI3Instance(Instance):
    """An FMI 3.0 instance: its log messages come formatted to a callback of its own."""

    value_counts = True

    def _instantiate(self, who: str) -> None:
        messages = self.messages

        def log3(env, status, category, message):
            record(messages, status, category, message, who)

        self.slave.instantiate(logMessage=interrupt.callback(log3))

    def _initialise(self, t: float, tolerance: float | None) -> None:
        self.slave.enterInitializationMode(tolerance=tolerance, startTime=t)
