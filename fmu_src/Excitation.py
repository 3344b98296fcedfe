"""FMU: a vertical plate motion (harmonic, chirps, sum of harmonics, record playback)
with consistent outputs plate_z, plate_v = d(plate_z)/dt, plate_a = d(plate_v)/dt, to
connect to the plate inputs of the Block FMUs.  Signals: vibroblock/excitation.py; the
FMI machinery (errors, time, FMU state) is shared with the Block FMUs: vibroblock/fmi.py.
"""
from pathlib import Path

from pythonfmu import Fmi2Slave
from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Status, Fmi2Variability
from pythonfmu.variables import Integer, Real, String

from vibroblock.excitation import BUNDLED_RECORD, PARAMETERS, PLAYBACK, Excitation as Plate, ExcitationError
from vibroblock.fmi import FmuFacade, fmu_class

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


class ExcitationFacade(FmuFacade):
    """Plate motion source: harmonic, linear/logarithmic chirp, sum of harmonics, record playback."""

    rejected = (ExcitationError,)
    what = "the excitation"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.description = ("Vertical plate motion with kinematically consistent height, velocity and "
                            "acceleration, for the plate inputs of the vibroblock Block FMUs.")
        self.bundled = self._bundled_record(kwargs.get("resources"))
        self.plate = Plate(bundled=self.bundled)
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

    # ------------------------------------------------------------------ facade hooks
    def _changed(self) -> None:
        self._cache = None

    def _is_started(self) -> bool:
        return self.plate.started

    def _time(self) -> float:
        return self.plate.time

    def _start(self, start_time: float) -> None:
        self.plate.start(start_time)
        if self.plate.mode == PLAYBACK:
            problems = self.plate.playback().rest_problems()
            if problems:
                self.log(f"the record {self.plate.playback().source} does not start or end at rest ("
                         f"{'; '.join(problems)}); outside the record the plate rests, so its motion jumps "
                         "there", Fmi2Status.warning)

    def _advance_to(self, end_time: float) -> None:
        self.plate.advance_to(end_time)

    # pythonfmu's default would capture the registered scalars only, not the clock.
    def _capture(self) -> dict:
        return {"plate": self.plate.get_state(), "start_time": self.start_time}

    def _restore(self, state: dict) -> None:
        plate = Plate.from_state(state["plate"], known=self.plate.record, bundled=self.bundled)
        self.start_time = float(state["start_time"])
        self.plate = plate


@fmu_class(ExcitationFacade)
class Excitation(Fmi2Slave):
    """Plate motion source: harmonic, linear/logarithmic chirp, sum of harmonics, record playback."""
