"""An FMU instance through fmpy's low-level API, for tests that step exported FMUs.

``Slave`` instantiates an FMI 2 or 3 co-simulation FMU (unpacked into a test's folder),
collects its log messages, sets and gets Float64 variables by name and steps it; ``run``
steps one from t = 0 and returns named outputs at every communication point.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi3 import FMU3Slave


class Slave:
    """One instance of the FMU at ``path``, unpacked into ``unzip``."""

    def __init__(self, path: Path, unzip: Path, name: str = "instance", logging_on: bool = False,
                 stop_time: float | None = None):
        self.md = read_model_description(str(path))
        self.fmi = int(self.md.fmiVersion[0])
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.messages: list[tuple[int, str, str]] = []
        kwargs = dict(guid=self.md.guid, unzipDirectory=extract(str(path), unzip),
                      modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        self.stop_time = stop_time
        if self.fmi == 2:
            self.fmu = FMU2Slave(**kwargs)
            callbacks = fmi2CallbackFunctions()
            callbacks.logger = self._logger2 = fmi2CallbackLoggerTYPE(self._collect2)
            self._callbacks = callbacks
            self.fmu.instantiate(callbacks=callbacks, loggingOn=logging_on)
            self.fmu.setupExperiment(startTime=0.0, stopTime=stop_time)
        else:
            self.fmu = FMU3Slave(**kwargs)
            self.fmu.instantiate(loggingOn=logging_on, logMessage=self._collect3)

    def _collect2(self, env, name, status, category, message):
        self.messages.append((status, category.decode(), message.decode()))

    def _collect3(self, env, status, category, message):
        self.messages.append((status, category.decode(), message.decode()))

    def names(self, causality: str) -> list[str]:
        return [v.name for v in self.md.modelVariables if v.causality == causality]

    def set(self, **values):
        """Set variables by name (``__`` in a keyword stands for ``.``)."""
        self.set_named({name.replace("__", "."): value for name, value in values.items()})

    def set_named(self, values: dict[str, float]):
        refs = [self.vr[name] for name in values]
        (self.fmu.setReal if self.fmi == 2 else self.fmu.setFloat64)(refs, [float(v) for v in values.values()])

    def get(self, names) -> np.ndarray:
        refs = [self.vr[n] for n in names]
        return np.array((self.fmu.getReal if self.fmi == 2 else self.fmu.getFloat64)(refs))

    def initialize(self):
        if self.fmi == 2:
            self.fmu.enterInitializationMode()
        else:
            self.fmu.enterInitializationMode(stopTime=self.stop_time)
        self.fmu.exitInitializationMode()

    def step(self, t: float, h: float):
        return self.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)

    def serialized_copy(self, state):
        """``state`` serialized and read back: a new FMU state."""
        if self.fmi == 2:
            return self.fmu.deSerializeFMUstate(self.fmu.serializeFMUstate(state))
        return self.fmu.deserializeFMUState(self.fmu.serializeFMUState(state))

    def free_states(self, *states):
        for state in states:
            (self.fmu.freeFMUstate if self.fmi == 2 else self.fmu.freeFMUState)(state)

    def errors(self) -> list[str]:
        return [m for status, category, m in self.messages if status == 3 and category == "logStatusError"]

    def close(self):
        try:
            self.fmu.terminate()
        except Exception:  # noqa: BLE001 - a failed instance may refuse; it is freed all the same
            pass
        self.fmu.freeInstance()


def run(path: Path, unzip: Path, names: list[str], step: float, n_steps: int,
        start: dict[str, float] | None = None) -> np.ndarray:
    """``names`` at t = 0, step, ..., n_steps * step (rows) of one instance of ``path``."""
    slave = Slave(path, unzip)
    try:
        if start:
            slave.set_named(start)
        slave.initialize()
        rows = [slave.get(names)]
        for k in range(n_steps):
            slave.step(k * step, step)
            rows.append(slave.get(names))
        return np.array(rows)
    finally:
        slave.close()
