"""A model-exchange instance's step: the model integrated from one hit to the next.

``ModelExchange2`` and ``ModelExchange3`` are the FMI 2 and FMI 3 instances of a
model-exchange FMU, integrated by the solver the block's ``Integration`` names
(``solvers``). The FMU's life between the hits follows FMI and fmpy's ME simulation:

- leaving initialisation mode, the FMU is in event mode: its discrete states are updated
  until they settle (event iteration), then it enters continuous-time mode and the solver
  starts from its states;
- at a hit, inputs that differ from those held since the last one are an (external)
  event: event mode, the inputs set, event iteration, the solver restarted. Inputs that did
  not change are not set again, and the solver goes on;
- from the hit to the next (``t + h``), the solver integrates up to the next time event
  the FMU announced (nextEventTime), or the first state event (an event indicator changing
  sign) or step event (completedIntegratorStep asking for one); at each of them the FMU
  goes through event mode and event iteration and the solver restarts;
- the outputs are read at the hits, after any event there.

A request to terminate (in event iteration or from completedIntegratorStep) ends the
step at that time, as a co-simulation FMU's terminateSimulation does. Event iteration
that does not settle, or time events that do not move on, are a SolverError.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..block import Signal
from .instance import FMI2Instance, FMI3Instance, Instance
from .solvers import CallFailed, ContinuousCalls, SolverError, solver

MAX_EVENT_PASSES = 1000
"""How many passes of the discrete update one event may take before it counts as not settling."""
MAX_EVENTS_AT_ONE_TIME = 1000
"""How many events may follow each other at one instant (time events the FMU keeps announcing for now)."""


class ModelExchange(Instance):
    """A model-exchange instance, integrated between the hits by its solver."""

    def _instantiate(self, who: str) -> None:
        super()._instantiate(who)
        model = self.model
        self.calls = ContinuousCalls(self.slave.component, model.major, self.slave._functions,
                                     model.states, model.indicators, model.completed_step)
        self.solver = None
        self.time = 0.0
        self.next_event: float | None = None
        self.terminated = False
        self.held: dict[str, bytes] = {}

    def _update_discrete_states(self) -> tuple:
        """One pass of the discrete update: (again, terminate, nominals changed, values
        changed, next event time defined, next event time)."""
        raise NotImplementedError

    # -- the run -------------------------------------------------------------------------

    def _initialised(self, t: float, inputs: Mapping[str, Signal]) -> None:
        self.time = t
        self.held = {port: _held(value) for port, value in inputs.items()}
        if self.solver is None:
            self.solver = solver(self.calls, self.model.integration)
        self.terminated = False
        self.next_event = None
        self._settle(t)

    def step(self, inputs: Mapping[str, Signal], t: float, h: float) -> tuple[bool, bool, float]:
        try:
            if not self.terminated and self._changed(inputs):
                self.slave.enterEventMode()
                self.write(inputs, t)
                self._settle(t)
            if not self.terminated:
                self._advance(t, t + h)
        except CallFailed:
            raise
        except Exception as exc:
            function = getattr(exc, "function", None)
            if function is None:
                raise
            raise CallFailed(function, getattr(exc, "status", 3), self.time) from None
        if self.terminated:
            return True, False, self.time
        return False, False, t + h

    def _changed(self, inputs: Mapping[str, Signal]) -> bool:
        """Whether ``inputs`` differ from those the FMU holds (which they then become);
        compared bit for bit, so a NaN held is no change."""
        held = self.held
        changed = False
        for port, value in inputs.items():
            now = _held(value)
            if now != held[port]:
                held[port] = now
                changed = True
        return changed

    def _settle(self, t: float) -> None:
        """In event mode at ``t``: event iteration, then continuous-time mode and the
        solver restarted (unless the FMU asked to terminate)."""
        for _ in range(MAX_EVENT_PASSES):
            again, terminate, _, _, defined, next_time = self._update_discrete_states()
            if terminate:
                self.terminated = True
                return
            if not again:
                break
        else:
            raise SolverError(f"the event iteration at t={t:.9g} s did not settle in {MAX_EVENT_PASSES} passes "
                              "(the FMU keeps asking for another update of its discrete states)")
        self.next_event = float(next_time) if defined else None
        self.slave.enterContinuousTimeMode()
        self.solver.start(t)

    def _advance(self, t: float, end: float) -> None:
        """Integrate from the FMU's time (``t``, or an event after it) to ``end``, through
        the events on the way; stops early where the FMU asks to terminate."""
        eps = 1e-9 * max(end - t, abs(end))
        hit = (t, end)
        at_once = 0
        while not self.terminated:
            due = self.next_event
            if due is not None and due <= self.time + eps:  # a time event now
                at_once += 1
                if at_once > MAX_EVENTS_AT_ONE_TIME:
                    raise SolverError(f"the FMU keeps announcing a time event at t={self.time:.9g} s "
                                      f"({MAX_EVENTS_AT_ONE_TIME} events at one time)")
                self._event()
                continue
            if self.time >= end - eps:
                return
            stop = end if due is None or due >= end - eps else due
            reached, outcome = self.solver.integrate(self.time, stop, hit)
            at_once = 0
            self.time = reached
            if outcome == "terminate":
                self.terminated = True
            elif outcome != "reached":
                self._event()

    def _event(self) -> None:
        """An event at the FMU's time: event mode, event iteration, the solver restarted."""
        self.slave.enterEventMode()
        self._settle(self.time)

    def free(self) -> None:
        if getattr(self, "solver", None) is not None:
            self.solver.close()
            self.solver = None
        super().free()


def _held(value: Signal) -> bytes:
    """An input's values as the FMU holds them, for comparison: their float64 bytes."""
    return np.asarray(value, dtype=np.float64).tobytes()


class ModelExchange2(ModelExchange, FMI2Instance):
    """An FMI 2.0 model-exchange instance."""

    fmpy_class = "FMU2Model"

    def _update_discrete_states(self) -> tuple:
        return self.slave.newDiscreteStates()


class ModelExchange3(ModelExchange, FMI3Instance):
    """An FMI 3.0 model-exchange instance."""

    fmpy_class = "FMU3Model"

    def _update_discrete_states(self) -> tuple:
        return self.slave.updateDiscreteStates()
