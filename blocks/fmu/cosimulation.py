"""A co-simulation instance's step: set the inputs, doStep, and what doStep's status says.

``CoSimulation2`` and ``CoSimulation3`` are the FMI 2 and FMI 3 instances of a
co-simulation FMU. Their ``step`` sets the inputs held over the communication step and
calls the FMU's doStep directly (fmpy's wrapper, and for FMI 3 its fresh output
arguments, cost more than the call); ``outcome`` reads what a doStep that did not plainly
succeed means: a request to terminate (FMI 2: a discard with ``fmi2Terminated``, and
``fmi2LastSuccessfulTime``; FMI 3: ``terminateSimulation``, ``lastSuccessfulTime``), an
early return, or a failure. The block's compiled kernel makes the same doStep call in C
(``do_step_address``, ``step_flags``) and asks ``outcome`` when it was not a success.
"""

from __future__ import annotations

import ctypes
import math
from collections.abc import Mapping

from ..block import Signal
from .instance import FMI2Instance, FMI3Instance, Instance, call_failed, function_address


class CoSimulation(Instance):
    """A co-simulation instance: each step is one doStep with the inputs set before it."""

    def step(self, inputs: Mapping[str, Signal], t: float, h: float) -> tuple[bool, bool, float]:
        self.write(inputs, t)
        return self.do_step(t, h)

    def do_step(self, t: float, h: float) -> tuple[bool, bool, float]:
        """One doStep; (terminate requested, returned early, last successful time).
        Raises fmpy's FMICallException for an error status, or for a discard that is not a
        request to terminate, as fmpy's own call does."""
        return self.outcome(self.call_do_step(t, h), t, h)

    def call_do_step(self, t: float, h: float) -> int:
        """The doStep call itself; its status (FMI 3's flags land in ``step_flags``)."""
        raise NotImplementedError

    def outcome(self, status: int, t: float, h: float) -> tuple[bool, bool, float]:
        """What a doStep from ``t`` that returned ``status`` did, as ``do_step`` says it
        (a compiled kernel makes the call and asks here when it was not a plain success)."""
        raise NotImplementedError

    def do_step_address(self) -> int:
        """The C address of the FMU's doStep."""
        return function_address(self._do_step)


class CoSimulation2(CoSimulation, FMI2Instance):
    """An FMI 2.0 co-simulation instance."""

    fmpy_class = "FMU2Slave"

    def _instantiate(self, who: str) -> None:
        super()._instantiate(who)
        self._do_step = self.slave._functions["fmi2DoStep"]

    def call_do_step(self, t: float, h: float) -> int:
        return self._do_step(self.component, t, h, 1)

    def outcome(self, status: int, t: float, h: float) -> tuple[bool, bool, float]:
        if status == 2 and self._terminated():
            return True, False, self._last_time(t + h)
        if status > 1:
            raise call_failed("fmi2DoStep", status)
        return False, False, t + h

    def _terminated(self) -> bool:
        """After a discard: whether the FMU asks to end the simulation (fmi2Terminated)."""
        flag = ctypes.c_int(0)
        fn = self.slave._functions.get("fmi2GetBooleanStatus")
        return fn is not None and fn(self.component, 3, ctypes.byref(flag)) <= 1 and bool(flag.value)

    def _last_time(self, default: float) -> float:
        """After a discard: how far the step got (fmi2LastSuccessfulTime), else ``default``."""
        value = ctypes.c_double(default)
        fn = self.slave._functions.get("fmi2GetRealStatus")
        if fn is None or fn(self.component, 2, ctypes.byref(value)) > 1 or not math.isfinite(value.value):
            return default
        return value.value


class CoSimulation3(CoSimulation, FMI3Instance):
    """An FMI 3.0 co-simulation instance (without event mode)."""

    fmpy_class = "FMU3Slave"

    def _instantiate(self, who: str) -> None:
        super()._instantiate(who)
        self._do_step = self.slave._functions["fmi3DoStep"]
        flags = [ctypes.c_bool(), ctypes.c_bool(), ctypes.c_bool(), ctypes.c_double()]
        self.step_flags = flags
        self._step_refs = [ctypes.byref(f) for f in flags]

    def call_do_step(self, t: float, h: float) -> int:
        return self._do_step(self.component, t, h, True, *self._step_refs)

    def outcome(self, status: int, t: float, h: float) -> tuple[bool, bool, float]:
        if status > 1:
            raise call_failed("fmi3DoStep", status)
        _, terminate, early, last = self.step_flags
        return terminate.value, early.value, last.value
