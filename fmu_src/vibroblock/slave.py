"""The FMI 2.0 co-simulation facade shared by the Block FMUs (pythonfmu).

An FMU script is a few lines::

    @block_slave("A")
    class BlockA(Fmi2Slave):
        '''Model A ...'''

The decorator swaps the class for a subclass of ``BlockSlave`` (pythonfmu's native
loader finds the slave class by the literal text ``class Name(Fmi2Slave):`` in the
script, which rules out declaring a shared base class there).

Error handling: pythonfmu turns a Python exception into fmi2Fatal and discards the
Python instance, so no exception may leave this facade.  A rejected call logs its
reason with status fmi2Error, keeps the last good state, and (doStep) returns False;
the FMU's native status shim (build/fmi_status_shim.c) turns a call that logged an
error into an fmi2Error return.
"""
from __future__ import annotations

import math
import sys
import traceback
from pathlib import Path

from pythonfmu import Fmi2Slave
from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Status, Fmi2Variability
from pythonfmu.variables import Boolean, Integer, Real

from .block import Block, ModelError
from .jitcache import CORE_DIGEST, PACKAGE_DIR, core_digest
from .models import DESCRIPTIONS
from .interface import ENERGY_BALANCE, INITIAL_CHOICES, INPUTS, INTEGRATOR_CHOICES, OUTPUTS
from .parameters import SCENE_OPTIONS, parameters_for
from .stepping import INTEGRATORS

class BlockSlave(Fmi2Slave):
    """FMU facade over ``vibroblock.Block``: registers variables, maps FMI calls, reports errors."""

    model = "A"
    author = "vibroblock"
    license = "MIT"
    version = "0.1.0"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.description = f"{DESCRIPTIONS[self.model]}. Spring-block friction on a vibrating plate."
        self.block = Block(self.model)
        self.start_time = 0.0
        self.plate_input = {name: 0.0 for name in INPUTS}
        self._input_changed = False
        self._healthy = self._check_core(kwargs.get("resources"))
        self._register_interface()

    # ------------------------------------------------------------------ interface
    def _register_interface(self) -> None:
        for spec in parameters_for(self.model):
            variability = Fmi2Variability.tunable if spec.tunable else Fmi2Variability.fixed
            self.register_variable(Real(
                spec.name, causality=Fmi2Causality.parameter, variability=variability,
                description=f"{spec.description} [{spec.unit}]",
                getter=lambda name=spec.name: self.block.parameters[name],
                setter=lambda value, name=spec.name: self._guard(self.block.set_parameter, name, value)))
        self.register_variable(Integer(
            "integrator", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description=f"internal integrator: {INTEGRATOR_CHOICES}",
            getter=lambda: INTEGRATORS[self.block.integrator],
            setter=lambda value: self._guard(self.block.set_integrator, int(value))))
        self.register_variable(Integer(
            "initial_state", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description=f"initial state: {INITIAL_CHOICES}",
            getter=lambda: self.block.initial_state,
            setter=lambda value: self._guard(self.block.set_initial_state, int(value))))
        self.register_variable(Boolean(
            "energy_balance", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description=ENERGY_BALANCE, getter=lambda: self.block.energy_balance,
            setter=lambda value: self._guard(self.block.set_energy_balance, bool(value))))
        for name, (models, text) in SCENE_OPTIONS.items():  # only the reductions this model offers
            if self.model in models:
                self.register_variable(Boolean(
                    name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed, description=text,
                    getter=lambda name=name: self.block.scene[name],
                    setter=lambda value, name=name: self._guard(self.block.set_scene_option, name, bool(value))))
        for name, (unit, text) in INPUTS.items():
            self.register_variable(Real(
                name, causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
                description=f"{text} [{unit}]",
                getter=lambda name=name: self.plate_input[name],
                setter=lambda value, name=name: self._guard(self._set_input, name, value)))
        variable_types = {"Real": Real, "Integer": Integer, "Boolean": Boolean}
        for name, (kind, unit, text) in OUTPUTS.items():
            variability = Fmi2Variability.continuous if kind == "Real" else Fmi2Variability.discrete
            self.register_variable(variable_types[kind](
                name, causality=Fmi2Causality.output, variability=variability, initial=Fmi2Initial.calculated,
                description=f"{text} [{unit}]" if unit else text, getter=lambda name=name: self._output(name)))

    def _output(self, name):
        if not self.block.started:
            return 0.0  # before initialization outputs are not yet calculated
        return self.block.output(name)

    # ------------------------------------------------------------------ guarding
    def _guard(self, action, *args) -> bool:
        """Run one request; on a bad request log fmi2Error and keep the last good state."""
        try:
            action(*args)
            return True
        except ModelError as exc:
            self.log(str(exc), Fmi2Status.error)
        except Exception as exc:  # a host must never see a Python exception (see module doc)
            self.log(f"internal error: {exc!r}\n{traceback.format_exc()}", Fmi2Status.error)
        return False

    def _check_core(self, resources) -> bool:
        """The process may already hold a vibroblock import (e.g. the harness): it must be
        the core this FMU was built with, or results would silently come from other code."""
        if resources is None:
            return True
        bundled = Path(resources) / "vibroblock"
        if not bundled.is_dir() or bundled.resolve() == PACKAGE_DIR:
            return True
        if core_digest(bundled) == CORE_DIGEST:
            return True
        self.log(f"this process already imported a different vibroblock core from {PACKAGE_DIR}; "
                 f"the FMU's own core is {bundled}. Run the FMU in a process without that import.",
                 Fmi2Status.error)
        return False

    def _set_input(self, name: str, value: float) -> None:
        if not math.isfinite(value):
            raise ModelError(f"input {name} = {value!r} is not finite; the previous value "
                             f"{self.plate_input[name]!r} is kept")
        self.plate_input[name] = float(value)
        self._input_changed = True

    # ------------------------------------------------------------------ FMI calls
    def setup_experiment(self, start_time=0.0, stop_time=None, tolerance=None):
        if start_time is not None and not math.isfinite(start_time):
            self.log(f"start time {start_time!r} is not finite; 0 is used", Fmi2Status.error)
            return
        self.start_time = float(start_time or 0.0)

    def exit_initialization_mode(self):
        if not self._healthy:
            self.log("the FMU cannot be initialized (see the previous error)", Fmi2Status.error)
            return
        if self._guard(self.block.start, self.start_time):
            self._apply_input()

    def _apply_input(self) -> None:
        if self._input_changed:
            self.block.set_plate_input(*(self.plate_input[name] for name in INPUTS))
            self._input_changed = False

    def do_step(self, current_time: float, step_size: float) -> bool:
        return self._guard(self._do_step, current_time, step_size)

    def _do_step(self, current_time: float, step_size: float) -> None:
        if not self.block.started:
            raise ModelError("doStep before a successful initialization (see earlier errors)")
        if not (math.isfinite(step_size) and step_size > 0.0):
            raise ModelError(f"communication step size {step_size!r} must be a finite number > 0")
        now = self.block.time
        if not math.isfinite(current_time) or abs(current_time - now) > 1e-9 * max(1.0, abs(now)):
            raise ModelError(f"communication point {current_time!r} differs from the FMU's time {now!r}; "
                             "to go back in time restore an FMU state first")
        self._apply_input()
        self.block.advance_to(now + step_size)

    def terminate(self):
        pass

    # ------------------------------------------------------------------ FMU state
    # pythonfmu's default captures registered scalars only; the block's dynamic state
    # (shear displacement, counters, drive phase, ...) lives in arrays, so capture it whole.
    def _get_fmu_state(self):
        try:
            return {
                "block": self.block.get_state() if self.block.started else None,
                "parameters": dict(self.block.parameters),
                "integrator": self.block.integrator, "initial_state": self.block.initial_state,
                "energy_balance": self.block.energy_balance, "scene": dict(self.block.scene),
                "start_time": self.start_time, "plate_input": dict(self.plate_input),
                "input_changed": self._input_changed,
            }
        except Exception as exc:
            self.log(f"could not capture the FMU state: {exc!r}", Fmi2Status.error)
            return {}

    def _set_fmu_state(self, state):
        try:
            block = Block(self.model, state["integrator"], state["initial_state"], state["energy_balance"],
                          **state["parameters"], **state.get("scene", {}))
            if state["block"] is not None:
                block.set_state(state["block"])
            self.start_time = float(state["start_time"])
            self.plate_input = {name: float(state["plate_input"][name]) for name in INPUTS}
            self._input_changed = bool(state["input_changed"])
            self.block = block
        except (KeyError, TypeError, ValueError) as exc:
            self.log(f"not a valid FMU state for {self.model}: {exc!r}; the current state is kept", Fmi2Status.error)
        except Exception as exc:
            self.log(f"internal error while restoring the FMU state: {exc!r}", Fmi2Status.error)


# pythonfmu 0.7.0's native loader executes the FMU script again in the script module's
# namespace at every instantiation, then releases a reference to that namespace which it
# only borrowed (PyModule_GetDict).  Unbalanced, the namespace is freed under the live
# module after the first instance and the host crashes later.  Every execution of the
# decorator below therefore hands one reference back, held for the life of the process.
_NAMESPACES_RELEASED_BY_LOADER: list = []


def block_slave(model: str):
    """Class decorator turning ``class BlockX(Fmi2Slave)`` into the facade of model ``model``."""
    def decorate(cls):
        module = sys.modules.get(cls.__module__)
        if module is not None:
            _NAMESPACES_RELEASED_BY_LOADER.append(vars(module))
        attributes = {"model": model, "__doc__": cls.__doc__, "__module__": cls.__module__}
        return type(cls.__name__, (BlockSlave,), attributes)
    return decorate

