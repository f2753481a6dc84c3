"""A scheduler of FMI 3.0 scheduled-execution FMUs written on FMPy's low-level API alone,
as a third-party importer would: for tests of exported FMUs.

It reads the input clocks of the modelDescription (interval and shift exact as counters of
a resolution, priorities: from the XML, which FMPy's reader leaves out), and runs the
instants of their tick grid in time order: at each, the inputs given for it set, the
clocks that tick there activated in priority order (``fmi3ActivateModelPartition``), the
outputs read. It counts the preemption-lock calls the FMU makes, which must pair up.
"""

from __future__ import annotations

import zipfile
from fractions import Fraction
from pathlib import Path
from typing import Callable
from xml.etree import ElementTree as ET

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi3 import (FMU3ScheduledExecution, fmi3Boolean, fmi3ClockUpdateCallback, fmi3InstanceEnvironment,
                       fmi3LockPreemptionCallback, fmi3LogMessageCallback, fmi3UnlockPreemptionCallback)


class Clock:
    """An input clock: its value reference, priority, interval and shift (exact, in seconds)."""

    def __init__(self, attrib: dict[str, str]):
        self.name = attrib["name"]
        self.valueReference = int(attrib["valueReference"])
        self.priority = int(attrib["priority"])
        resolution = int(attrib["resolution"])
        self.interval = Fraction(int(attrib["intervalCounter"]), resolution)
        self.shift = Fraction(int(attrib.get("shiftCounter", 0)), resolution)


class Scheduler:
    """One instance of the scheduled-execution FMU at ``path``, unpacked into ``unzip``."""

    def __init__(self, path: Path, unzip: Path, name: str = "scheduled"):
        self.md = read_model_description(str(path))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        with zipfile.ZipFile(path) as archive:
            root = ET.fromstring(archive.read("modelDescription.xml"))
        self.clocks = sorted((Clock(e.attrib) for e in root.iter("Clock") if e.get("causality") == "input"),
                             key=lambda c: c.priority)
        self.messages: list[tuple[int, str]] = []
        self.locked = self.lock_calls = 0
        folder = str(extract(str(path), str(unzip)))
        self.fmu = FMU3ScheduledExecution(guid=self.md.guid, unzipDirectory=folder, instanceName=name,
                                          modelIdentifier=self.md.scheduledExecution.modelIdentifier)
        self._callbacks = (fmi3LogMessageCallback(self._log), fmi3ClockUpdateCallback(lambda env: None),
                           fmi3LockPreemptionCallback(self._lock), fmi3UnlockPreemptionCallback(self._unlock))
        self.fmu.component = self.fmu.fmi3InstantiateScheduledExecution(
            name.encode(), self.md.guid.encode(), (folder + "/resources/").encode(), fmi3Boolean(False),
            fmi3Boolean(False), fmi3InstanceEnvironment(), *self._callbacks)
        if not self.fmu.component:
            raise RuntimeError(f"instantiation failed: {self.messages}")

    def _log(self, env, status, category, message):
        self.messages.append((status, message.decode()))

    def _lock(self):
        self.locked += 1
        self.lock_calls += 1

    def _unlock(self):
        self.locked -= 1

    def instants(self, t_end: Fraction) -> list[tuple[Fraction, list]]:
        """Every instant in [0, t_end] at which a clock ticks, with its clocks in priority order."""
        ticks: dict[Fraction, list] = {}
        for clock in self.clocks:
            interval, t = clock.interval, clock.shift
            while t <= t_end:
                ticks.setdefault(t, []).append(clock)
                t += interval
        return sorted(ticks.items())

    def run(self, t_end: Fraction, outputs: list[str],
            inputs: Callable[[Fraction], dict[str, float]] | None = None) -> tuple[list[Fraction], np.ndarray]:
        """The instants to ``t_end`` and the ``outputs`` read after each (rows)."""
        def set_inputs(t: Fraction):
            given = inputs(t) if inputs is not None else None
            if given:
                self.fmu.setFloat64([self.vr[n] for n in given], list(given.values()))

        self.fmu.enterInitializationMode()
        set_inputs(Fraction(0))  # the outputs at t = 0 before the first activation read them
        self.fmu.exitInitializationMode()
        times, rows = [], []
        refs = [self.vr[n] for n in outputs]
        for t, clocks in self.instants(t_end):
            set_inputs(t)
            for clock in clocks:
                self.fmu.activateModelPartition(clock.valueReference, float(t))
            times.append(t)
            rows.append(self.fmu.getFloat64(refs))
        return times, np.array(rows)

    def close(self):
        try:
            self.fmu.terminate()
        finally:
            self.fmu.freeInstance()
