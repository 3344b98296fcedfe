"""From a record to consistent acceleration, velocity and displacement.

:func:`process_record` turns a :class:`~.readers.Record` (any of the three
quantities, SI units) into a :class:`GroundMotion` whose three series are
*kinematically consistent*: on the output grid, velocity is the exact
integral of the piecewise-linear acceleration and displacement the exact
integral of the resulting piecewise-quadratic velocity::

    v[i+1] = v[i] + dt (a[i] + a[i+1]) / 2
    z[i+1] = z[i] + dt v[i] + dt² (2 a[i] + a[i+1]) / 6

so a plate driven by ``(z, v, a)`` sees no contradiction between its inputs,
and :func:`~.model_units.to_model_grid` can evaluate the same piecewise
polynomials at any time.

Steps (all settings in :class:`ProcessingSettings`)
---------------------------------------------------
1. **Detrend** the input series (least-squares line or mean), removing DC
   offsets such as a zero-level error of the accelerometer.
2. **Taper** both ends with a Hann (cosine) window over ``taper_fraction`` of
   the record length each.
3. **Zero-pad** both ends by ``pad_seconds`` (default ``0.75·corners/freqmin``,
   i.e. 1.5·n/f_c in total). The zero-phase filter spreads energy in both
   directions; the pads keep it, so that the filtered record still integrates
   to a displacement that starts and ends at rest. The pads are kept in the
   output unless ``trim_padding`` is set.
4. **Convert to acceleration**: velocity or displacement input is
   differentiated in the frequency domain (multiplication by ``iω`` on the
   tapered, padded series), which is exact for band-limited data.
5. **Band-pass** the acceleration with a Butterworth filter of order
   ``corners`` run forward and backward (``scipy.signal.sosfiltfilt``): zero
   phase, amplitude response ``|H|²`` (−6 dB at ``freqmin`` and ``freqmax``),
   effective order 2·``corners``.
6. **Integrate** twice with the scheme above, starting at rest at the start
   of the padded window.
7. **Baseline correction**: a polynomial ``p(t) = Σ c_k (t/T)^k``,
   ``k = 2 … baseline_order`` (no constant or linear term, so the start at
   rest is kept) is fitted by least squares to the displacement over the whole
   window, constrained so that the corrected displacement *and* velocity are
   exactly zero at the end. ``p''`` is removed from the acceleration and the
   correction is integrated with the same scheme, so consistency holds
   exactly. This is the consistent form of the usual "high-pass after each
   integration": a high-pass on velocity or displacement alone would break
   ``a = dv/dt``; pushing the correction back to the acceleration keeps it.

The order of magnitude of the result can be judged from
:attr:`GroundMotion.peak_acceleration` and friends; all values are SI.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, replace
from typing import Literal

import numpy as np
from scipy import fft as sp_fft
from scipy import signal

from .errors import RecordError
from .quantities import SI_UNITS, STANDARD_GRAVITY, Quantity
from .readers import Record

__all__ = [
    "GroundMotion",
    "ProcessingSettings",
    "integrate_linear_acceleration",
    "load_ground_motion",
    "process_record",
    "scale_to_peak_acceleration",
]


@dataclass(frozen=True)
class ProcessingSettings:
    """Settings of :func:`process_record` (all frequencies in Hz, times in s).

    Attributes:
        freqmin: high-pass corner. Content below it is treated as noise; it
            also bounds the shortest usable record (one period, 1/freqmin).
        freqmax: low-pass corner; ``None`` means 0.4 × sampling rate (80 % of
            Nyquist). Must be below Nyquist.
        corners: Butterworth order of each filter pass (zero-phase: applied
            twice).
        taper_fraction: length of the Hann taper at *each* end, as a fraction
            of the record length (0 disables it; at most 0.5).
        detrend: ``"linear"`` removes a least-squares line, ``"constant"``
            only the mean.
        pad_seconds: zero padding at each end; ``None`` means
            ``0.75 * corners / freqmin``.
        baseline_order: highest power of the displacement baseline polynomial
            (at least 3); ``None`` skips the baseline correction (the end of
            the record is then not forced to rest).
        trim_padding: drop the pads from the output (then velocity and
            displacement no longer start exactly at rest).
    """

    freqmin: float = 0.1
    freqmax: float | None = None
    corners: int = 4
    taper_fraction: float = 0.05
    detrend: Literal["linear", "constant"] = "linear"
    pad_seconds: float | None = None
    baseline_order: int | None = 5
    trim_padding: bool = False

    def __post_init__(self) -> None:
        if not (np.isfinite(self.freqmin) and self.freqmin > 0):
            raise RecordError(f"freqmin={self.freqmin!r} Hz must be positive")
        if self.freqmax is not None and not (self.freqmax > self.freqmin):
            raise RecordError(
                f"freqmax={self.freqmax!r} Hz must be above freqmin={self.freqmin!r} Hz; "
                "raise freqmax or lower freqmin"
            )
        if int(self.corners) != self.corners or not 1 <= self.corners <= 10:
            raise RecordError(f"corners={self.corners!r} must be an integer from 1 to 10")
        if not 0 <= self.taper_fraction <= 0.5:
            raise RecordError(
                f"taper_fraction={self.taper_fraction!r} must lie in [0, 0.5]"
            )
        if self.detrend not in ("linear", "constant"):
            raise RecordError(
                f"detrend={self.detrend!r} is not supported; use 'linear' or 'constant'"
            )
        if self.pad_seconds is not None and not self.pad_seconds >= 0:
            raise RecordError(f"pad_seconds={self.pad_seconds!r} must be >= 0")
        if self.baseline_order is not None and (
            int(self.baseline_order) != self.baseline_order
            or not 3 <= self.baseline_order <= 12
        ):
            raise RecordError(
                f"baseline_order={self.baseline_order!r} must be an integer from "
                "3 to 12, or None to skip the baseline correction"
            )

    def resolved(self, sampling_rate: float) -> "ProcessingSettings":
        """Copy with ``freqmax`` and ``pad_seconds`` filled in for a record."""
        freqmax = 0.4 * sampling_rate if self.freqmax is None else float(self.freqmax)
        if self.freqmax is None and not freqmax > self.freqmin:
            # A long-period record (e.g. a 1 Hz LH channel) has no band above the default
            # high-pass corner: say which corner to move, and to where.
            raise RecordError(
                f"freqmin={self.freqmin:g} Hz is not below this record's default low-pass corner "
                f"freqmax={freqmax:g} Hz (0.4 x its sampling rate of {sampling_rate:g} Hz); "
                f"lower freqmin (--freqmin), e.g. to {freqmax / 10:.2g} Hz"
            )
        pad = 0.75 * self.corners / self.freqmin if self.pad_seconds is None else self.pad_seconds
        return replace(self, freqmax=freqmax, pad_seconds=float(pad))


@dataclass(frozen=True, eq=False)
class GroundMotion:
    """Kinematically consistent ground motion in SI units.

    Attributes:
        time: sample times in s, from the start of the output window (which
            includes the zero pads unless they were trimmed).
        acceleration: m/s².
        velocity: m/s.
        displacement: m.
        settings: the processing settings, with defaults resolved.
        record_offset: time (s, on ``time``) of the first sample of the
            original record, i.e. the front pad length.
        source: where the record came from.
        trace_id: SEED id when known.
        start_time: ISO 8601 UTC time of the record's first sample when known.
        history: steps applied, in order.
    """

    time: np.ndarray
    acceleration: np.ndarray
    velocity: np.ndarray
    displacement: np.ndarray
    settings: ProcessingSettings
    record_offset: float = 0.0
    source: str = ""
    trace_id: str = ""
    start_time: str = ""
    history: tuple[str, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        arrays = {}
        for name in ("time", "acceleration", "velocity", "displacement"):
            arr = np.array(getattr(self, name), dtype=float, copy=True)
            arr.setflags(write=False)
            arrays[name] = arr
        n = {a.shape for a in arrays.values()}
        if len(n) != 1 or arrays["time"].ndim != 1:
            raise RecordError(f"time and series must be 1-D of equal length, got {n}")
        for name, arr in arrays.items():
            object.__setattr__(self, name, arr)
        object.__setattr__(self, "history", tuple(self.history))

    @property
    def dt(self) -> float:
        """Sample interval in s."""
        return float(self.time[1] - self.time[0])

    @property
    def peak_acceleration(self) -> float:
        """Largest |acceleration| in m/s²."""
        return float(np.max(np.abs(self.acceleration)))

    @property
    def peak_velocity(self) -> float:
        """Largest |velocity| in m/s."""
        return float(np.max(np.abs(self.velocity)))

    @property
    def peak_displacement(self) -> float:
        """Largest |displacement| in m."""
        return float(np.max(np.abs(self.displacement)))

    def to_dataset(self) -> "xarray.Dataset":  # noqa: F821
        """Return an :class:`xarray.Dataset` with the three series on ``time``.

        Variables carry ``units`` and ``long_name`` attributes; the dataset
        attributes hold the processing settings (prefixed ``processing_``),
        the provenance and the history (one string, lines joined by
        newlines). ``None`` settings are stored as the string ``"none"`` so
        the dataset can be written to netCDF.
        """
        import xarray as xr

        def var(values: np.ndarray, q: Quantity) -> "xr.DataArray":
            return xr.DataArray(values, dims="time",
                                attrs={"units": SI_UNITS[q], "long_name": f"ground {q.value}"})

        attrs: dict[str, object] = {
            f"processing_{k}": ("none" if v is None else v)
            for k, v in asdict(self.settings).items()
        }
        attrs.update(record_offset=self.record_offset, source=self.source,
                     trace_id=self.trace_id, start_time=self.start_time,
                     history="\n".join(self.history))
        return xr.Dataset(
            {
                "acceleration": var(self.acceleration, Quantity.ACCELERATION),
                "velocity": var(self.velocity, Quantity.VELOCITY),
                "displacement": var(self.displacement, Quantity.DISPLACEMENT),
            },
            coords={"time": ("time", self.time, {"units": "s", "long_name": "time"})},
            attrs={k: (int(v) if isinstance(v, bool) else v) for k, v in attrs.items()},
        )


def integrate_linear_acceleration(
    acceleration: np.ndarray, dt: float, v0: float = 0.0, z0: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and displacement of a piecewise-linear acceleration.

    Exact integration of the acceleration interpolated linearly between
    samples (trapezoid rule for velocity; the matching cubic rule for
    displacement)::

        v[i+1] = v[i] + dt (a[i] + a[i+1]) / 2
        z[i+1] = z[i] + dt v[i] + dt² (2 a[i] + a[i+1]) / 6

    Args:
        acceleration: samples (any units).
        dt: sample interval.
        v0, z0: velocity and displacement at the first sample.

    Returns:
        ``(velocity, displacement)`` arrays of the same length.
    """
    a = np.asarray(acceleration, dtype=float)
    dv = 0.5 * dt * (a[:-1] + a[1:])
    v = np.concatenate(([v0], v0 + np.cumsum(dv)))
    dz = dt * v[:-1] + dt * dt * (2.0 * a[:-1] + a[1:]) / 6.0
    z = np.concatenate(([z0], z0 + np.cumsum(dz)))
    return v, z


def _differentiate(x: np.ndarray, dt: float, times: int) -> np.ndarray:
    """Spectral derivative of order *times* (0, 1 or 2) of a tapered series."""
    if times == 0:
        return x
    n = x.size
    nfft = sp_fft.next_fast_len(2 * n, real=True)
    spec = sp_fft.rfft(x, nfft)
    omega = 2.0 * np.pi * sp_fft.rfftfreq(nfft, dt)
    spec *= (1j * omega) ** times
    if nfft % 2 == 0:
        spec[-1] = 0.0  # Nyquist bin has no well-defined derivative
    return sp_fft.irfft(spec, nfft)[:n]


def _baseline(a: np.ndarray, v: np.ndarray, z: np.ndarray, dt: float,
              order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Constrained polynomial baseline; returns corrected (a, v, z) and coefficients."""
    n = a.size
    span = (n - 1) * dt
    s = np.arange(n) * dt / span
    powers = range(2, order + 1)
    cols_a, cols_v, cols_z = [], [], []
    for k in powers:
        ak = k * (k - 1) * s ** (k - 2) / span**2  # d²/dt² of (t/T)^k
        vk, zk = integrate_linear_acceleration(ak, dt)
        cols_a.append(ak)
        cols_v.append(vk)
        cols_z.append(zk)
    A, V, Z = (np.column_stack(c) for c in (cols_a, cols_v, cols_z))
    m = Z.shape[1]
    # minimise |z - Z c|² subject to Z[-1] c = z[-1] and V[-1] c = v[-1]
    C = np.vstack([Z[-1], V[-1]])
    d = np.array([z[-1], v[-1]])
    kkt = np.zeros((m + 2, m + 2))
    kkt[:m, :m] = 2.0 * Z.T @ Z
    kkt[:m, m:] = C.T
    kkt[m:, :m] = C
    rhs = np.concatenate([2.0 * Z.T @ z, d])
    coef = np.linalg.lstsq(kkt, rhs, rcond=None)[0][:m]
    return a - A @ coef, v - V @ coef, z - Z @ coef, coef


def process_record(record: Record, settings: ProcessingSettings | None = None) -> GroundMotion:
    """Detrend, taper, pad, filter, integrate and baseline-correct a record.

    See the module docstring for the steps and their rationale.

    Args:
        record: the input, any quantity, SI units.
        settings: processing settings (defaults: 0.1 Hz high-pass, 0.4 × fs
            low-pass, order 4, 5 % taper, linear detrend, baseline order 5).

    Returns:
        A :class:`GroundMotion` with consistent acceleration, velocity and
        displacement.

    Raises:
        RecordError: if the band does not fit the sampling (``freqmax`` at or
            above Nyquist) or the record is shorter than one period of
            ``freqmin``.
    """
    s = (settings or ProcessingSettings()).resolved(record.sampling_rate)
    dt = record.dt
    nyquist = 0.5 * record.sampling_rate
    if s.freqmax >= nyquist:
        raise RecordError(
            f"freqmax={s.freqmax:g} Hz is not below the Nyquist frequency "
            f"{nyquist:g} Hz of this record (dt={dt:g} s); lower freqmax"
        )
    if s.freqmin >= s.freqmax:
        raise RecordError(
            f"freqmin={s.freqmin:g} Hz is not below freqmax={s.freqmax:g} Hz"
        )
    if record.duration < 1.0 / s.freqmin:
        raise RecordError(
            f"{record.source}: the record lasts {record.duration:.4g} s, shorter "
            f"than one period of the high-pass corner (1/freqmin = "
            f"{1.0 / s.freqmin:.4g} s); raise freqmin or use a longer record"
        )

    x = signal.detrend(np.asarray(record.data, dtype=float),
                       type="linear" if s.detrend == "linear" else "constant")
    if s.taper_fraction > 0:
        n_taper = max(1, int(round(s.taper_fraction * record.npts)))
        ramp = 0.5 * (1.0 - np.cos(np.pi * np.arange(n_taper) / n_taper))
        x[:n_taper] *= ramp
        x[-n_taper:] *= ramp[::-1]
    n_pad = int(np.ceil(s.pad_seconds / dt))
    x = np.concatenate([np.zeros(n_pad), x, np.zeros(n_pad)])
    a = _differentiate(x, dt, 2 - record.quantity.order)

    sos = signal.butter(s.corners, [s.freqmin, s.freqmax], btype="bandpass",
                        fs=record.sampling_rate, output="sos")
    a = signal.sosfiltfilt(sos, a, padtype=None)
    v, z = integrate_linear_acceleration(a, dt)
    history = list(record.history)
    history.append(
        f"{s.detrend} detrend, {s.taper_fraction:.0%} Hann taper, {n_pad * dt:g} s "
        f"zero pads, {record.quantity.value} -> acceleration, zero-phase Butterworth "
        f"band-pass {s.freqmin:g}-{s.freqmax:g} Hz (order {s.corners} per pass), "
        "linear-acceleration integration"
    )
    if s.baseline_order is not None:
        a, v, z, coef = _baseline(a, v, z, dt, s.baseline_order)
        history.append(
            f"displacement baseline: powers 2..{s.baseline_order} of t/T fitted with "
            "zero end displacement and velocity, removed consistently from a, v, z "
            f"(largest term {np.max(np.abs(coef)):.3g} m)"
        )
    time = np.arange(a.size) * dt
    offset = n_pad * dt
    if s.trim_padding and n_pad:
        keep = slice(n_pad, a.size - n_pad)
        a, v, z = a[keep], v[keep], z[keep]
        time = np.arange(a.size) * dt
        offset = 0.0
        history.append("zero pads trimmed")
    return GroundMotion(time=time, acceleration=a, velocity=v, displacement=z,
                        settings=s, record_offset=offset, source=record.source,
                        trace_id=record.trace_id, start_time=record.start_time,
                        history=tuple(history))


def scale_to_peak_acceleration(motion: GroundMotion, peak_g: float,
                               gravity: float = STANDARD_GRAVITY) -> GroundMotion:
    """Scale a motion so that its peak |acceleration| equals ``peak_g · gravity``.

    All three series are multiplied by the same factor, so consistency is
    kept. To state the peak relative to the *block's* gravity (the model's
    g = 1), pass that gravity, e.g. ``scales.gravity`` of a
    :class:`~.model_units.ModelScales`.

    Args:
        motion: the motion to scale.
        peak_g: wanted peak acceleration in units of *gravity* (> 0).
        gravity: value of g in m/s² (default standard gravity 9.80665).

    Returns:
        A new :class:`GroundMotion`; the factor is recorded in its history.

    Raises:
        RecordError: if *peak_g* is not positive or the motion is all zero.
    """
    if not (np.isfinite(peak_g) and peak_g > 0):
        raise RecordError(f"peak_g={peak_g!r} must be a positive number")
    current = motion.peak_acceleration
    if current == 0.0:
        raise RecordError("the motion has zero acceleration everywhere; it cannot be scaled")
    factor = peak_g * gravity / current
    return replace(
        motion,
        acceleration=motion.acceleration * factor,
        velocity=motion.velocity * factor,
        displacement=motion.displacement * factor,
        history=motion.history + (
            f"scaled by {factor:.6g} to peak acceleration {peak_g:g} g "
            f"(g = {gravity:g} m/s^2)",),
    )


def load_ground_motion(source, settings: ProcessingSettings | None = None,
                       **read_kwargs) -> GroundMotion:
    """Read a record and process it: ``process_record(read_record(...))``.

    Args:
        source: file path or obspy ``Stream``/``Trace``.
        settings: processing settings (see :class:`ProcessingSettings`).
        **read_kwargs: passed to :func:`~.readers.read_record` (``quantity``,
            ``unit``, ``format``, ``inventory``, ``trace_id``, ``response``,
            ``time_tolerance``).

    Returns:
        The processed :class:`GroundMotion` (SI units).
    """
    from .readers import read_record

    return process_record(read_record(source, **read_kwargs), settings)
