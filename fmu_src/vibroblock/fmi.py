"""The FMI 2.0 co-simulation facade shared by every vibroblock FMU (pythonfmu).

An FMU class holds no physics: it registers its variables and maps the FMI calls onto
one object of the core (a ``Block``, an ``Excitation`` signal).  This base does what
every FMU needs the same way:

* Errors.  pythonfmu turns a Python exception into fmi2Fatal and discards the Python
  instance, so no exception may leave a facade.  A rejected call logs its reason with
  status fmi2Error, keeps the last good state and returns normally (doStep returns
  False); the FMU's native status shim (build/fmi_status_shim.c) turns a call that
  logged an error into an fmi2Error return.
* Time.  The start time is checked; a doStep must start at the FMU's own time (to go
  back, a master restores an FMU state) and have a finite positive size.
* FMU state.  pythonfmu's default captures registered scalars only; the facades capture
  their core object whole (``_capture`` / ``_restore``), so hysteresis runs and
  rollbacks continue bit for bit.
* pythonfmu 0.7.0's loader re-executes the FMU script at every instantiation and then
  releases a reference to the script's namespace that it only borrowed
  (PyModule_GetDict); unbalanced, the namespace is freed under the live module after
  the first instance and the host crashes later.  ``fmu_class`` hands one reference
  back per execution, held for the life of the process.

An FMU script is then a few lines: pythonfmu's native loader finds the slave class by
the literal text ``class Name(Fmi2Slave):`` in the script, so the script declares that
and the ``fmu_class`` decorator puts this base (and the facade's own class) under it.
"""
from __future__ import annotations

import math
import sys
import threading
import traceback
import weakref
from pathlib import Path

from pythonfmu import Fmi2Slave
from pythonfmu.enums import Fmi2Status

from .jitcache import CORE_DIGEST, PACKAGE_DIR, SHIPPED_KERNELS, core_digest, seed_cache

_NAMESPACES_RELEASED_BY_LOADER: list = []
# A doStep's communication point may differ from the FMU's time by this much relative
# (masters that compute k h instead of accumulating); the step then starts at the FMU's time.
TIME_TOLERANCE = 1e-9

# The native front end (build/fmi_status_shim.c) calls a slave's do_step itself, without
# pythonfmu's per-call work (method lookup, argument tuple, log-queue scan): right after
# pythonfmu has made a slave (fmi2Instantiate, fmi2Reset), on the same thread, it takes
# the slave from here.  Weak, so that a slave made without that front end (a Python test)
# is not kept alive; and the instance name and resource folder must be the ones the
# front end passed to pythonfmu, so that such a slave is never taken for another FMU's.
_MADE_ON_THREAD: dict = {}


def _claim_slave(instance_name: str, resource_location: str):
    """The slave made last on this thread if it is the instance named (once; else None)."""
    made = _MADE_ON_THREAD.pop(threading.get_ident(), None)
    slave = None if made is None else made()
    if slave is None or slave.instance_name != instance_name:
        return None
    # The folder as pythonfmu 0.7.0 passes it to the slave: "%20" decoded, "file://" cut.
    folder = resource_location.replace("%20", " ")
    cut = folder.find("file://")
    if cut >= 0:
        folder = folder[:cut] + folder[cut + len("file://"):]
    return slave if slave.resources == folder else None


class FmuFacade(Fmi2Slave):
    """Error guard, time checks and FMU state handling; subclasses provide the hooks."""

    author = "vibroblock"
    license = "MIT"
    version = "0.1.0"
    # Exceptions whose message is the user's answer (a rejected value or request).
    rejected = (ValueError,)
    what = "the FMU"  # names the FMU in messages

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.start_time = 0.0
        _MADE_ON_THREAD[threading.get_ident()] = weakref.ref(self)
        # False if this process holds another core than the FMU's: initialization is refused.
        self._healthy = self._check_core(kwargs.get("resources"))

    def _check_core(self, resources) -> bool:
        """The process may already hold a vibroblock import (e.g. the harness): it must be
        the core this FMU was built with, or results would silently come from other code."""
        if resources is None:
            return True
        bundled = Path(resources) / "vibroblock"
        if not bundled.is_dir() or bundled.resolve() == PACKAGE_DIR:
            return True
        if core_digest(bundled) == CORE_DIGEST:
            # The same core imported from elsewhere (the harness imports it from the
            # checkout) has no shipped kernels beside it: seed the cache from the FMU's,
            # or each new process compiles the default integrator at its first doStep.
            seed_cache(Path(resources) / SHIPPED_KERNELS.name)
            return True
        self.log(f"this process already imported a different vibroblock core from {PACKAGE_DIR}; "
                 f"the FMU's own core is {bundled}. Run the FMU in a process without that import.",
                 Fmi2Status.error)
        return False

    # ------------------------------------------------------------------ hooks
    def _is_started(self) -> bool:
        raise NotImplementedError

    def _time(self) -> float:
        raise NotImplementedError

    def _start(self, start_time: float) -> None:
        raise NotImplementedError

    def _advance_to(self, end_time: float) -> None:
        raise NotImplementedError

    def _capture(self) -> dict:
        raise NotImplementedError

    def _restore(self, state: dict) -> None:
        raise NotImplementedError

    def _changed(self) -> None:
        """Called after every accepted request (e.g. to drop cached outputs)."""

    # ------------------------------------------------------------------ guarding
    def _guard(self, action, *args) -> bool:
        """Run one request; on a bad request log fmi2Error and keep the last good state."""
        try:
            action(*args)
            self._changed()
            return True
        except Exception as exc:  # a host must never see a Python exception (see module doc)
            return self._refuse(exc)

    def _refuse(self, exc: Exception) -> bool:
        """Log why a request was refused (fmi2Error); False, what the refused call returns."""
        if isinstance(exc, self.rejected):
            self.log(str(exc), Fmi2Status.error)
        else:
            self.log(f"internal error: {exc!r}\n{traceback.format_exc()}", Fmi2Status.error)
        return False

    # ------------------------------------------------------------------ FMI calls
    def setup_experiment(self, start_time=0.0, stop_time=None, tolerance=None):
        if start_time is not None and not math.isfinite(start_time):
            self.log(f"start time {start_time!r} is not finite; 0 is used", Fmi2Status.error)
            return
        self.start_time = float(start_time or 0.0)
        self._changed()

    def exit_initialization_mode(self):
        return self._guard(self._start_if_healthy, self.start_time)

    def _start_if_healthy(self, start_time: float) -> None:
        if not self._healthy:
            raise self.rejected[0]("the FMU cannot be initialized (see the previous error)")
        self._start(start_time)

    def do_step(self, current_time: float, step_size: float) -> bool:
        # The guard written out: a doStep is the call a master makes most, and at a
        # thousand internal steps per doStep each layer of Python calls costs a few
        # percent of the step (harness/benchmarks/fmi_boundary.py).
        try:
            self._advance_to(self._step_end(current_time, step_size))
            self._changed()
            return True
        except Exception as exc:  # as in _guard
            return self._refuse(exc)

    def _step_end(self, current_time: float, step_size: float) -> float:
        """The end time of a doStep, or why it is refused."""
        if not self._is_started():
            raise self.rejected[0]("doStep before a successful initialization (see earlier errors)")
        if not 0.0 < step_size < math.inf:  # NaN fails too
            raise self.rejected[0](f"communication step size {step_size!r} must be a finite number > 0")
        now = self._time()
        if not abs(current_time - now) <= TIME_TOLERANCE * max(1.0, abs(now)):  # NaN and infinities fail too
            raise self.rejected[0](f"communication point {current_time!r} differs from the FMU's time {now!r}; "
                                   "to go back in time restore an FMU state first")
        return now + step_size

    def terminate(self):
        pass

    def _take_log(self) -> list:
        """The queued log messages as (status, category, text), taken off the queue.  The
        native front end's doStep bypasses pythonfmu, which would otherwise pass them on;
        the queue is emptied in place because pythonfmu holds the list itself."""
        messages = [(int(m.status), m.category or "", str(m.msg)) for m in self.log_queue]
        self.log_queue.clear()
        return messages

    # ------------------------------------------------------------------ FMU state
    def _get_fmu_state(self):
        try:
            return self._capture()
        except Exception as exc:
            self.log(f"could not capture the FMU state: {exc!r}", Fmi2Status.error)
            return {}

    def _set_fmu_state(self, state):
        try:
            self._restore(state)
            self._changed()
        except self.rejected as exc:
            self.log(f"{exc}; the current state is kept", Fmi2Status.error)
        except (KeyError, TypeError, ValueError) as exc:
            self.log(f"not a valid FMU state for {self.what}: {exc!r}; the current state is kept", Fmi2Status.error)
        except Exception as exc:
            self.log(f"internal error while restoring the FMU state: {exc!r}", Fmi2Status.error)


class PlateInputs:
    """The plate inputs of a facade (``plate_input``: name -> value): a value is checked
    as it is set and applied at the next doStep (``_input_changed``)."""

    def _set_input(self, name: str, value: float) -> None:
        if not math.isfinite(value):
            raise self.rejected[0](f"input {name} = {value!r} is not finite; the previous value "
                                   f"{self.plate_input[name]!r} is kept")
        self.plate_input[name] = float(value)
        self._input_changed = True


def fmu_class(facade: type):
    """Class decorator for an FMU script's ``class Name(Fmi2Slave)``: returns a class of
    that name built on ``facade`` (a subclass of ``FmuFacade``), with the script class's
    own attributes (its docstring, ...) on top."""
    def decorate(cls):
        module = sys.modules.get(cls.__module__)
        if module is not None:
            _NAMESPACES_RELEASED_BY_LOADER.append(vars(module))
        own = {k: v for k, v in vars(cls).items() if k not in ("__dict__", "__weakref__")}
        return type(cls.__name__, (facade,), own)
    return decorate
