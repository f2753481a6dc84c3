"""Scheduled-execution FMUs (FMI 3.0) as blocks: their input clocks activated on the tick grid.

A scheduled-execution FMU has one model partition per input clock, which the importer
activates (``fmi3ActivateModelPartition``). The FMU block runs one at the hits of its
period: at a hit it sets the inputs, activates the partitions of the clocks due there in
priority order (the smallest ``priority`` value first, as the standard orders the clocks
of one instant) and reads the outputs, so its outputs at a hit read its inputs there and
hold between hits. Which input clocks are due at a hit:

- periodic ones (``constant``; ``fixed`` and ``tunable`` ones at the interval the
  modelDescription gives) at each of their ticks, exact where the FMU gives
  ``intervalCounter / resolution``; the block's default period is the grid of their ticks
  (the gcd of their intervals and shifts), and a period given must divide every one;
- ``triggered`` ones where their input port (named as the clock) rises: it is nonzero at
  the hit and was zero at the hit before (or this is the first hit);
- ``countdown`` ones when the FMU asks: after it calls ``clockUpdate``, the block reads the
  clock's interval (``fmi3GetIntervalDecimal``) and activates it that long after the hit,
  at once when the interval is 0 (after the clocks of the hit before it in priority).

An output clock is an output port (named as the clock): 1 at a hit where the FMU said it
ticked (``fmi3GetClock`` after a ``clockUpdate``), else 0. The FMU's preemption locks are
no-ops: the block activates one partition at a time. Not supported: changing clocks, FMU
states of a scheduled run, and running the FMU in a process of its own (``isolation:
process``).
"""

from __future__ import annotations

import os
from fractions import Fraction

import numpy as np

from . import interrupt
from .clocks import Clock, ClockRun
from .instance import FMI3Instance
from .log_messages import record


class ScheduledExecution3(FMI3Instance):
    """An FMI 3.0 scheduled-execution instance: partitions activated instead of steps,
    with a ``clockUpdate`` callback that notes the FMU's requests."""

    fmpy_class = "FMU3ScheduledExecution"

    def _instantiate(self, who: str) -> None:
        from fmpy.fmi3 import (fmi3Boolean, fmi3ClockUpdateCallback, fmi3InstanceEnvironment,
                               fmi3LockPreemptionCallback, fmi3LogMessageCallback, fmi3UnlockPreemptionCallback)

        messages, slave = self.messages, self.slave
        self.updated = False

        def log3(env, status, category, message):
            record(messages, status, category, message, who)

        def clock_update(env):
            self.updated = True

        # kept on the fmpy instance, which keeps them alive as long as the FMU may call them
        slave.logMessage = fmi3LogMessageCallback(interrupt.callback(log3))
        slave.clockUpdate = fmi3ClockUpdateCallback(interrupt.callback(clock_update))
        slave.lockPreemption = fmi3LockPreemptionCallback(lambda: None)
        slave.unlockPreemption = fmi3UnlockPreemptionCallback(lambda: None)
        slave.component = slave.fmi3InstantiateScheduledExecution(
            slave.instanceName.encode(), slave.guid.encode(),
            (os.path.join(slave.unzipDirectory, "resources") + os.path.sep).encode(), fmi3Boolean(False),
            fmi3Boolean(False), fmi3InstanceEnvironment(), slave.logMessage, slave.clockUpdate, slave.lockPreemption,
            slave.unlockPreemption)
        if not slave.component:
            raise RuntimeError("fmi3InstantiateScheduledExecution returned no instance")

    def activate(self, clocks: tuple[Clock, ...], run: ClockRun, t: float, exact: Fraction, period: Fraction,
                 inputs) -> dict[str, np.ndarray]:
        """Activate the input clocks due at the hit ``t`` (``exact``) in priority order, the
        countdown clocks the FMU asks for included; the output clocks' ports. fmpy raises
        FMICallException for a call that fails."""
        due = set()
        for c in clocks:
            if c.kind == "triggered":
                value = float(np.asarray(inputs[c.port]).ravel()[0])
                if value != 0.0 and run.previous.get(c.port, 0.0) == 0.0:
                    due.add(c.vr)
                run.previous[c.port] = value
            elif c.ticks_at(exact) or run.due.get(c.vr) == exact:
                due.add(c.vr)
                run.due.pop(c.vr, None)
        ticked: set[int] = set()
        done: set[int] = set()
        self.updated = False
        while True:
            waiting = [c for c in clocks if c.vr in due and c.vr not in done]
            if not waiting:
                break
            clock = waiting[0]  # clocks are in priority order
            self.slave.activateModelPartition(clock.vr, t)
            done.add(clock.vr)
            if self.updated:
                self.updated = False
                self._requests(clocks, run, exact, period, due, ticked)
        return {c.port: np.array([1.0 if c.vr in ticked else 0.0]) for c in clocks if c.kind == "output"}

    def _requests(self, clocks, run: ClockRun, exact: Fraction, period: Fraction, due: set, ticked: set) -> None:
        """After a clockUpdate: the output clocks that ticked, the countdown clocks' new intervals."""
        from fmpy.fmi3 import fmi3Float64, fmi3IntervalQualifier, fmi3ValueReference

        outputs = [c for c in clocks if c.kind == "output"]
        if outputs:
            for c, active in zip(outputs, self.slave.getClock([c.vr for c in outputs])):
                if active:
                    ticked.add(c.vr)
        for c in clocks:
            if c.kind != "countdown":
                continue
            intervals, qualifiers = (fmi3Float64 * 1)(), (fmi3IntervalQualifier * 1)()
            self.slave.getIntervalDecimal((fmi3ValueReference * 1)(c.vr), intervals, qualifiers)
            if qualifiers[0] != 2:  # fmi3IntervalChanged
                continue
            at = exact + Fraction(repr(float(intervals[0])))
            if (at / period).denominator != 1:
                raise ValueError(f"countdown clock '{c.name}' asks for an activation at t={float(at):.9g} s, "
                                 f"off the block's hits every {float(period):g} s")
            if at == exact:
                due.add(c.vr)
            else:
                run.due[c.vr] = at
