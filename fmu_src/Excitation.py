"""FMU: a vertical plate motion (harmonic, chirps, sum of harmonics, record playback)
with consistent outputs plate_z, plate_v = d(plate_z)/dt, plate_a = d(plate_v)/dt, to
connect to the plate inputs of the Block FMUs.  Signals: vibroblock/excitation.py.

Errors follow the Block FMUs (vibroblock/slave.py): no Python exception may leave a
method called by pythonfmu (it would become fmi2Fatal and free the instance); a
rejected call logs its reason with status fmi2Error, keeps the last good state and
returns normally, and the FMU's status shim turns the logged error into fmi2Error.
"""
import math
import sys
import traceback
from pathlib import Path

from pythonfmu import Fmi2Slave
from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Status, Fmi2Variability
from pythonfmu.variables import Integer, Real, String

from vibroblock.excitation import BUNDLED_RECORD, PARAMETERS, PLAYBACK, Excitation as Plate, ExcitationError
from vibroblock.slave import _NAMESPACES_RELEASED_BY_LOADER

OUTPUTS = {
    "plate_z": "plate height [delta_0]",
    "plate_v": "plate velocity, the exact derivative of plate_z [delta_0/tau_0]",
    "plate_a": "plate acceleration, the exact derivative of plate_v [delta_0/tau_0^2]",
}
MODE_TEXT = ("signal f of signal time s = (t - onset)/time_scale; plate_z = amplitude_scale * w * f with w the "
             "start ramp (1 if ramp_time = 0). 0 = harmonic: amplitude sin(omega s + phase); 1 = linear chirp: "
             "amplitude sin(theta + phase), frequency linear from omega_start to omega_end over sweep_time; "
             "2 = logarithmic chirp (geometric frequency sweep); 3 = sum of harmonics amplitude_i "
             "sin(omega_i s + phase_i), i = 1..4; 4 = playback of the record in record_file (piecewise-linear "
             "acceleration integrated exactly; at rest outside the record)")
RECORD_TEXT = ("record for mode 4: path of a .npz (dt, acceleration[, velocity0, displacement0]) or two-column "
               "text file (time, acceleration), in units made model units by amplitude_scale and time_scale; "
               f"empty: the bundled record {BUNDLED_RECORD.name} (BW.RJOB vertical, 2009-08-24, SI units)")


def _hand_back_namespace(cls):
    """pythonfmu 0.7.0's loader re-executes this script at every instantiation and then
    releases a reference to its namespace that it only borrowed; each execution hands
    one back (see vibroblock/slave.py, where the list lives)."""
    module = sys.modules.get(cls.__module__)
    if module is not None:
        _NAMESPACES_RELEASED_BY_LOADER.append(vars(module))
    return cls


@_hand_back_namespace
class Excitation(Fmi2Slave):
    """Plate motion source: harmonic, linear/logarithmic chirp, sum of harmonics, record playback."""

    author = "vibroblock"
    license = "MIT"
    version = "0.1.0"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.description = ("Vertical plate motion with kinematically consistent height, velocity and "
                            "acceleration, for the plate inputs of the vibroblock Block FMUs.")
        self.bundled = self._bundled_record(kwargs.get("resources"))
        self.plate = Plate(bundled=self.bundled)
        self.start_time = 0.0
        self._cache = None  # (time, outputs): the three getters of one step share one evaluation
        self._register_interface()

    @staticmethod
    def _bundled_record(resources):
        """This FMU's own copy of the bundled record: the process may hold a vibroblock
        import from another (possibly deleted) extraction folder."""
        if resources:
            own = Path(resources) / "vibroblock" / "data" / BUNDLED_RECORD.name
            if own.is_file():
                return own
        return BUNDLED_RECORD

    def _register_interface(self) -> None:
        self.register_variable(Integer(
            "mode", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description=MODE_TEXT, getter=lambda: self.plate.mode,
            setter=lambda value: self._guard(self.plate.set_mode, int(value))))
        for spec in PARAMETERS:
            self.register_variable(Real(
                spec.name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
                description=f"{spec.description} [{spec.unit}]",
                getter=lambda name=spec.name: self.plate.parameters[name],
                setter=lambda value, name=spec.name: self._guard(self.plate.set_parameter, name, value)))
        self.register_variable(String(
            "record_file", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description=RECORD_TEXT, getter=lambda: self.plate.record_file,
            setter=lambda value: self._guard(self.plate.set_record_file, value)))
        for name, text in OUTPUTS.items():
            self.register_variable(Real(
                name, causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                initial=Fmi2Initial.calculated, description=text, getter=lambda name=name: self._output(name)))

    def _output(self, name: str) -> float:
        # Masters read outputs in initialization mode too (libcosim passes them on to
        # connected inputs there), so before the start they are the motion at the start time.
        time = self.plate.time if self.plate.started else self.start_time
        if self._cache is None or self._cache[0] != time:
            try:
                z, v, a = self.plate.evaluate(time)
                values = {"plate_z": z, "plate_v": v, "plate_a": a}
            except Exception as exc:  # settings that do not fit together yet; start() will say why
                if self.plate.started:
                    self.log(f"internal error while evaluating the plate motion: {exc!r}", Fmi2Status.error)
                return 0.0
            self._cache = (time, values)
        return self._cache[1][name]

    def _guard(self, action, *args) -> bool:
        """Run one request; on a bad request log fmi2Error and keep the last good state."""
        try:
            action(*args)
            self._cache = None
            return True
        except ExcitationError as exc:
            self.log(str(exc), Fmi2Status.error)
        except Exception as exc:  # a host must never see a Python exception (see module doc)
            self.log(f"internal error: {exc!r}\n{traceback.format_exc()}", Fmi2Status.error)
        return False

    # ------------------------------------------------------------------ FMI calls
    def setup_experiment(self, start_time=0.0, stop_time=None, tolerance=None):
        if start_time is not None and not math.isfinite(start_time):
            self.log(f"start time {start_time!r} is not finite; 0 is used", Fmi2Status.error)
            return
        self.start_time = float(start_time or 0.0)
        self._cache = None

    def exit_initialization_mode(self):
        if self._guard(self.plate.start, self.start_time) and self.plate.mode == PLAYBACK:
            problems = self.plate.playback().rest_problems()
            if problems:
                self.log(f"the record {self.plate.playback().source} does not start or end at rest ("
                         f"{'; '.join(problems)}); outside the record the plate rests, so its motion jumps "
                         "there", Fmi2Status.warning)

    def do_step(self, current_time: float, step_size: float) -> bool:
        return self._guard(self._do_step, current_time, step_size)

    def _do_step(self, current_time: float, step_size: float) -> None:
        if not self.plate.started:
            raise ExcitationError("doStep before a successful initialization (see earlier errors)")
        if not (math.isfinite(step_size) and step_size > 0.0):
            raise ExcitationError(f"communication step size {step_size!r} must be a finite number > 0")
        now = self.plate.time
        if not math.isfinite(current_time) or abs(current_time - now) > 1e-9 * max(1.0, abs(now)):
            raise ExcitationError(f"communication point {current_time!r} differs from the FMU's time {now!r}; "
                                  "to go back in time restore an FMU state first")
        self.plate.advance_to(current_time + step_size)

    def terminate(self):
        pass

    # ------------------------------------------------------------------ FMU state
    # pythonfmu's default would capture the registered scalars only, not the clock.
    def _get_fmu_state(self):
        try:
            return {"plate": self.plate.get_state(), "start_time": self.start_time}
        except Exception as exc:
            self.log(f"could not capture the FMU state: {exc!r}", Fmi2Status.error)
            return {}

    def _set_fmu_state(self, state):
        try:
            plate = Plate.from_state(state["plate"], known=self.plate.record, bundled=self.bundled)
            self.start_time = float(state["start_time"])
            self.plate, self._cache = plate, None
        except ExcitationError as exc:
            self.log(f"{exc}; the current state is kept", Fmi2Status.error)
        except (KeyError, TypeError, ValueError) as exc:
            self.log(f"not a valid FMU state for the excitation: {exc!r}; the current state is kept",
                     Fmi2Status.error)
        except Exception as exc:
            self.log(f"internal error while restoring the FMU state: {exc!r}", Fmi2Status.error)
