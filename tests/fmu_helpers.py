"""Helpers of the FMU tests: an FMU's instance driven call by call with FMPy, its log
messages collected."""

from __future__ import annotations

from pathlib import Path
from typing import Any

#: the log messages of the last instance created (also when its instantiation failed)
LAST_MESSAGES: list[tuple[int, str]] = []


class Instance:
    """One instance of an FMU (FMPy's ``FMU2Slave``), instantiated with debug logging on and
    its log messages kept in ``messages`` as (status, text)."""

    def __init__(self, path: Path, name: str, unzipdir: str | None = None) -> None:
        from fmpy import extract, read_model_description
        from fmpy.fmi1 import calloc, free
        from fmpy.fmi2 import (
            FMU2Slave,
            fmi2CallbackAllocateMemoryTYPE,
            fmi2CallbackFreeMemoryTYPE,
            fmi2CallbackFunctions,
            fmi2CallbackLoggerTYPE,
        )

        self.md = read_model_description(str(path))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        global LAST_MESSAGES
        self.messages: list[tuple[int, str]] = []
        LAST_MESSAGES = self.messages

        def logger(env: Any, instance: bytes, status: int, category: bytes,
                   message: bytes) -> None:
            self.messages.append((int(status), message.decode(errors="replace")))

        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(logger)
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self._callbacks = (cb, logger)  # kept alive while the FMU may call them
        self.slave = FMU2Slave(guid=self.md.guid, unzipDirectory=unzipdir or extract(str(path)),
                               modelIdentifier=self.md.coSimulation.modelIdentifier,
                               instanceName=name)
        self.slave.instantiate(callbacks=cb, loggingOn=True)

    def start(self, values: dict[str, float] | None = None) -> None:
        """Initialise at t = 0 with ``values`` of inputs and parameters."""
        s = self.slave
        self.t = 0.0
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        self.set(values or {})
        s.exitInitializationMode()

    def set(self, values: dict[str, float]) -> None:
        if values:
            self.slave.setReal([self.vr[k] for k in values], list(values.values()))

    def get(self, *names: str) -> list[float]:
        return self.slave.getReal([self.vr[k] for k in names])

    def step(self, t: float, dt: float) -> None:
        """doStep from ``t`` over ``dt`` [s]; ``self.t`` is then ``t + dt``."""
        self.slave.doStep(currentCommunicationPoint=t, communicationStepSize=dt)
        self.t = t + dt

    def close(self) -> None:
        self.slave.terminate()
        self.slave.freeInstance()
