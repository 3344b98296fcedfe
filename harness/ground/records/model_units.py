"""Conversion of ground motion to the block model's units.

The model is written with m = g = k_n = 1: lengths are measured in the rest
penetration δ₀ = m g / k_n and times in τ₀ = √(m / k_n) (the inverse of the
normal-contact angular frequency). :class:`ModelScales` holds the two
factors,

* ``length_scale`` = δ₀, metres per model length unit,
* ``time_scale`` = τ₀, seconds per model time unit,

from which velocities scale with δ₀/τ₀ and accelerations with
δ₀/τ₀² = g: *one model unit of acceleration is the block's gravity*.

Worked example: a 1 kg block on a 1e5 N/m contact, g = 9.81 m/s²
----------------------------------------------------------------
>>> s = ModelScales.from_block(mass=1.0, normal_stiffness=1e5, gravity=9.81)
>>> round(s.length_scale, 10), round(s.time_scale, 7)
(9.81e-05, 0.0031623)

* δ₀ = 1 · 9.81 / 1e5 m = 9.81e-5 m; τ₀ = √(1 / 1e5) s = 3.1623e-3 s.
* velocity unit δ₀/τ₀ = 0.031022 m/s; acceleration unit δ₀/τ₀² = 9.81 m/s².
* a ground acceleration of 0.1 m/s² is 0.1 / 9.81 = 0.010194 model units;
  0.3 g (standard gravity) is 0.29990 model units;
* a ground velocity of 1 cm/s is 0.01 / 0.031022 = 0.32235 model units;
* a ground displacement of 1 mm is 1e-3 / 9.81e-5 = 10.194 model units;
* a 10 s record lasts 10 / 3.1623e-3 = 3162.3 model time units, and a
  record sampled at 100 Hz has a step of 3.1623 model time units;
* a 1 Hz shaking has angular frequency 2π · τ₀ = 0.019869 in model units,
  far below the contact's ω_n = 1.

>>> round(s.to_model(0.1, "acceleration"), 6)
0.010194
>>> round(s.to_model(0.01, "velocity"), 5)
0.32235
>>> round(s.to_model(1e-3, "displacement"), 3)
10.194
>>> round(s.to_model(10.0, "time"), 1)
3162.3

The inverse: :meth:`ModelScales.block_parameters` recovers the normal
stiffness and gravity for a given mass, and :meth:`ModelScales.to_si`
undoes :meth:`ModelScales.to_model`.

:func:`to_model_grid` converts a processed
:class:`~.processing.GroundMotion` to model units on a uniform model-time grid
(the plate drive); between the record's samples it evaluates the same
piecewise-linear acceleration / quadratic velocity / cubic displacement that
the processing integrated, so the resampled series stay exactly consistent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .errors import RecordError
from .processing import GroundMotion

__all__ = ["BLOCK_GRAVITY", "ModelScales", "PlateDrive", "to_model_grid"]

#: Default gravity (m/s²) acting on the block when deriving scales.
BLOCK_GRAVITY: float = 9.81

# exponents (p, q) of length_scale**p * time_scale**q, the SI size of one model unit
_DIMENSIONS: dict[str, tuple[int, int]] = {
    "time": (0, 1),
    "displacement": (1, 0),
    "length": (1, 0),
    "velocity": (1, -1),
    "acceleration": (1, -2),
    "angular_frequency": (0, -1),
}


def _positive(name: str, value: float) -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0):
        raise RecordError(f"{name}={value!r} must be a positive finite number")
    return value


@dataclass(frozen=True)
class ModelScales:
    """SI size of the model's units.

    Attributes:
        length_scale: metres per model length unit (δ₀ = m g / k_n).
        time_scale: seconds per model time unit (τ₀ = √(m / k_n)).
    """

    length_scale: float
    time_scale: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "length_scale", _positive("length_scale", self.length_scale))
        object.__setattr__(self, "time_scale", _positive("time_scale", self.time_scale))

    @classmethod
    def from_block(cls, mass: float, normal_stiffness: float,
                   gravity: float = BLOCK_GRAVITY) -> "ModelScales":
        """Scales of a block of *mass* (kg) on a contact of *normal_stiffness* (N/m).

        Args:
            mass: block mass m in kg.
            normal_stiffness: normal contact stiffness k_n in N/m.
            gravity: gravitational acceleration g in m/s² (default 9.81).

        Returns:
            ``ModelScales(length_scale=m g / k_n, time_scale=√(m / k_n))``.
        """
        m = _positive("mass", mass)
        k = _positive("normal_stiffness", normal_stiffness)
        g = _positive("gravity", gravity)
        return cls(length_scale=m * g / k, time_scale=math.sqrt(m / k))

    @property
    def velocity_scale(self) -> float:
        """m/s per model velocity unit (δ₀/τ₀)."""
        return self.length_scale / self.time_scale

    @property
    def acceleration_scale(self) -> float:
        """m/s² per model acceleration unit (δ₀/τ₀², equal to the block's g)."""
        return self.length_scale / self.time_scale**2

    @property
    def gravity(self) -> float:
        """The block's gravity in m/s² implied by the scales (= acceleration_scale)."""
        return self.acceleration_scale

    def block_parameters(self, mass: float) -> tuple[float, float]:
        """Inverse of :meth:`from_block` for a given mass.

        Args:
            mass: block mass in kg (the scales fix only k_n/m, not m itself).

        Returns:
            ``(normal_stiffness, gravity)`` in N/m and m/s², so that
            ``ModelScales.from_block(mass, *s.block_parameters(mass)) == s``
            up to rounding.
        """
        m = _positive("mass", mass)
        return m / self.time_scale**2, self.gravity

    def _factor(self, quantity: str) -> float:
        key = str(getattr(quantity, "value", quantity)).strip().lower()
        if key not in _DIMENSIONS:
            raise RecordError(
                f"cannot convert quantity {quantity!r}; use one of "
                f"{', '.join(sorted(_DIMENSIONS))}"
            )
        p, q = _DIMENSIONS[key]
        return self.length_scale**p * self.time_scale**q

    def to_model(self, value, quantity: str):
        """Convert an SI *value* (scalar or array) of *quantity* to model units.

        *quantity* is one of ``time``, ``displacement`` (or ``length``),
        ``velocity``, ``acceleration``, ``angular_frequency`` (rad/s).
        """
        factor = self._factor(quantity)
        if np.ndim(value) == 0:
            return float(value) / factor
        return np.asarray(value, dtype=float) / factor

    def to_si(self, value, quantity: str):
        """Convert a model-unit *value* of *quantity* to SI (inverse of :meth:`to_model`)."""
        factor = self._factor(quantity)
        if np.ndim(value) == 0:
            return float(value) * factor
        return np.asarray(value, dtype=float) * factor


@dataclass(frozen=True, eq=False)
class PlateDrive:
    """Plate kinematics in model units on a uniform model-time grid.

    Attributes:
        time: model time, from 0 with step ``dt``.
        displacement: plate displacement in units of δ₀.
        velocity: in units of δ₀/τ₀.
        acceleration: in units of δ₀/τ₀² (= the block's g).
        dt: model time step.
        scales: the unit scales used.
        motion: the SI ground motion the drive was made from.
    """

    time: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    dt: float
    scales: ModelScales
    motion: GroundMotion = field(repr=False)

    def __post_init__(self) -> None:
        for name in ("time", "displacement", "velocity", "acceleration"):
            arr = np.array(getattr(self, name), dtype=float, copy=True)
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    def to_dataset(self) -> "xarray.Dataset":  # noqa: F821
        """Return an :class:`xarray.Dataset` in model units.

        Attributes carry ``length_scale_m`` and ``time_scale_s`` and, prefixed
        ``processing_``, the settings that produced the SI motion.
        """
        import xarray as xr

        base = self.motion.to_dataset().attrs
        attrs = dict(base)
        attrs.update(length_scale_m=self.scales.length_scale,
                     time_scale_s=self.scales.time_scale,
                     model_dt=self.dt,
                     units_note="lengths in delta0=m*g/k_n, times in tau0=sqrt(m/k_n)")
        units = {"displacement": "delta0", "velocity": "delta0/tau0",
                 "acceleration": "delta0/tau0^2 (= g)"}
        return xr.Dataset(
            {k: ("time", getattr(self, k), {"units": u, "long_name": f"plate {k}"})
             for k, u in units.items()},
            coords={"time": ("time", self.time, {"units": "tau0", "long_name": "model time"})},
            attrs=attrs,
        )


def to_model_grid(motion: GroundMotion, scales: ModelScales, dt: float | None = None,
                  *, duration: float | None = None,
                  max_samples: int = 50_000_000) -> PlateDrive:
    """Convert a motion to model units on a uniform model-time grid.

    Values between the motion's samples come from the piecewise-linear
    acceleration and its exact integrals (the scheme of
    :func:`~.processing.integrate_linear_acceleration`), so the output is as
    consistent as the input and reproduces it exactly at the original
    sample times.

    Args:
        motion: processed SI motion.
        scales: model unit scales.
        dt: model time step; ``None`` keeps the record's sampling
            (``motion.dt / time_scale``).
        duration: model time span to cover from the motion's first sample;
            ``None`` covers the whole motion.
        max_samples: refuse grids larger than this (memory guard).

    Returns:
        The :class:`PlateDrive`.

    Raises:
        RecordError: for a non-positive step, a duration beyond the motion, a
            grid coarser than the band needs (its Nyquist frequency below the
            motion's ``freqmax``: lower freqmax when processing, or use a finer
            step), or a grid larger than *max_samples*.
    """
    T = scales.time_scale
    dt_model = motion.dt / T if dt is None else _positive("dt", dt)
    total = (motion.time[-1] - motion.time[0]) / T
    span = total if duration is None else _positive("duration", duration)
    if span > total * (1 + 1e-12):
        raise RecordError(
            f"duration={span:.6g} model time units exceeds the motion "
            f"({total:.6g} units = {total * T:.6g} s); shorten it"
        )
    dt_si = dt_model * T
    nyquist = 0.5 / dt_si
    fmax = motion.settings.freqmax
    if fmax is not None and dt_si > motion.dt * (1 + 1e-9) and nyquist < fmax:
        raise RecordError(
            f"model step {dt_model:.6g} (= {dt_si:.6g} s) has a Nyquist frequency of "
            f"{nyquist:.4g} Hz, below the motion's band edge freqmax={fmax:.4g} Hz, "
            "so resampling would alias; process with freqmax below "
            f"{nyquist:.4g} Hz or use a model step of at most {0.5 / fmax / T:.6g}"
        )
    n = int(math.floor(span / dt_model * (1 + 1e-12))) + 1
    if n > max_samples:
        raise RecordError(
            f"the grid would have {n} samples (> max_samples={max_samples}); use "
            "a larger model step, a shorter duration, or raise max_samples"
        )
    t_model = np.arange(n) * dt_model
    t_si = t_model * T
    h = motion.dt
    a, v, z = motion.acceleration, motion.velocity, motion.displacement
    i = np.clip(np.floor(t_si / h).astype(np.int64), 0, a.size - 2)
    tau = t_si - i * h
    da = (a[i + 1] - a[i]) / h
    acc = a[i] + da * tau
    vel = v[i] + a[i] * tau + 0.5 * da * tau**2
    disp = z[i] + v[i] * tau + 0.5 * a[i] * tau**2 + da * tau**3 / 6.0
    return PlateDrive(
        time=t_model,
        displacement=disp / scales.length_scale,
        velocity=vel / scales.velocity_scale,
        acceleration=acc / scales.acceleration_scale,
        dt=dt_model,
        scales=scales,
        motion=motion,
    )
