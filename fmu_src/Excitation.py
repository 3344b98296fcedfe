"""FMU: a plate motion (harmonic, chirps, sum of harmonics, record playback) with
consistent outputs plate_z, plate_v = d(plate_z)/dt, plate_a = d(plate_v)/dt and, for a
motion along ``direction`` or a three-component record, plate_x, plate_vx, plate_ax, to
connect to the plate inputs of the Block FMUs.  Signals: vibroblock/excitation.py; the
FMI machinery (errors, time, FMU state) is shared with the Block FMUs: vibroblock/fmi.py.
"""
import math
from pathlib import Path

from pythonfmu import Fmi2Slave
from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Status, Fmi2Variability
from pythonfmu.variables import Integer, Real, String

from vibroblock.excitation import (BUNDLED_RECORD, PARAMETERS, PLAYBACK, TEXT_SUFFIXES, Excitation as Plate,
                                   ExcitationError, Playback)
from vibroblock.fmi import FmuFacade, fmu_class

OUTPUTS = {
    "plate_z": "plate height [delta_0]",
    "plate_v": "plate velocity, the exact derivative of plate_z [delta_0/tau_0]",
    "plate_a": "plate acceleration, the exact derivative of plate_v [delta_0/tau_0^2]",
    "plate_x": "plate position along +x: sin(direction) times the signal, or a record's horizontal component "
               "(record_components = 2) [delta_0]",
    "plate_vx": "plate velocity along +x, the exact derivative of plate_x [delta_0/tau_0]",
    "plate_ax": "plate acceleration along +x, the exact derivative of plate_vx [delta_0/tau_0^2]",
}
COMPONENTS_TEXT = ("components of a seismic record_file played in mode 4: 1 = one channel (the vertical one of "
                   "several) as plate_z; 2 = a three-component record (channels Z, N, E, or Z, 1, 2 with "
                   "record_inventory): its vertical motion as plate_z and its horizontal motion along "
                   "record_azimuth as plate_x, each channel processed alike")
AZIMUTH_TEXT = ("slip direction (+x) of a three-component record (record_components = 2): degrees clockwise from "
                "north; plate_x = N cos(azimuth) + E sin(azimuth)")
MODE_TEXT = ("signal f of signal time s = (t - onset)/time_scale; plate_z = amplitude_scale * w * f with w the "
             "start ramp (1 if ramp_time = 0); 0 = harmonic: amplitude sin(omega s + phase); 1 = linear chirp: "
             "amplitude sin(theta + phase), frequency linear from omega_start to omega_end over sweep_time; "
             "2 = logarithmic chirp (geometric frequency sweep); 3 = sum of harmonics amplitude_i "
             "sin(omega_i s + phase_i), i = 1..4; 4 = playback of the record in record_file (piecewise-linear "
             "acceleration integrated exactly; at rest outside the record)")
RECORD_TEXT = ("record for mode 4: path of a .npz (dt, acceleration[, velocity0, displacement0]) or two-column "
               "text file (time, acceleration), in units made model units by amplitude_scale and time_scale; "
               "or a seismic record in any format obspy reads (MiniSEED, SAC, GSE2, ..., or PEER .AT2), processed "
               "when the FMU is initialized to consistent SI acceleration, velocity and displacement (response "
               "removed with record_inventory, band 0.1 Hz to 0.4 x the sampling rate, baseline corrected; "
               "one channel, or the vertical one); "
               f"empty: the bundled record {BUNDLED_RECORD.name} (BW.RJOB vertical, 2009-08-24, SI units)")
INVENTORY_TEXT = ("instrument response of a seismic record_file in counts: path of a StationXML, RESP or dataless "
                  "SEED file (empty: the record's own units, if it has physical ones)")
# Record files the core plays as they are (vibroblock.excitation.load_record); any other is
# read and processed as a seismic record (the bundled vibroblock_records package, which is
# harness.ground.records).
PLAIN_RECORDS = (".npz", *TEXT_SUFFIXES)


class ExcitationFacade(FmuFacade):
    """Plate motion source: harmonic, linear/logarithmic chirp, sum of harmonics, record playback."""

    rejected = (ExcitationError,)
    what = "the excitation"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.description = ("Plate motion with kinematically consistent position, velocity and acceleration, "
                            "vertical and along x, for the plate inputs of the vibroblock Block FMUs.")
        self.bundled = self._bundled_record(kwargs.get("resources"))
        self.plate = Plate(bundled=self.bundled)
        self.seismic_record = ""  # a record_file processed at initialization (see _start)
        self.record_inventory = ""
        self.record_components, self.record_azimuth = 1, 0.0
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
            "record_inventory", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description=INVENTORY_TEXT, getter=lambda: self.record_inventory,
            setter=lambda value: self._guard(self._set_inventory, value)))
        self.register_variable(String(
            "record_file", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description=RECORD_TEXT, getter=lambda: self.seismic_record or self.plate.record_file,
            setter=lambda value: self._guard(self._set_record_file, value)))
        self.register_variable(Integer(
            "record_components", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description=COMPONENTS_TEXT, getter=lambda: self.record_components,
            setter=lambda value: self._guard(self._set_components, int(value))))
        self.register_variable(Real(
            "record_azimuth", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
            description=f"{AZIMUTH_TEXT} [deg]", getter=lambda: self.record_azimuth,
            setter=lambda value: self._guard(self._set_azimuth, float(value))))
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
                x, vx, ax = self.plate.evaluate_horizontal(time)
                values = {"plate_z": z, "plate_v": v, "plate_a": a, "plate_x": x, "plate_vx": vx, "plate_ax": ax}
            except Exception as exc:  # settings that do not fit together yet; start() will say why
                if self.plate.started:
                    self.log(f"internal error while evaluating the plate motion: {exc!r}", Fmi2Status.error)
                return 0.0
            self._cache = (time, values)
        return self._cache[1][name]

    def _set_components(self, components: int) -> None:
        if self.plate.started:
            raise ExcitationError("record_components is fixed once the run has started")
        if components not in (1, 2):
            raise ExcitationError(f"record_components = {components!r} is not 1 (one channel) or 2 (vertical and "
                                  "horizontal of a three-component record)")
        self.record_components = components

    def _set_azimuth(self, azimuth: float) -> None:
        if self.plate.started:
            raise ExcitationError("record_azimuth is fixed once the run has started")
        if not math.isfinite(azimuth):
            raise ExcitationError(f"record_azimuth = {azimuth!r} must be a finite number of degrees clockwise "
                                  "from north")
        self.record_azimuth = azimuth

    def _set_inventory(self, path: str) -> None:
        if self.plate.started:
            raise ExcitationError("record_inventory is fixed once the run has started")
        if path and not Path(path).is_file():
            raise ExcitationError(f"record_inventory = {path!r} does not exist (or is not a file): give the path of "
                                  "a StationXML, RESP or dataless SEED file, or leave it empty")
        self.record_inventory = str(path)

    def _set_record_file(self, path: str) -> None:
        """A plain record goes to the core, which reads it at once; a seismic one is
        checked to exist and processed when the FMU is initialized (the inventory may
        come after it)."""
        if not path or Path(path).suffix.lower() in PLAIN_RECORDS:
            self.plate.set_record_file(path)
            self.seismic_record = ""
            return
        if self.plate.started:
            raise ExcitationError("record_file is fixed once the run has started")
        if not Path(path).is_file():
            raise ExcitationError(f"record_file = {path!r} does not exist (or is not a file): give the path of an "
                                  f"existing record file, absolute or relative to the master's working directory "
                                  f"({Path.cwd()}), or leave it empty for the bundled record")
        self.seismic_record = str(path)

    def _seismic_playback(self, path: str | None = None, inventory: str | None = None,
                          components: int | None = None, azimuth: float | None = None) -> tuple:
        """The seismic record_file (or ``path``, with ``inventory``) processed to SI
        (harness.ground.records, bundled): (vertical playback, horizontal playback or None)."""
        path = self.seismic_record if path is None else path
        inventory = self.record_inventory if inventory is None else inventory
        components = self.record_components if components is None else components
        azimuth = self.record_azimuth if azimuth is None else azimuth
        try:
            from vibroblock_records import RecordError, load_ground_motion, load_ground_motion_components
        except ImportError:  # a process that has the harness: the same package
            try:
                from harness.ground.records import RecordError, load_ground_motion, load_ground_motion_components
            except ImportError as exc:
                raise ExcitationError(f"record_file = {path!r} is a seismic record, which needs obspy "
                                      f"in the FMU's Python environment ({exc}); install it (pip install obspy) or "
                                      "convert the record with 'vibroblock record FILE --save-record record.npz'") \
                    from None
        try:
            if components == 2:
                motion, horizontal = load_ground_motion_components(path, azimuth, inventory=inventory or None)
            else:
                motion, horizontal = load_ground_motion(path, inventory=inventory or None), None
        except RecordError as exc:
            if "no instrument response" in str(exc):
                raise ExcitationError(
                    f"record_file = {path!r} holds counts without an instrument response, which have "
                    "no physical meaning: set record_inventory to its StationXML, RESP or dataless SEED file, or "
                    "convert it with 'vibroblock record FILE --sensitivity COUNTS_PER_UNIT --quantity Q --unit U "
                    "--save-record record.npz' and play that") from None
            raise ExcitationError(f"record_file = {path!r}: {exc}") from None
        played = [None if m is None else Playback(m.acceleration, m.dt, m.velocity[0], m.displacement[0],
                                                  source=f"{path} ({m.trace_id})" if horizontal else path)
                  for m in (motion, horizontal)]
        return played[0], played[1]

    # ------------------------------------------------------------------ facade hooks
    def _changed(self) -> None:
        self._cache = None

    def _is_started(self) -> bool:
        return self.plate.started

    def _time(self) -> float:
        return self.plate.time

    def _start(self, start_time: float) -> None:
        if self.record_components == 2 and not (self.seismic_record and self.plate.mode == PLAYBACK):
            raise ExcitationError("record_components = 2 plays a three-component seismic record_file in mode 4 "
                                  "(playback); set mode = 4 and record_file, or record_components = 1")
        if self.seismic_record and self.plate.mode == PLAYBACK:
            vertical, horizontal = self._seismic_playback()
            self.plate.use_record(vertical, name=self.seismic_record, horizontal=horizontal)
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
        return {"plate": self.plate.get_state(), "start_time": self.start_time,
                "seismic_record": self.seismic_record, "record_inventory": self.record_inventory,
                "record_components": self.record_components, "record_azimuth": self.record_azimuth}

    def _restore(self, state: dict) -> None:
        known, known_horizontal = self.plate.record, self.plate.horizontal_record
        seismic, inventory = str(state.get("seismic_record", "")), str(state.get("record_inventory", ""))
        components, azimuth = int(state.get("record_components", 1)), float(state.get("record_azimuth", 0.0))
        digests = (state["plate"]["record_digest"], state["plate"].get("horizontal_digest"))
        if seismic and digests != (getattr(known, "digest", None), getattr(known_horizontal, "digest", None)):
            # A seismic record is known by its processed samples: process it again (a fresh
            # instance has not read it yet) and check that it is the same.
            known, known_horizontal = self._seismic_playback(seismic, inventory, components, azimuth)
            if (known.digest, getattr(known_horizontal, "digest", None)) != digests:
                raise ExcitationError(f"the record file {seismic!r} (or its inventory) changed since the state was "
                                      "saved")
        plate = Plate.from_state(state["plate"], known=known, bundled=self.bundled, known_horizontal=known_horizontal)
        self.start_time = float(state["start_time"])
        self.seismic_record, self.record_inventory = seismic, inventory
        self.record_components, self.record_azimuth = components, azimuth
        self.plate = plate


@fmu_class(ExcitationFacade)
class Excitation(Fmi2Slave):
    """Plate motion source: harmonic, linear/logarithmic chirp, sum of harmonics, record playback."""
