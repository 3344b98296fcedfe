"""Test helpers for driving FMUs through fmpy's FMI 2.0 layer and reading their log."""
from __future__ import annotations

from ctypes import byref

import fmpy
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2Real,
    fmi2ValueReference,
    printLogMessage,
)
from fmpy.logging import addLoggerProxy


class FmuLog:
    """The FMU's log messages, caught through fmpy's native logger proxy.

    fmpy's proxy formats the message and calls one process-wide Python logger;
    ``close`` points it back at fmpy's printer.
    """

    _printer = fmi2CallbackLoggerTYPE(printLogMessage)  # alive for the whole process

    def __init__(self):
        self.records: list[tuple[str, int, str, str]] = []
        self._logger = fmi2CallbackLoggerTYPE(self._log)
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = self._logger
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(fmpy.calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(fmpy.free)
        addLoggerProxy(byref(self.callbacks))

    def _log(self, env, instance, status, category, message):
        self.records.append(
            (instance.decode(), status, (category or b"").decode(), message.decode())
        )

    def close(self):
        restore = fmi2CallbackFunctions()
        restore.logger = self._printer
        addLoggerProxy(byref(restore))

    def of(self, instance):
        return [r for r in self.records if r[0] == instance]

    def clear(self):
        self.records.clear()


@pytest.fixture
def fmu_log():
    log = FmuLog()
    yield log
    log.close()


def status_of(call) -> int:
    """The FMI status of a call, also when fmpy raises for it."""
    try:
        return call()
    except FMICallException as e:
        return e.status


def set_real(slave, vr, value) -> int:
    return status_of(lambda: slave.fmi2SetReal(
        slave.component, (fmi2ValueReference * 1)(vr), 1, (fmi2Real * 1)(value)))


def do_step(slave, t, h) -> int:
    return status_of(lambda: slave.fmi2DoStep(slave.component, t, h, 1))


def with_another_core(source, other) -> str:
    """A copy of the FMU at ``source``, written to ``other``, whose bundled vibroblock core
    differs by one comment: an FMU a process holding the checkout's core must refuse."""
    import zipfile

    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(other, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item)
            if item.filename == "resources/vibroblock/layout.py":
                data += b"\n# a different core\n"
            zout.writestr(item, data)
    return str(other)
