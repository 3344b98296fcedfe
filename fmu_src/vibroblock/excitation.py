"""Vertical plate motions for the block: the signal core of the Excitation FMU.

A plate motion is three functions of time that belong together: the height ``z(t)``,
the velocity ``v(t) = dz/dt`` and the acceleration ``a(t) = dv/dt``.  Every mode
below returns all three from one closed form, so they are consistent by construction
(analytic modes: exactly; playback: to rounding, see ``Playback``).  Nothing here
knows FMI; the FMU script ``Excitation.py`` is a thin facade over ``Excitation``.

Time and amplitude
------------------
A signal ``f`` is written in its own time ``s`` and scaled into the plate motion::

    s = (t - onset) / time_scale
    z(t) = amplitude_scale * w(t) * f(s)

so ``v = amplitude_scale (w' f + w f'(s) / time_scale)`` and
``a = amplitude_scale (w'' f + 2 w' f'(s) / time_scale + w f''(s) / time_scale**2)``:
stretching a signal in time by ``time_scale`` divides its velocity by ``time_scale``
and its acceleration by ``time_scale**2``.  ``w`` is the start envelope:

* ``ramp_time = 0`` (default): ``w = 1`` at all times; the signal is defined for all
  ``t`` and ``onset`` is a plain time shift;
* ``ramp_time > 0``: the plate rests (``z = v = a = 0``) before ``onset`` and the
  amplitude rises over ``ramp_time`` with the quintic ``w = 10u^3 - 15u^4 + 6u^5``,
  ``u = (t - onset) / ramp_time``, whose first and second derivatives vanish at both
  ends: the plate starts without a jump in velocity or acceleration (a block resting
  on a plate that starts moving abruptly is hit, not shaken).

Modes (``MODES``; in the block model's units, lengths in delta_0 and times in tau_0,
unless a record says otherwise)
---------------------------------------------------------------------------------
0. harmonic: ``f = amplitude sin(omega s + phase)``.
1. linear chirp: ``f = amplitude sin(theta(s) + phase)``; the angular frequency
   ``theta'`` goes linearly from ``omega_start`` to ``omega_end`` for
   ``0 <= s <= sweep_time`` and stays at ``omega_start`` before, ``omega_end`` after.
2. logarithmic chirp: as 1 with ``theta'`` growing geometrically,
   ``omega_start (omega_end / omega_start)^(s / sweep_time)``; both frequencies > 0.
3. sum of harmonics: ``f = sum_i amplitude_i sin(omega_i s + phase_i)``,
   i = 1..``N_COMPONENTS``.
4. playback of a record (``Playback``): a uniformly sampled acceleration, integrated
   exactly as a piecewise-linear function; before its first and after its last sample
   the plate rests at the record's first/last height.

The chirps' acceleration jumps where the sweep starts and ends (``theta''`` jumps);
height and velocity stay continuous.

Record files (mode 4)
---------------------
``record_file`` names a ``.npz`` archive or a two-column text file (``.csv``,
``.txt``, ``.dat``; columns time and acceleration, ``#`` comments, comma or blank
separated) in any consistent units: the FMU multiplies heights by ``amplitude_scale``
and divides times by ``time_scale``, so a record in metres and seconds plays in the
block's units with ``amplitude_scale = 1 / delta_0[m]`` and
``time_scale = 1 / tau_0[s]``.  The ``.npz`` holds ``dt`` (sample interval) and
``acceleration``; optionally ``velocity0``, ``displacement0`` (values at the first
sample, default 0) and full ``velocity``, ``displacement`` series, which must agree
with the exact integral of the acceleration (they are checked, then recomputed).
The empty name selects the record bundled with the package (``BUNDLED_RECORD``).
"""
from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .parameters import NON_NEGATIVE, POSITIVE, Parameter

MODES = {0: "harmonic", 1: "linear_chirp", 2: "log_chirp", 3: "harmonic_sum", 4: "playback"}
HARMONIC, LINEAR_CHIRP, LOG_CHIRP, HARMONIC_SUM, PLAYBACK = range(5)
N_COMPONENTS = 4

DATA_DIR = Path(__file__).resolve().parent / "data"
# Vertical ground motion of a local event at station BW.RJOB (Bavaria), 2009-08-24,
# shipped with obspy; processed to consistent SI acceleration (m/s^2, dt in s) by
# ``harness.ground.excitation.write_bundled_record`` (how: see the archive's ``history``).
BUNDLED_RECORD = DATA_DIR / "bw_rjob_ehz_2009-08-24.npz"
TEXT_SUFFIXES = (".csv", ".txt", ".dat")
# A record file's velocity and displacement may differ from the exact integral of
# its acceleration by this fraction of their peak (rounding of the writer's sums).
CONSISTENCY_TOLERANCE = 1e-9
# A record whose first or last velocity/acceleration exceeds this fraction of its
# peak does not start or end at rest: the plate's motion jumps there (warned).
REST_TOLERANCE = 1e-3
# Sample times of a text record may deviate from a uniform grid by this fraction of dt.
UNIFORM_TOLERANCE = 1e-6
MAX_SAMPLES = 50_000_000


class ExcitationError(ValueError):
    """A value or request the excitation cannot accept; the message says which and why."""


# ---------------------------------------------------------------------------- parameters
# The same admissibility rules as the block's parameters (parameters.py).


def _component_parameters():
    for i in range(1, N_COMPONENTS + 1):
        yield Parameter(f"amplitude_{i}", 0.0, "delta_0", f"amplitude of component {i} (mode 3)")
        yield Parameter(f"omega_{i}", 0.0, "1/tau_0", f"angular frequency of component {i} (mode 3)", NON_NEGATIVE)
        yield Parameter(f"phase_{i}", 0.0, "rad", f"phase of component {i} (mode 3)")


PARAMETERS: tuple[Parameter, ...] = (
    Parameter("amplitude", 1.0, "delta_0", "amplitude of the harmonic and the chirps (modes 0-2)"),
    Parameter("omega", 0.1, "1/tau_0", "angular frequency of the harmonic (mode 0)", NON_NEGATIVE),
    Parameter("phase", 0.0, "rad", "phase of the harmonic and the chirps (modes 0-2)"),
    Parameter("omega_start", 0.05, "1/tau_0", "angular frequency where a chirp starts (modes 1, 2)", NON_NEGATIVE),
    Parameter("omega_end", 0.5, "1/tau_0", "angular frequency where a chirp ends (modes 1, 2)", NON_NEGATIVE),
    Parameter("sweep_time", 1000.0, "tau_0", "duration of a chirp's sweep, in signal time s (modes 1, 2)",
              POSITIVE),
    *_component_parameters(),
    Parameter("amplitude_scale", 1.0, "delta_0 per signal length unit",
              "factor on the signal's height (a record in metres: 1/delta_0[m] times any amplification)"),
    Parameter("time_scale", 1.0, "tau_0 per signal time unit",
              "stretch of the signal in time, s = (t - onset)/time_scale (a record in seconds: 1/tau_0[s])",
              POSITIVE),
    Parameter("onset", 0.0, "tau_0", "time at which the signal's time s is 0 (a record's first sample plays)"),
    Parameter("ramp_time", 0.0, "tau_0",
              "0: no envelope; > 0: plate at rest before onset, amplitude rising smoothly over ramp_time",
              NON_NEGATIVE),
    Parameter("direction", 0.0, "rad",
              "direction of the motion from the vertical towards +x: plate_z is cos(direction) and plate_x "
              "sin(direction) times the signal (a Block with plate_motion = 1 takes plate_x; a record played "
              "with its horizontal component has its own plate_x and ignores this)"),
)
PARAMETER_NAMES = tuple(p.name for p in PARAMETERS)
_SPECS = {p.name: p for p in PARAMETERS}


def defaults() -> dict[str, float]:
    return {p.name: p.default for p in PARAMETERS}


# ---------------------------------------------------------------------------- signals
# Every signal maps signal time s (float or array) to (f, f', f'') in signal units.
def _sinusoid(amplitude, theta, rate, curvature):
    """amplitude sin(theta) and its first two derivatives, given theta' and theta''."""
    sin, cos = np.sin(theta), np.cos(theta)
    return amplitude * sin, amplitude * rate * cos, amplitude * (curvature * cos - rate * rate * sin)


@dataclass(frozen=True)
class Harmonic:
    amplitude: float
    omega: float
    phase: float

    def __call__(self, s):
        return _sinusoid(self.amplitude, self.omega * s + self.phase, self.omega, 0.0)


@dataclass(frozen=True)
class HarmonicSum:
    components: tuple[Harmonic, ...]

    def __call__(self, s):
        f = df = d2f = 0.0 * s
        for component in self.components:
            g, dg, d2g = component(s)
            f, df, d2f = f + g, df + dg, d2f + d2g
        return f, df, d2f


@dataclass(frozen=True)
class Chirp:
    """Sweep of the angular frequency from omega_start to omega_end over [0, sweep_time]."""

    amplitude: float
    omega_start: float
    omega_end: float
    sweep_time: float
    phase: float
    logarithmic: bool

    def phase_rate(self, s):
        """theta(s), theta'(s), theta''(s) of the sweep, extended at constant frequency."""
        w0, w1, T = self.omega_start, self.omega_end, self.sweep_time
        inside = np.clip(s, 0.0, T)
        if self.logarithmic and w1 != w0:
            growth = math.log(w1 / w0) / T
            rate = w0 * np.exp(growth * inside)
            theta_in = (rate - w0) / growth
            curvature_in = growth * rate
        else:
            slope = (w1 - w0) / T
            rate = w0 + slope * inside
            theta_in = w0 * inside + 0.5 * slope * inside * inside
            curvature_in = slope + 0.0 * inside
        sweeping = (s >= 0.0) & (s <= T)
        theta = theta_in + rate * (s - inside)  # constant frequency outside the sweep
        return theta, rate, np.where(sweeping, curvature_in, 0.0)

    def __call__(self, s):
        theta, rate, curvature = self.phase_rate(s)
        return _sinusoid(self.amplitude, theta + self.phase, rate, curvature)


class Playback:
    """A record as a piecewise-linear acceleration, integrated exactly.

    Between samples i and i + 1 (tau = s - s_i):

        a = a_i + j tau,  v = v_i + a_i tau + j tau^2 / 2,  z = z_i + v_i tau + a_i tau^2 / 2 + j tau^3 / 6

    with j = (a_{i+1} - a_i) / dt and v_i, z_i from the same formulas at tau = dt (the
    scheme of ``harness.ground.records``), so v = dz/ds and a = dv/ds hold exactly inside each
    interval and z, v, a are continuous across samples up to rounding of the sums.
    """

    def __init__(self, acceleration, dt: float, velocity0: float = 0.0, displacement0: float = 0.0,
                 source: str = ""):
        a = np.array(acceleration, dtype=float).ravel()
        if a.size < 2:
            raise ExcitationError(f"record {source or '(array)'} has {a.size} samples; it needs at least 2")
        if a.size > MAX_SAMPLES:
            raise ExcitationError(f"record {source} has {a.size} samples, more than {MAX_SAMPLES}")
        if not np.all(np.isfinite(a)):
            bad = int(np.argmax(~np.isfinite(a)))
            raise ExcitationError(f"record {source} has a non-finite acceleration at sample {bad}")
        dt, velocity0, displacement0 = float(dt), float(velocity0), float(displacement0)
        if not (math.isfinite(dt) and dt > 0.0):
            raise ExcitationError(f"record {source}: sample interval dt = {dt!r} must be a finite number > 0")
        if not (math.isfinite(velocity0) and math.isfinite(displacement0)):
            raise ExcitationError(f"record {source}: initial velocity/displacement must be finite")
        self.acceleration, self.dt, self.source = a, dt, source
        self.velocity, self.displacement = integrate(a, dt, velocity0, displacement0)
        self.acceleration.setflags(write=False)
        self.velocity.setflags(write=False)
        self.displacement.setflags(write=False)
        self.duration = (a.size - 1) * dt
        digest = hashlib.sha256(np.float64(dt).tobytes())
        for series in (a, np.array([velocity0, displacement0])):
            digest.update(np.ascontiguousarray(series).tobytes())
        self.digest = digest.hexdigest()

    def rest_problems(self) -> list[str]:
        """Ways in which the record does not start or end at rest (the plate jumps there)."""
        problems = []
        for name, series in (("velocity", self.velocity), ("acceleration", self.acceleration)):
            peak = float(np.max(np.abs(series)))
            for where, value in (("first", series[0]), ("last", series[-1])):
                if peak > 0.0 and abs(value) > REST_TOLERANCE * peak:
                    problems.append(f"{where} {name} {value:.3g} is {abs(value) / peak:.1%} of its peak")
        return problems

    def __call__(self, s):
        a, v, z, h = self.acceleration, self.velocity, self.displacement, self.dt
        inside = np.clip(s, 0.0, self.duration)
        i = np.minimum(np.floor(inside / h).astype(np.int64), a.size - 2)
        tau = inside - i * h
        jerk = (a[i + 1] - a[i]) / h
        acc = a[i] + jerk * tau
        vel = v[i] + a[i] * tau + 0.5 * jerk * tau**2
        disp = z[i] + v[i] * tau + 0.5 * a[i] * tau**2 + jerk * tau**3 / 6.0
        resting = (s < 0.0) | (s > self.duration)  # at rest at the first/last height
        return disp, np.where(resting, 0.0, vel), np.where(resting, 0.0, acc)


def integrate(acceleration, dt: float, velocity0: float = 0.0, displacement0: float = 0.0):
    """Velocity and displacement of a piecewise-linear acceleration, exactly."""
    a = np.asarray(acceleration, dtype=float)
    v = np.concatenate(([velocity0], velocity0 + np.cumsum(0.5 * dt * (a[:-1] + a[1:]))))
    z = np.concatenate(([displacement0],
                        displacement0 + np.cumsum(dt * v[:-1] + dt * dt * (2.0 * a[:-1] + a[1:]) / 6.0)))
    return v, z


def load_record(path: str | Path = "", bundled: str | Path = BUNDLED_RECORD) -> Playback:
    """Read a record file (see the module doc); the empty name is the bundled record,
    found at ``bundled`` (an FMU passes the copy in its own resources folder)."""
    path = Path(path) if str(path) else Path(bundled)
    where = str(path)
    if not path.is_file():
        raise ExcitationError(f"record_file = {where!r} does not exist (or is not a file): give the path of an "
                              f"existing record file, absolute or relative to the master's working directory "
                              f"({Path.cwd()}), or leave it empty for the bundled record")
    try:
        if path.suffix.lower() == ".npz":
            return _load_npz(path)
        if path.suffix.lower() in TEXT_SUFFIXES:
            return _load_text(path)
    except ExcitationError:
        raise
    except Exception as exc:  # numpy raises many types for unreadable files
        raise ExcitationError(f"cannot read record file {where!r}: {exc}") from None
    raise ExcitationError(f"record_file = {where!r} is not a record the FMU plays (unknown format; it plays .npz "
                          f"with dt and acceleration, or two-column text {', '.join(TEXT_SUFFIXES)}: time, "
                          f"acceleration); a seismic record (SAC, MiniSEED, ... in counts or physical units) becomes "
                          f"one with 'vibroblock record FILE --save-record record.npz' (response removed, processed, "
                          f"SI)")


def _load_npz(path: Path) -> Playback:
    with np.load(path, allow_pickle=False) as data:
        missing = [key for key in ("dt", "acceleration") if key not in data.files]
        if missing:
            raise ExcitationError(f"record file {str(path)!r} lacks {', '.join(missing)}; it holds "
                                  f"{', '.join(data.files) or 'nothing'}")
        if np.size(data["dt"]) != 1:
            raise ExcitationError(f"record file {str(path)!r}: dt must be one number")
        acceleration = data["acceleration"]
        if acceleration.ndim != 1:
            raise ExcitationError(f"record file {str(path)!r}: acceleration must be one-dimensional, "
                                  f"not of shape {acceleration.shape}")
        given = {key: data[key] for key in ("velocity", "displacement") if key in data.files}
        v0 = float(data["velocity0"]) if "velocity0" in data.files else float(given.get("velocity", [0.0])[0])
        z0 = (float(data["displacement0"]) if "displacement0" in data.files
              else float(given.get("displacement", [0.0])[0]))
        record = Playback(acceleration, float(data["dt"]), v0, z0, source=str(path))
    for key, series in given.items():
        exact = record.velocity if key == "velocity" else record.displacement
        series = np.asarray(series, dtype=float)
        if series.shape != exact.shape:
            raise ExcitationError(f"record file {str(path)!r}: {key} has {series.size} samples, "
                                  f"acceleration {exact.size}")
        scale = max(float(np.max(np.abs(exact))), float(np.max(np.abs(series))), np.finfo(float).tiny)
        deviation = float(np.max(np.abs(series - exact))) / scale
        if not deviation <= CONSISTENCY_TOLERANCE:
            raise ExcitationError(
                f"record file {str(path)!r}: its {key} is not the integral of its acceleration taken as "
                f"piecewise linear (off by {deviation:.2e} of its peak, tolerance {CONSISTENCY_TOLERANCE:g}); "
                f"store the acceleration only, with velocity0 and displacement0")
    return record


def _load_text(path: Path) -> Playback:
    text = path.read_text(errors="replace").replace(",", " ")
    rows = [line.split("#", 1)[0].split() for line in text.splitlines()]
    rows = [row for row in rows if row]
    if any(len(row) != 2 for row in rows):
        raise ExcitationError(f"record file {str(path)!r}: every data line must hold two numbers "
                              "(time, acceleration)")
    try:
        table = np.array(rows, dtype=float).reshape(-1, 2)
    except ValueError as exc:
        raise ExcitationError(f"record file {str(path)!r}: {exc}") from None
    if table.shape[0] < 2:
        raise ExcitationError(f"record file {str(path)!r} has {table.shape[0]} samples; it needs at least 2")
    time = table[:, 0]
    steps = np.diff(time)
    dt = (time[-1] - time[0]) / (time.size - 1)
    if not (np.all(np.isfinite(time)) and dt > 0.0 and np.max(np.abs(steps - dt)) <= UNIFORM_TOLERANCE * dt):
        raise ExcitationError(f"record file {str(path)!r}: the times are not uniformly increasing "
                              f"(steps from {steps.min():g} to {steps.max():g}); resample the record first")
    return Playback(table[:, 1], dt, source=str(path))


# ---------------------------------------------------------------------------- envelope
def envelope(u):
    """Quintic start ramp w(u) = 10u^3 - 15u^4 + 6u^5 on [0, 1] (0 before, 1 after) and
    its first two derivatives with respect to u."""
    u = np.clip(u, 0.0, 1.0)
    w = u**3 * (10.0 + u * (-15.0 + 6.0 * u))
    dw = 30.0 * u**2 * (1.0 - u) ** 2
    d2w = 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u)
    return w, dw, d2w


# ---------------------------------------------------------------------------- excitation
class Excitation:
    """A plate motion as the Excitation FMU computes it (see the module doc).

    Typical use::

        plate = Excitation(mode=1, amplitude=2.0, omega_start=0.05, omega_end=0.5)
        plate.start()
        z, v, a = plate.evaluate(np.linspace(0.0, 100.0, 11))
    """

    def __init__(self, mode: int = HARMONIC, record_file: str = "", bundled: str | Path = BUNDLED_RECORD,
                 **parameters: float):
        self.bundled = Path(bundled)
        self.parameters = defaults()
        self.mode = HARMONIC
        self.record_file = ""
        self.record: Playback | None = None
        self.horizontal_record: Playback | None = None  # a record's own horizontal component (plate_x)
        self.started = False
        self.time = 0.0
        self.set_mode(mode)
        for name, value in parameters.items():
            self.set_parameter(name, value)
        if record_file:
            self.set_record_file(record_file)

    # ------------------------------------------------------------------ settings
    def _require_not_started(self, what: str) -> None:
        if self.started:
            raise ExcitationError(f"{what} is fixed once the run has started")

    def set_parameter(self, name: str, value: float) -> None:
        spec = _SPECS.get(name)
        if spec is None:
            raise ExcitationError(f"the excitation has no parameter {name!r}; it has {list(PARAMETER_NAMES)}")
        problem = spec.problem(value)
        if problem:
            raise ExcitationError(problem)
        self._require_not_started(name)
        self.parameters[name] = float(value)

    def set_mode(self, mode: int) -> None:
        if isinstance(mode, bool) or not isinstance(mode, (int, np.integer)) or int(mode) not in MODES:
            raise ExcitationError(f"mode = {mode!r} is not one of {MODES}")
        self._require_not_started("mode")
        self.mode = int(mode)

    def set_record_file(self, path: str) -> None:
        """Name the record to play; it is read now, so that a bad file is refused at once.
        The empty name (the default) selects the bundled record, read when first needed."""
        if not isinstance(path, str):
            raise ExcitationError(f"record_file = {path!r} is not a string")
        self._require_not_started("record_file")
        record = load_record(path, self.bundled) if path else None
        self.record_file, self.record = path, record

    def use_record(self, record: Playback, name: str = "", horizontal: Playback | None = None) -> None:
        """Play a record held in memory (e.g. a processed ground motion); ``name`` is
        what ``record_file`` reports, for the log and the state.  ``horizontal``: the
        record's horizontal component along +x (e.g. a three-component record's, rotated
        to the slip azimuth), played as plate_x on the same clock."""
        for part in (record, horizontal):
            if part is not None and not isinstance(part, Playback):
                raise ExcitationError(f"use_record needs a Playback, not {type(part).__name__}")
        if record is None:
            raise ExcitationError("use_record needs a Playback, not None")
        self._require_not_started("the record")
        self.record_file, self.record, self.horizontal_record = name, record, horizontal

    def playback(self) -> Playback:
        """The record of mode 4 (the bundled one unless record_file names another)."""
        if self.record is None:
            self.record = load_record(self.record_file, self.bundled)
        return self.record

    def signal(self):
        """The signal of the chosen mode, checking the settings that belong together."""
        p = self.parameters
        if self.mode == HARMONIC:
            return Harmonic(p["amplitude"], p["omega"], p["phase"])
        if self.mode in (LINEAR_CHIRP, LOG_CHIRP):
            logarithmic = self.mode == LOG_CHIRP
            if logarithmic and not (p["omega_start"] > 0.0 and p["omega_end"] > 0.0):
                raise ExcitationError(
                    f"a logarithmic chirp needs omega_start > 0 and omega_end > 0, got {p['omega_start']!r} "
                    f"and {p['omega_end']!r}")
            return Chirp(p["amplitude"], p["omega_start"], p["omega_end"], p["sweep_time"], p["phase"], logarithmic)
        if self.mode == HARMONIC_SUM:
            return HarmonicSum(tuple(Harmonic(p[f"amplitude_{i}"], p[f"omega_{i}"], p[f"phase_{i}"])
                                     for i in range(1, N_COMPONENTS + 1)))
        return self.playback()

    # ------------------------------------------------------------------ running
    def start(self, t0: float = 0.0) -> None:
        if not math.isfinite(t0):
            raise ExcitationError(f"start time {t0!r} is not finite")
        self._signal = self.signal()
        self.time, self.started = float(t0), True

    def advance_to(self, t: float) -> None:
        """Move to time t (> the current time); the motion is a function of time only."""
        if not self.started:
            raise ExcitationError("the run has not started: call start() (FMI: exit initialization mode) first")
        if not (math.isfinite(t) and t > self.time):
            raise ExcitationError(f"cannot advance from t = {self.time!r} to t = {t!r}: "
                                  "the end time must be finite and later than the current time")
        self.time = float(t)

    def evaluate(self, t):
        """(z, v, a) of the plate at time(s) t: floats for a float, arrays for an array."""
        along = math.cos(self.parameters["direction"])
        if self.horizontal_record is not None and self.mode == PLAYBACK:
            along = 1.0  # the record's vertical channel: its horizontal one is plate_x
        z, v, a = self._played(self._signal if self.started else self.signal(), t)
        if along == 1.0:  # (the vertical motion itself, to the bit)
            return z, v, a
        return along * z, along * v, along * a

    def evaluate_horizontal(self, t):
        """(x, vx, ax) of the plate along +x at time(s) t: the record's horizontal
        component, or sin(direction) times the signal."""
        if self.horizontal_record is not None and self.mode == PLAYBACK:
            return self._played(self.horizontal_record, t)
        across = math.sin(self.parameters["direction"])
        x, vx, ax = self._played(self._signal if self.started else self.signal(), t)
        return across * x, across * vx, across * ax

    def _played(self, signal, t):
        """(f, f', f'') of ``signal`` played at time(s) t: scaled, stretched and ramped."""
        p = self.parameters
        t_arr = np.asarray(t, dtype=float)
        scale, stretch = p["amplitude_scale"], p["time_scale"]
        f, df, d2f = signal((t_arr - p["onset"]) / stretch)
        df, d2f = df / stretch, d2f / (stretch * stretch)
        if p["ramp_time"] > 0.0:
            ramp = p["ramp_time"]
            w, dw, d2w = envelope((t_arr - p["onset"]) / ramp)
            dw, d2w = dw / ramp, d2w / (ramp * ramp)
            f, df, d2f = w * f, dw * f + w * df, d2w * f + 2.0 * dw * df + w * d2f
        z, v, a = scale * f, scale * df, scale * d2f
        if t_arr.ndim == 0:
            return float(z), float(v), float(a)
        return np.broadcast_to(z, t_arr.shape).copy(), np.broadcast_to(v, t_arr.shape).copy(), \
            np.broadcast_to(a, t_arr.shape).copy()

    def outputs(self) -> dict[str, float]:
        z, v, a = self.evaluate(self.time)
        x, vx, ax = self.evaluate_horizontal(self.time)
        return {"plate_z": z, "plate_v": v, "plate_a": a, "plate_x": x, "plate_vx": vx, "plate_ax": ax}

    # ------------------------------------------------------------------ state
    def get_state(self) -> dict:
        """Everything needed to continue, as plain (JSON-able) values.

        A record enters by its file name and digest, not its samples: the state stays
        small, and a restore refuses a file whose contents changed meanwhile."""
        return {"mode": self.mode, "parameters": dict(self.parameters), "record_file": self.record_file,
                "record_digest": self.record.digest if self.record is not None else None,
                "horizontal_digest": self.horizontal_record.digest if self.horizontal_record is not None else None,
                "started": self.started, "time": self.time}

    @classmethod
    def from_state(cls, state: dict, known: Playback | None = None,
                   bundled: str | Path = BUNDLED_RECORD, known_horizontal: Playback | None = None) -> "Excitation":
        """A new excitation in ``state``; ``known`` is a record already read (reused if it is
        the same), ``known_horizontal`` its horizontal component (which a state that has one
        needs: it is read from a seismic record, not a file of its own)."""
        try:
            horizontal_digest = state.get("horizontal_digest")
            if horizontal_digest is not None and getattr(known_horizontal, "digest", None) != horizontal_digest:
                raise ExcitationError("the state plays a record's horizontal component, which is not the one given "
                                      "(the record file or its inventory changed since the state was saved)")
            excitation = cls(bundled=bundled)
            excitation.set_mode(int(state["mode"]))
            for name, value in state["parameters"].items():
                excitation.set_parameter(name, value)
            record_file, digest = str(state["record_file"]), state["record_digest"]
            excitation.record_file = record_file
            if digest is not None:
                same = known is not None and known.digest == digest
                excitation.record = known if same else load_record(record_file, bundled)
                if excitation.record.digest != digest:
                    raise ExcitationError(f"the record file {record_file or str(bundled)!r} changed since "
                                          "the state was saved")
            if horizontal_digest is not None:
                excitation.horizontal_record = known_horizontal
            if state["started"]:
                excitation.start(float(state["time"]))
            return excitation
        except (KeyError, TypeError, AttributeError) as exc:
            raise ExcitationError(f"not a valid excitation state: {exc!r}") from None
