"""Ground-motion records as plate kinematics for the block model.

A record file becomes a plate drive in three steps::

    from . import (ModelScales, ProcessingSettings, read_record,
                                 process_record, to_model_grid)

    record = read_record("station.mseed", inventory="station.xml")   # SI units
    motion = process_record(record, ProcessingSettings(freqmin=0.2))  # a, v, z
    scales = ModelScales.from_block(mass=1.0, normal_stiffness=1e5)
    drive = to_model_grid(motion, scales, dt=0.5)                     # model units
    drive.to_dataset()                                                # xarray

* :mod:`.readers` — :func:`read_record`: every format obspy reads (with
  instrument response removal from an inventory), PEER NGA ``.AT2``, and
  two-column (time, value) text with caller-stated units.
* :mod:`.processing` — :func:`process_record`: detrend, taper, zero-pad,
  zero-phase band-pass, integration, baseline correction; the result
  :class:`GroundMotion` holds consistent acceleration, velocity and
  displacement in SI. :func:`scale_to_peak_acceleration` rescales.
* :mod:`.components` — :func:`load_ground_motion_components`: a
  three-component record as its vertical motion and its horizontal motion
  along a slip azimuth, each channel processed as above.
* :mod:`.model_units` — :class:`ModelScales` (δ₀ = m g/k_n metres and
  τ₀ = √(m/k_n) seconds per model unit; worked example in that module) and
  :func:`to_model_grid` for a uniform model-time grid.
* :mod:`.quantities` — quantity names and accepted unit strings.

Every failure about a record or a setting raises :class:`RecordError` with a
message that says what is wrong and what to do.
"""

from .components import load_ground_motion_components
from .errors import RecordError
from .model_units import BLOCK_GRAVITY, ModelScales, PlateDrive, to_model_grid
from .processing import (
    GroundMotion,
    ProcessingSettings,
    integrate_linear_acceleration,
    load_ground_motion,
    process_record,
    scale_to_peak_acceleration,
)
from .quantities import STANDARD_GRAVITY, Quantity, parse_quantity, si_factor
from .readers import MIN_SAMPLES, Record, ResponseSettings, read_record

__all__ = [
    "BLOCK_GRAVITY",
    "GroundMotion",
    "MIN_SAMPLES",
    "ModelScales",
    "PlateDrive",
    "ProcessingSettings",
    "Quantity",
    "Record",
    "RecordError",
    "ResponseSettings",
    "STANDARD_GRAVITY",
    "integrate_linear_acceleration",
    "load_ground_motion",
    "load_ground_motion_components",
    "parse_quantity",
    "process_record",
    "read_record",
    "scale_to_peak_acceleration",
    "si_factor",
    "to_model_grid",
]
