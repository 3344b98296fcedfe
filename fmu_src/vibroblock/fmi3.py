"""The FMI 3.0 co-simulation side of the shared facade (pythonfmu3).

An FMI 3.0 FMU is an FMI 2.0 facade (``fmi.FmuFacade`` and its subclass, e.g. the
chain's) with ``Fmi3Adapter`` in front: the facade declares its variables, guards its
requests and keeps its FMU state exactly as for FMI 2.0, and the adapter

* turns each variable the facade registers (pythonfmu's Real, Integer, Boolean, String)
  into pythonfmu3's (Float64, Int32, Boolean, String), so both FMUs share one table;
* routes the calls pythonfmu3's native library makes (get_float64, set_boolean, log
  messages, ...) to pythonfmu3's implementations, which read the same ``vars``;
* returns a refused doStep as fmi3Error: pythonfmu3 0.3.4 passes a doStep's
  ``status`` through (PySlaveInstance::DoStep), and a plain False would read as
  fmi3Discard;
* serializes FMU states with pickle (pythonfmu3's JSON cannot hold numpy arrays).

pythonfmu3 0.3.4 returns fmi3OK from every call but doStep unless a Python exception
escapes, and then it returns fmi3Fatal and drops the Python instance
(PySlaveInstance::handle_py_exception).  So a refused setting is logged with status
fmi3Error, keeps the last good value, and leaves the FMU refusing to initialize: every
later doStep returns fmi3Error, which a master cannot overlook.
"""
from __future__ import annotations

import pickle

from pythonfmu import variables as fmi2_variables
from pythonfmu3 import Fmi3SlaveBase, Fmi3StepResult
from pythonfmu3 import variables as fmi3_variables
from pythonfmu3.enums import Fmi3Causality, Fmi3Initial, Fmi3Status, Fmi3Variability

# pythonfmu's variable kind -> pythonfmu3's (FMI 2.0 Integer is 32 bits wide, as Int32).
FMI3_KINDS = {fmi2_variables.Real: fmi3_variables.Float64, fmi2_variables.Integer: fmi3_variables.Int32,
              fmi2_variables.Boolean: fmi3_variables.Boolean, fmi2_variables.String: fmi3_variables.String}


def fmi3_variable(var):
    """The pythonfmu3 variable declaring what the pythonfmu variable ``var`` declares."""
    kind = FMI3_KINDS[type(var)]

    def same(enum, value):
        return None if value is None else enum[value.name]

    return kind(var.name, causality=same(Fmi3Causality, var.causality), description=var.description,
                variability=same(Fmi3Variability, var.variability), initial=same(Fmi3Initial, var.initial),
                getter=var.getter, setter=var.setter)


class Fmi3Adapter:
    """Put in front of an ``FmuFacade`` subclass, with pythonfmu3's ``Fmi3Slave`` last:
    ``type(name, (Fmi3Adapter, Facade, Fmi3Slave), {})``."""

    log_categories = Fmi3SlaveBase.log_categories  # pythonfmu's name fmi2 statuses

    def __init__(self, **kwargs):
        # pythonfmu3's model description needs these; pythonfmu's __init__ (run by the
        # facade) sets the rest of what both share (vars, log queue, names).
        self.event_indicators, self.type_definitions, self.units = [], {}, {}
        self._refusals = []
        super().__init__(**kwargs)
        # FMI 3.0 asks for exactly one independent variable.
        self.register_variable(fmi3_variables.Float64(
            "time", causality=Fmi3Causality.independent, variability=Fmi3Variability.continuous,
            description="simulation time [tau_0]",
            getter=lambda: self._time() if self._is_started() else self.start_time))

    def register_variable(self, var, nested: bool = True):
        if isinstance(var, fmi2_variables.ScalarVariable):
            var = fmi3_variable(var)
        Fmi3SlaveBase.register_variable(self, var, nested=False)

    def to_xml(self, model_options=None):
        root = Fmi3SlaveBase.to_xml(self, model_options or {})
        # pythonfmu3 0.3.4 writes a UInt64's start as its ctypes repr ("c_ulong(16)").
        for element in root.iter("UInt64"):
            if "start" in element.attrib:
                element.set("start", str(int(self.vars[int(element.get("valueReference"))].getter())))
        return root

    def log(self, msg: str, status=Fmi3Status.ok, category=None, debug: bool = False):
        status = Fmi3Status(int(status))
        if status >= Fmi3Status.error and not debug:
            self._refusals.append(msg)
        Fmi3SlaveBase.log(self, msg, status, category, debug)

    # pythonfmu's methods of the same names handle pythonfmu's variables only.
    def get_boolean(self, vrs):
        return Fmi3SlaveBase.get_boolean(self, vrs)

    def get_string(self, vrs):
        return Fmi3SlaveBase.get_string(self, vrs)

    def set_boolean(self, vrs, values):
        Fmi3SlaveBase.set_boolean(self, vrs, values)

    def set_string(self, vrs, values):
        Fmi3SlaveBase.set_string(self, vrs, values)

    def _get_log_queue(self):
        return self.log_queue

    def enter_initialization_mode(self):
        pass

    def exit_initialization_mode(self):
        if self._refusals:  # see the module's doc: a refused setting is not silently run past
            self.log(f"not initialized: {len(self._refusals)} refused request(s) before, the first: "
                     f"{self._refusals[0]}", Fmi3Status.error)
            return False
        return super().exit_initialization_mode()

    def do_step(self, current_time: float, step_size: float):
        accepted = super().do_step(current_time, step_size)
        return Fmi3StepResult(status=Fmi3Status.ok if accepted else Fmi3Status.error)

    @staticmethod
    def _fmu_state_to_bytes(state) -> bytes:
        return pickle.dumps(state, protocol=pickle.HIGHEST_PROTOCOL)

    @staticmethod
    def _fmu_state_from_bytes(state: bytes):
        return pickle.loads(state)

