"""FMU access for the harness: extraction, instances, and FMI errors as exceptions.

Three layers, each usable alone:

* :func:`fmu_sha256` and :func:`extract_fmu` -- an FMU file is identified by the
  sha256 of its bytes and extracted once into ``<cache>/fmus/<sha256>/``.  Extraction
  goes to a private temporary folder that is renamed into place, so two processes
  extracting the same FMU at once both end up using one complete folder.
* :class:`FmuInstance` -- one instantiated co-simulation slave (fmpy's
  :class:`fmpy.fmi2.FMU2Slave`).  It is instantiated once and ``reset()`` between
  runs.  Every FMI call goes through :meth:`FmuInstance._call`, the one place that
  turns a failing status into :class:`FmuError` carrying the FMU's log text.
* :class:`InstancePool` -- instances of a process keyed by FMU sha256, so a worker
  evaluating many points loads each FMU once.  A pool is an object handed around
  (or attached to a Dask worker by :class:`harness.runs.sweep.FmuPoolPlugin`), never a
  module global.
"""
from __future__ import annotations

import hashlib
import itertools
import os
import re
import shutil
import tempfile
import threading
import weakref
from ctypes import byref
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Mapping

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (FMU2Slave, defaultCallbacks, fmi2Boolean, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE,
                       fmi2Integer, fmi2Real, fmi2ValueReference, printLogMessage)

REPO_ROOT = Path(__file__).resolve().parents[2]
DEFAULT_CACHE = REPO_ROOT / ".cache"
STATUS_LABELS = ("ok", "warning", "discard", "error", "fatal", "pending")
# Log lines kept per instance: enough to explain the failing call, bounded for long runs.
LOG_LINES_KEPT = 50


# fmpy's native logger proxy (fmpy.logging.addLoggerProxy) formats a message and hands it
# to one process-wide Python callback: that of the callbacks it was given last.  Had each
# instance its own callback there, the proxy would keep calling it after the instance was
# gone and ctypes had freed it, and the next message any FMU logs through the proxy (a
# plain simulate_fmu run with fmpy's default callbacks included) would call freed memory:
# a segfault, or another Python function called with the logger's arguments.  So the
# process has one callback, alive as long as the proxy is, and each instance's callbacks
# carry a key (componentEnvironment, which the FMU passes back with every message) that
# routes its messages to its own log; messages without a known key are printed as fmpy's
# default logger prints them.
_LOG_ROUTES: dict[int, list[str]] = {}
_ROUTE_KEYS = itertools.count(1)


def _route_message(component_environment, instance, status, category, message) -> None:
    log = _LOG_ROUTES.get(component_environment or 0)
    if log is None:
        printLogMessage(component_environment, instance, status, category, message or b"")
        return
    text = message.decode("utf-8", "replace") if message else ""
    label = STATUS_LABELS[status] if 0 <= status < len(STATUS_LABELS) else str(status)
    log.append(f"[{label}] {text}")
    del log[:-LOG_LINES_KEPT]


_PROCESS_LOGGER = fmi2CallbackLoggerTYPE(_route_message)


class FmuError(RuntimeError):
    """An FMI call failed; the message holds the call, its status and the FMU's log."""

    def __init__(self, call: str, status: int | None, log: Iterable[str], detail: str = ""):
        self.call, self.status, self.log = call, status, list(log)
        label = STATUS_LABELS[status] if status is not None and 0 <= status < len(STATUS_LABELS) else "failure"
        # The FMU's own reasons (its error messages name the value, the rule and the fix)
        # lead, after the FMI function's name only: a call that sets many values names the
        # one the FMU refused in its message, not all it was given.
        reasons = [line.split("] ", 1)[1] for line in self.log if line.startswith(("[error] ", "[fatal] "))]
        function = call.split("(", 1)[0]
        if reasons:
            text = f"{function} refused: " + "; ".join(reasons)
            others = [line for line in self.log if not line.startswith(("[error] ", "[fatal] "))]
            if others:
                text += "\nFMU log:\n  " + "\n  ".join(others)
        else:
            text = f"{call} failed ({label})"
            if detail:
                text += f": {detail}"
            if self.log:
                text += "\nFMU log:\n  " + "\n  ".join(self.log)
        super().__init__(text)


def fmu_sha256(path: str | os.PathLike) -> str:
    """sha256 of the FMU file's bytes: the identity of an FMU everywhere in the harness."""
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def extract_fmu(path: str | os.PathLike, cache: str | os.PathLike = DEFAULT_CACHE, sha256: str | None = None) -> Path:
    """Folder holding the extracted FMU, ``<cache>/fmus/<sha256>``; extracted on first use.

    Safe against concurrent extraction: each process unpacks into its own temporary
    folder next to the target and renames it into place; a process that loses the race
    discards its copy.  A folder that exists is complete (rename is atomic).
    """
    sha256 = sha256 or fmu_sha256(path)
    root = Path(cache) / "fmus"
    target = root / sha256
    if (target / "modelDescription.xml").is_file():
        return target
    root.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{sha256[:12]}-", dir=root))
    try:
        extract(str(path), unzipdir=str(staging))
        try:
            os.rename(staging, target)
        except OSError:
            if not (target / "modelDescription.xml").is_file():
                raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return target


@dataclass(frozen=True)
class Variable:
    name: str
    reference: int
    type: str  # Real, Integer, Boolean, String
    causality: str
    variability: str
    start: str | None
    description: str = ""

    def choices(self) -> dict[str, int]:
        """name -> code of an Integer whose description lists its values as "0 = name: ...; 1 = name: ..."."""
        return {label: int(code) for code, label in _CHOICE.findall(self.description or "")}

    def typed(self, value):
        """``value`` as this variable's FMI type, refusing lossy or surprising conversions:
        an Integer takes an integral number or the name of one of its choices, a Boolean a
        bool (or 0/1), a Real a finite or non-finite number (the FMU judges it)."""
        if self.type == "Integer":
            if isinstance(value, str) and value in self.choices():
                return self.choices()[value]
            if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_)):
                if float(value).is_integer() and -2**31 <= value < 2**31:
                    return int(value)
            named = f" or one of {sorted(self.choices())}" if self.choices() else ""
            raise ValueError(f"{self.name} is an Integer parameter and cannot take {value!r}: give a whole "
                             f"number{named}")
        if self.type == "Boolean":
            if isinstance(value, (bool, np.bool_)) or (isinstance(value, (int, float, np.integer, np.floating))
                                                      and value in (0, 1)):
                return bool(value)
            raise ValueError(f"{self.name} is a Boolean parameter and cannot take {value!r}: give true or false")
        if self.type == "Real":
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
                raise ValueError(f"{self.name} is a Real parameter and cannot take {value!r}: give a number")
            return float(value)
        return value


# "0 = fixed_axes: ...; 1 = tangent_frame: ..." in an Integer's description
_CHOICE = re.compile(r"(?:^|[;:,(]\s*)(-?\d+) = ([A-Za-z_][A-Za-z0-9_]*)")


class FmuInterface:
    """The variables of an FMU, read from its model description."""

    def __init__(self, folder: Path):
        description = read_model_description(str(folder))
        if description.coSimulation is None:
            raise FmuError("read_model_description", None, [], f"{folder} is not a co-simulation FMU")
        self.guid = description.guid
        self.model_identifier = description.coSimulation.modelIdentifier
        self.model_name = description.modelName
        self.variables = {v.name: Variable(v.name, v.valueReference, v.type, v.causality, v.variability, v.start,
                                           v.description or "")
                          for v in description.modelVariables}
        self.parameters = {n: v for n, v in self.variables.items() if v.causality == "parameter"}
        self.outputs = tuple(n for n, v in self.variables.items() if v.causality == "output")
        self.tunable = frozenset(n for n, v in self.parameters.items() if v.variability == "tunable")

    def defaults(self) -> dict[str, float | int | bool | str]:
        """Start values of the parameters, typed as the FMU declares them."""
        out = {}
        for name, var in self.parameters.items():
            if var.start is None:
                continue
            if var.type == "Integer":
                out[name] = int(var.start)
            elif var.type == "Boolean":
                out[name] = var.start.strip().lower() in ("true", "1")
            elif var.type == "String":
                out[name] = var.start
            else:
                out[name] = float(var.start)
        return out

    def choices(self, name: str) -> dict[str, int]:
        """The named values of an Integer switch (``integrator``, ``initial_state``, ...),
        as the FMU's own description of the variable lists them ("0 = name, 1 = name")."""
        variable = self.variables.get(name)
        if variable is None or variable.type != "Integer":
            return {}
        return variable.choices()

    @staticmethod
    def parse_choices(description: str) -> dict[str, int]:
        return {label: int(code) for code, label in _CHOICE.findall(description or "")}

    def encode(self, name: str, value):
        """An Integer switch given by name becomes the FMU's value for it."""
        if not isinstance(value, str):
            return value
        choices = self.choices(name)
        if value not in choices:
            raise ValueError(f"{self.model_name}: {name} = {value!r} is not one of {sorted(choices)} "
                             "(the FMU's model description)")
        return choices[value]

    def typed(self, values: Mapping[str, object]) -> dict[str, float | int | bool | str]:
        """``values`` converted to the FMU's types (``Variable.typed``): Integer and Boolean
        parameters given as numbers (``RunSettings.parameters`` holds floats and bools) or
        by a choice's name come out as int and bool."""
        self.require(values)
        return {name: self.variables[name].typed(value) for name, value in values.items()}

    def require(self, names: Iterable[str], what: str = "variable") -> None:
        unknown = sorted(set(names) - set(self.variables))
        if unknown:
            raise KeyError(f"{self.model_name} has no {what} {', '.join(map(repr, unknown))}; "
                           f"its parameters are {sorted(self.parameters)}")


class FmuInstance:
    """One co-simulation slave, instantiated once and reset between runs."""

    def __init__(self, fmu_path: str | os.PathLike, cache: str | os.PathLike = DEFAULT_CACHE,
                 sha256: str | None = None, name: str = "vibroblock"):
        self.fmu_path = Path(fmu_path)
        self.sha256 = sha256 or fmu_sha256(self.fmu_path)
        self.folder = extract_fmu(self.fmu_path, cache, self.sha256)
        self.interface = FmuInterface(self.folder)
        self._log: list[str] = []
        self._callbacks = self._make_callbacks()
        self._slave = FMU2Slave(guid=self.interface.guid, unzipDirectory=str(self.folder),
                                modelIdentifier=self.interface.model_identifier, instanceName=name)
        try:
            self._slave.instantiate(callbacks=self._callbacks)
        except Exception as exc:
            raise FmuError("fmi2Instantiate", None, self._log, str(exc)) from None
        self.state = "instantiated"  # -> configuring -> running; reset() -> instantiated; closed
        self.runs = 0
        try:
            self._check_health()
        except FmuError:
            # A slave that failed its own start-up checks has been seen to crash in
            # fmi2FreeInstance (pythonfmu 0.7): leave it allocated rather than end the process.
            self.state = "closed"
            raise

    # ------------------------------------------------------------------ plumbing
    def _make_callbacks(self) -> fmi2CallbackFunctions:
        # FMUs log printf-style (the vibroblock FMUs pass their text through "%s"); ctypes
        # cannot read variadic arguments, so fmpy's native proxy formats the message first,
        # and passes it to the process's one logger (_PROCESS_LOGGER says why), which
        # finds this instance's log by the key in componentEnvironment.
        self._route = next(_ROUTE_KEYS)
        _LOG_ROUTES[self._route] = self._log
        weakref.finalize(self, _LOG_ROUTES.pop, self._route, None)
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = _PROCESS_LOGGER
        callbacks.allocateMemory = defaultCallbacks.allocateMemory
        callbacks.freeMemory = defaultCallbacks.freeMemory
        callbacks.componentEnvironment = self._route
        try:
            from fmpy.logging import addLoggerProxy

            addLoggerProxy(byref(callbacks))
        except Exception:  # without the proxy, messages arrive unformatted but still arrive
            pass
        return callbacks

    def _call(self, name: str, function, *args):
        """Run one FMI call; a status of error or worse becomes FmuError with the log."""
        if self.state == "closed":
            raise FmuError(name, None, [], "the instance was closed")
        mark = len(self._log)
        try:
            return function(*args)
        except FMICallException as exc:
            raise FmuError(name, exc.status, self._log[mark:] or self._log[-3:]) from None
        except OSError as exc:  # a crash inside the library surfaces as an access violation
            raise FmuError(name, None, self._log[mark:] or self._log[-3:], str(exc)) from None

    def _references(self, names: Iterable[str]) -> dict[str, list]:
        by_type: dict[str, list] = {}
        for name in names:
            var = self.interface.variables[name]
            by_type.setdefault(var.type, []).append(var)
        return by_type

    def _check_health(self) -> None:
        """Surface an error the slave logged while instantiating.

        Messages logged during fmi2Instantiate reach the host with the next call, which
        then reports their status; a read of a parameter is that call, harmless if all
        is well.
        """
        name = next(iter(self.interface.parameters), None)
        if name is None:
            return
        try:
            self.reader([name])()
        except FmuError as exc:
            raise FmuError("fmi2Instantiate", exc.status, exc.log, "the FMU reported an error while starting up") \
                from None

    # ------------------------------------------------------------------ values
    def set(self, values: Mapping[str, float | int | bool]) -> None:
        self.interface.require(values)
        groups = self._references(values)
        setters = {"Real": self._slave.setReal, "Integer": self._slave.setInteger,
                   "Boolean": self._slave.setBoolean, "String": self._slave.setString}
        for kind, variables in groups.items():
            refs = [v.reference for v in variables]
            vals = [self.interface.encode(v.name, values[v.name]) for v in variables]
            if kind == "Integer":
                vals = [int(v) for v in vals]
            elif kind == "Boolean":
                vals = [bool(v) for v in vals]
            self._call(f"fmi2Set{kind}({', '.join(v.name for v in variables)})", setters[kind], refs, vals)

    def reader(self, names: Iterable[str]):
        """A function returning the current values of ``names`` as a list of floats, in order.

        The value-reference and value buffers are built once and fmpy's raw call layer is
        used, so that reading a few outputs after every step of a long run stays cheap.
        """
        names = list(names)
        self.interface.require(names)
        slave = self._slave
        raw = {"Real": (slave.fmi2GetReal, fmi2Real), "Integer": (slave.fmi2GetInteger, fmi2Integer),
               "Boolean": (slave.fmi2GetBoolean, fmi2Boolean)}
        plan = []
        for kind, variables in self._references(names).items():
            function, ctype = raw[kind]
            refs = (fmi2ValueReference * len(variables))(*(v.reference for v in variables))
            values = (ctype * len(variables))()
            positions = [names.index(v.name) for v in variables]
            plan.append((f"fmi2Get{kind}", function, refs, len(variables), values, positions))

        def read() -> list[float]:
            row = [0.0] * len(names)
            for call, function, refs, count, values, positions in plan:
                self._call(call, function, slave.component, refs, count, values)
                for position, value in zip(positions, values):
                    row[position] = float(value)
            return row

        return read

    # ------------------------------------------------------------------ life cycle
    def start(self, parameters: Mapping[str, float | int], start_time: float = 0.0) -> None:
        """Reset unless fresh, set the parameters and initialize at ``start_time``.

        Parameters not given keep the values a reset gives them (their start values); the
        harness always passes the complete set so that no run depends on an earlier one.
        """
        if self.state != "instantiated":
            self.reset()
        self._log.clear()
        self.state = "configuring"
        self._call("fmi2SetupExperiment", self._slave.setupExperiment, None, start_time)
        self._call("fmi2EnterInitializationMode", self._slave.enterInitializationMode)
        self.set(parameters)
        self._call("fmi2ExitInitializationMode", self._slave.exitInitializationMode)
        self.state = "running"
        self.runs += 1

    def do_step(self, time: float, step: float) -> None:
        try:
            self._call("fmi2DoStep", self._slave.doStep, time, step)
        except FmuError as exc:  # the call's arguments are formatted only when they are needed
            raise FmuError(f"fmi2DoStep(t={time!r}, h={step!r})", exc.status, exc.log) from None

    def reset(self) -> None:
        self._call("fmi2Reset", self._slave.reset)
        self.state = "instantiated"

    def get_state(self) -> bytes:
        """The complete FMU state, serialized (restorable on any instance of this FMU)."""
        handle = self._call("fmi2GetFMUstate", self._slave.getFMUstate)
        try:
            return bytes(self._call("fmi2SerializeFMUstate", self._slave.serializeFMUstate, handle))
        finally:
            self._call("fmi2FreeFMUstate", self._slave.freeFMUstate, handle)

    def set_state(self, serialized: bytes) -> None:
        handle = self._call("fmi2DeSerializeFMUstate", self._slave.deSerializeFMUstate, serialized)
        try:
            self._call("fmi2SetFMUstate", self._slave.setFMUstate, handle)
        finally:
            self._call("fmi2FreeFMUstate", self._slave.freeFMUstate, handle)
        self.state = "running"

    def close(self) -> None:
        if self.state == "closed":
            return
        try:
            if self.state == "running":
                self._slave.terminate()
            self._slave.freeInstance()
        finally:
            self.state = "closed"

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class InstancePool:
    """The FMU instances of one process, keyed by FMU sha256 (one each)."""

    def __init__(self, cache: str | os.PathLike = DEFAULT_CACHE):
        self.cache = Path(cache)
        self._instances: dict[str, FmuInstance] = {}
        self._lock = threading.Lock()
        self._digests: dict[tuple, str] = {}
        self.loads = 0  # instances created: a worker should create one per FMU

    def sha256(self, fmu_path: str | os.PathLike) -> str:
        """sha256 of an FMU file, recomputed only when its size or modification time changes."""
        status = os.stat(fmu_path)
        stamp = (os.fspath(fmu_path), status.st_mtime_ns, status.st_size)
        digest = self._digests.get(stamp)
        if digest is None:
            digest = self._digests[stamp] = fmu_sha256(fmu_path)
        return digest

    def get(self, fmu_path: str | os.PathLike, sha256: str | None = None) -> FmuInstance:
        """The instance of the FMU at ``fmu_path``; if ``sha256`` is given the file must have it."""
        actual = self.sha256(fmu_path)
        if sha256 is not None and actual != sha256:
            raise FmuError("load", None, [], f"{fmu_path} has sha256 {actual}, expected {sha256}: "
                                             "the FMU file changed during the sweep")
        sha256 = actual
        with self._lock:
            instance = self._instances.get(sha256)
            if instance is None or instance.state == "closed":
                instance = FmuInstance(fmu_path, self.cache, sha256)
                self._instances[sha256] = instance
                self.loads += 1
            return instance

    def close(self) -> None:
        with self._lock:
            for instance in self._instances.values():
                try:
                    instance.close()
                except Exception:  # closing is best effort; the process may be ending
                    pass
            self._instances.clear()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


__all__ = ["DEFAULT_CACHE", "REPO_ROOT", "FmuError", "FmuInstance", "FmuInterface", "InstancePool", "Variable",
           "extract_fmu", "fmu_sha256"]
