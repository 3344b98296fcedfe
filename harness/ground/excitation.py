"""Ground motion and other plate motions as input to the Block FMUs.

Two ways to drive a block with a processed record (``harness.ground.records``):

* through fmpy's ``input``: :func:`plate_input` evaluates the motion at the
  communication points and returns the structured array ``simulate_fmu`` takes
  (columns ``time, plate_z, plate_v, plate_a``); :func:`simulate_block` runs it;
* through the Excitation FMU (``mode = 4``): :func:`write_record` stores the motion as
  a record file and :func:`playback_parameters` gives the FMU's scale parameters.

Both evaluate the same piecewise polynomials (``vibroblock.excitation.Playback``: the
acceleration linear between samples, velocity and height its exact integrals), so a
block sees the same plate either way.  Example::

    from .records import ModelScales, load_ground_motion
    from .excitation import plate_input, playback_parameters, simulate_block, write_record

    motion = load_ground_motion("station.mseed", inventory="station.xml")   # SI
    scales = ModelScales.from_block(mass=1.0, normal_stiffness=1e5)          # delta_0, tau_0
    table = plate_input(motion, scales=scales, step_size=0.5, stop_time=2000.0)
    result = simulate_block("BlockA.fmu", table, start_values={"k_d": 1e-2})

    write_record(motion, "quake.npz")                    # for the Excitation FMU:
    start_values = {"mode": 4, "record_file": "quake.npz", **playback_parameters(scales)}

Units: a record file keeps the motion in SI (m, m/s, m/s^2, s); the Excitation FMU
multiplies heights by ``amplitude_scale = 1/delta_0`` (model lengths per metre) and
divides times by ``time_scale = 1/tau_0`` (model time units per second), which turns
velocities and accelerations into model units too (delta_0/tau_0, delta_0/tau_0^2 = g).
"""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from .records import GroundMotion, ModelScales, PlateDrive, ProcessingSettings, RecordError, process_record
from vibroblock.excitation import BUNDLED_RECORD, PLAYBACK, Excitation, Playback

__all__ = ["BUNDLED_SETTINGS", "HORIZONTAL_INPUT_NAMES", "INPUT_NAMES", "bundled_ground_motion", "communication_times", "excitation_of",
           "peak_scaled_parameters", "plate_input", "playback_parameters", "simulate_block", "write_bundled_record",
           "write_record"]

INPUT_NAMES = ("plate_z", "plate_v", "plate_a")
HORIZONTAL_INPUT_NAMES = ("plate_x", "plate_vx", "plate_ax")  # an oblique plate's (plate_motion = 1)
# The bundled record: obspy's example event (BW.RJOB, vertical), band 1-20 Hz, which
# keeps its local-event content (the velocity rises ~50x above the noise in 2-20 Hz).
BUNDLED_SETTINGS = ProcessingSettings(freqmin=1.0, freqmax=20.0)


# ---------------------------------------------------------------------------- records
def bundled_ground_motion(settings: ProcessingSettings = BUNDLED_SETTINGS) -> GroundMotion:
    """obspy's bundled example event, vertical component, response removed, processed (SI)."""
    import obspy

    from .records import read_record

    stream = obspy.read()  # the example data shipped inside obspy; nothing is downloaded
    record = read_record(stream, inventory=obspy.read_inventory(), trace_id="BW.RJOB..EHZ")
    return process_record(record, settings)


def write_record(motion: GroundMotion, path: str | os.PathLike) -> Path:
    """Store a processed motion (SI) as a record file for the Excitation FMU (``.npz``).

    The file holds the acceleration with the velocity and height at the first sample;
    the FMU integrates the rest exactly, as ``process_record`` did.  Provenance travels
    along as text entries.
    """
    path = Path(path)
    if path.suffix != ".npz":
        raise RecordError(f"record files for the Excitation FMU end in .npz, not {path.name!r}")
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "wb") as stream:  # np.savez would append .npz to some names
        np.savez_compressed(
            stream, dt=np.float64(motion.dt), acceleration=np.asarray(motion.acceleration, dtype=float),
            velocity0=np.float64(motion.velocity[0]), displacement0=np.float64(motion.displacement[0]),
            units=np.str_("SI: acceleration m/s^2, dt s (velocity m/s, displacement m)"),
            source=np.str_(motion.source), trace_id=np.str_(motion.trace_id),
            start_time=np.str_(motion.start_time), record_offset=np.float64(motion.record_offset),
            history=np.str_("\n".join(motion.history)))
    return path


def write_bundled_record(path: str | os.PathLike = BUNDLED_RECORD) -> Path:
    """(Re)write the record bundled with the Excitation FMU from obspy's example data."""
    return write_record(bundled_ground_motion(), path)


def playback_of(motion: GroundMotion) -> Playback:
    """The Excitation FMU's playback of a motion held in memory (SI, like its record file)."""
    return Playback(motion.acceleration, motion.dt, motion.velocity[0], motion.displacement[0],
                    source=motion.source or "ground motion")


# ---------------------------------------------------------------------------- scaling
def playback_parameters(scales: ModelScales, amplification: float = 1.0, onset: float = 0.0) -> dict[str, float]:
    """Excitation FMU parameters that play an SI record in the block's units.

    ``amplitude_scale = amplification / delta_0[m]`` and ``time_scale = 1 / tau_0[s]``;
    the record's first sample plays at model time ``onset``.
    """
    for name, value in (("amplification", amplification), ("onset", onset)):
        if not math.isfinite(value):
            raise RecordError(f"{name} = {value!r} must be finite")
    return {"amplitude_scale": amplification / scales.length_scale, "time_scale": 1.0 / scales.time_scale,
            "onset": float(onset)}


def peak_scaled_parameters(record: Playback, peak_acceleration: float, time_scale: float,
                           onset: float = 0.0) -> dict[str, float]:
    """Excitation FMU parameters that play ``record`` stretched by ``time_scale`` with a
    peak plate acceleration of ``peak_acceleration`` (model units: fractions of g).

    Stretching by ``time_scale`` divides accelerations by ``time_scale**2``, so the
    amplitude factor is ``peak_acceleration * time_scale**2 / max|a_record|``.
    """
    peak = float(np.max(np.abs(record.acceleration)))
    if not (math.isfinite(peak_acceleration) and peak_acceleration >= 0.0):
        raise RecordError(f"peak_acceleration = {peak_acceleration!r} must be a finite number >= 0")
    if not (math.isfinite(time_scale) and time_scale > 0.0):
        raise RecordError(f"time_scale = {time_scale!r} must be a finite number > 0")
    if peak == 0.0:
        raise RecordError(f"the record {record.source} has zero acceleration everywhere")
    return {"amplitude_scale": peak_acceleration * time_scale**2 / peak, "time_scale": float(time_scale),
            "onset": float(onset)}


# ---------------------------------------------------------------------------- fmpy input
def communication_times(stop_time: float, step_size: float, start_time: float = 0.0) -> np.ndarray:
    """start_time + k step_size, k = 0..n, as fmpy's ``simulate_fmu`` computes its points."""
    if not (math.isfinite(step_size) and step_size > 0.0):
        raise ValueError(f"step_size = {step_size!r} must be a finite number > 0")
    steps = (stop_time - start_time) / step_size
    n = round(steps)
    if n < 1 or abs(steps - n) > 1e-9 * max(1.0, steps):
        raise ValueError(f"stop_time - start_time = {stop_time - start_time!r} is not a whole number of steps "
                         f"of {step_size!r}")
    return start_time + np.arange(n + 1) * step_size


def excitation_of(source, scales: ModelScales | None = None, **parameters: float) -> Excitation:
    """A started ``vibroblock.excitation.Excitation`` playing ``source`` in model units.

    ``source``: a :class:`PlateDrive` (its SI motion and scales are used, so the drive's
    own samples are reproduced), a :class:`GroundMotion` with ``scales``, a
    ``Playback`` (played with ``parameters`` as given), or an ``Excitation`` (returned
    started).  ``parameters`` go to the Excitation (e.g.
    ``onset``, or an ``amplitude_scale`` that replaces 1/delta_0).
    """
    if isinstance(source, Excitation):
        excitation = source
    elif isinstance(source, Playback):
        excitation = Excitation(mode=PLAYBACK, **parameters)
        excitation.use_record(source, name=source.source)
        parameters = {}
    else:
        if isinstance(source, PlateDrive):
            motion, scales = source.motion, source.scales
        elif isinstance(source, GroundMotion):
            if scales is None:
                raise RecordError("a GroundMotion is in SI units: give scales=ModelScales(...) to play it")
            motion = source
        else:
            raise TypeError(f"cannot play a {type(source).__name__}; give a PlateDrive, a GroundMotion with "
                            "scales, or a vibroblock.excitation.Excitation")
        excitation = Excitation(mode=PLAYBACK, **{**playback_parameters(scales), **parameters})
        excitation.use_record(playback_of(motion), name=motion.source or "ground motion")
        parameters = {}
    for name, value in parameters.items():
        excitation.set_parameter(name, value)
    if not excitation.started:
        excitation.start()
    return excitation


def plate_input(source, *, step_size: float | None = None, stop_time: float | None = None,
                start_time: float = 0.0, scales: ModelScales | None = None, horizontal=None,
                **parameters: float) -> np.ndarray:
    """fmpy ``input`` array (``time, plate_z, plate_v, plate_a``) for a Block FMU.

    With ``step_size`` the motion is evaluated exactly at the communication points
    ``start_time + k step_size`` up to ``stop_time`` (default: the end of a drive or
    record), so fmpy hands the block each point's own values (fmpy interpolates
    linearly between table rows, which would make the three columns disagree).
    Without it a :class:`PlateDrive`'s own samples are packed as they are; run the
    block with ``output_interval = drive.dt`` then.

    ``horizontal``: a second motion (of the same kinds as ``source``, played with the
    same scales and parameters) for the plate's horizontal inputs ``plate_x, plate_vx,
    plate_ax`` of a block with ``plate_motion = 1`` (oblique), e.g. the horizontal
    component of a three-component record (``records.load_ground_motion_components``);
    or True: the source's own motion along x (an Excitation's ``direction``).
    """
    if step_size is None:
        if not isinstance(source, PlateDrive) or parameters or scales is not None or horizontal is not None:
            raise ValueError("give step_size (the communication step) unless packing a PlateDrive as it is")
        columns = (source.time, source.displacement, source.velocity, source.acceleration)
    else:
        excitation = excitation_of(source, scales, **parameters)
        if stop_time is None:
            record = excitation.record
            if record is None:
                raise ValueError("give stop_time for a signal without an end")
            p = excitation.parameters
            stop_time = start_time + step_size * math.floor(
                (p["onset"] + record.duration * p["time_scale"] - start_time) / step_size + 1e-9)
        times = communication_times(stop_time, step_size, start_time)
        columns = (times, *excitation.evaluate(times))
        if horizontal is True:  # the source's own motion along x (a direction, a record's horizontal component)
            columns += tuple(excitation.evaluate_horizontal(times))
        elif horizontal is not None:
            columns += tuple(excitation_of(horizontal, scales, **parameters).evaluate(times))
    names = INPUT_NAMES + (HORIZONTAL_INPUT_NAMES if len(columns) > 4 else ())
    table = np.empty(len(columns[0]), dtype=[("time", float)] + [(name, float) for name in names])
    for name, values in zip(table.dtype.names, columns):
        table[name] = values
    return table


def simulate_block(fmu: str | os.PathLike, table: np.ndarray, *, start_values: dict | None = None,
                   outputs=("x", "z", "vx", "vz", "phi_integral", "coulomb_resets", "contact", "normal_force"),
                   stop_time: float | None = None) -> np.ndarray:
    """Run a Block FMU in fmpy with the plate input ``table`` (:func:`plate_input`).

    The communication step is the table's row spacing, so every step starts on a row
    (fmpy sets the inputs at each communication point, then calls doStep); the block
    holds the row's acceleration over the step.
    """
    from fmpy import simulate_fmu

    time = table["time"]
    steps = np.diff(time)
    if time.size < 2 or np.max(np.abs(steps - steps[0])) > 1e-9 * steps[0]:
        raise ValueError("the input table must hold at least two rows on a uniform time grid")
    return simulate_fmu(str(fmu), start_time=float(time[0]), stop_time=float(time[-1] if stop_time is None
                                                                             else stop_time),
                        output_interval=float(steps[0]), input=table, start_values=dict(start_values or {}),
                        output=list(outputs))
