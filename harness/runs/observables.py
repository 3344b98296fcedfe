"""Observables of a run: pure functions of its trajectory Dataset.

Every function takes a Dataset as :func:`harness.runs.run.simulate` returns it (variables
``x``, ``vx``, optionally ``phi_integral``, ``contact``, ``coulomb_resets`` over ``time``;
the drive velocity ``V_d`` and the other parameters as attributes) and a measuring
window; :func:`observe` computes them all under one :class:`ObservableSettings`
and returns an :class:`Observables` record that states its window, transient and
threshold.

Window: [t_from, t_to] with t_to the last sample and t_from = max(start + transient,
t_to - window) (window None: start + transient), snapped to the first sample at or
after it.

Vocabulary (one meaning each)
-----------------------------
* A **Coulomb reset** is one break of the tangential (Cundall-Strack) spring, when
  |k_t F| reaches mu_s N: the FMUs count them in their output ``coulomb_resets`` (old
  name ``slip_count``), and ``coulomb_resets`` here is their number in the window.
* A **slip** is a stretch of motion: the block moves faster than the drive.  The one rule
  that turns the motion (and with it the many resets it holds: the spring rings after a
  break and breaks again) into slips is :func:`slip_events`: a run of samples with
  vx > ``slip_release`` V_d that reaches vx > ``slip_onset`` V_d; runs at most
  ``merge_gap`` apart are one slip; it counts when it advanced x by at least
  ``slip_min_length`` (default a quarter of the paper's slip length mu_s N0 / k_d).
  ``slip_events`` is their number in the window; shorter slips count as none.
* The **regime** names what the block does in the window and never contradicts those
  counts: ``stick_slip`` has slips (or a window shorter than one cycle, with the block
  resting); a block whose phi is above the threshold while it never rests, drifts with
  the drive and makes no slip of the counted size is ``micro_slip`` (it slides, with
  short slips, e.g. one per plate period where the Coulomb bound dips at each trough of
  N).  Both are held by friction in the paper's sense (phi above the threshold): a
  sweep's Boolean ``stick_slip`` is true for both.

Definitions
-----------
* phi = <(vx - V_d)^2> / V_d^2 over the window (the paper's order parameter).  From the
  FMU's exact running integral ``phi_integral`` when recorded, otherwise by the
  trapezoidal rule on the samples.
* regime, from what the block does in the window (rules applied in this order):
  "flying" if it never touches the plate (no contact sample); "hopping" if
  phi > threshold but the block touches the plate less than half of the window and
  rests less than a tenth of it (it hops from landing to landing, e.g. from crest to
  crest of a corrugation: not held by friction, however large phi); "micro_slip" if
  phi > threshold but the block rests less than a tenth of the window, drifts with the
  drive (>= half of V_d) and no slip of the counted size completes in it; "stick_slip" if
  phi > threshold otherwise; "sliding" if it keeps up with the drive
  (drift velocity >= half of V_d); "jammed" if it neither slips nor keeps up while the
  drive spring's stretch V_d t - x grows and ends beyond the flat surface's Coulomb
  limit mu_s N0 / k_d (the paper's slip length, N0 = m g or P_l), and friction can
  self-lock where it sits: a tangential spring (k_t > 0) on a flank rising along the
  pull with tan(alpha) >= 1 / mu_s (docs/physics.md, "Self-locking"); else "stuck"
  (which includes a block held beyond that limit by the slope and load alone, e.g. the
  stable rest of Eq. (9) with k_t = 0): no slip and no sliding in a window shorter than a
  stick phase (phi = 1 for a block at rest, below any sensible threshold): lengthen
  the window to classify.  A block mostly in contact is judged by phi, as in the
  paper: its velocity cannot tell a stick from a slip when the tangential spring rings
  through every stick (model A below the onset, where the Coulomb bound dips at each
  trough of N: vx swings far beyond V_d / 10 while the block is held), see rest fraction.
* drift velocity: (x(t_to) - x(t_from)) / (t_to - t_from).
* rest fraction: share of the window's samples with |vx| < V_d / 10 (the creep of a
  stick, V_d k_d / (k_t + k_d), is 3 % of V_d with the scaled drive).  It separates a
  block that hops (never at rest) from one that sticks between bounces; it does not
  decide for a block mostly in contact.  Measured on C3 (model A, omega = 0.1, scaled
  drive), a rule asking a block in contact to rest would move the friction/sliding
  boundary from 106 (g/omega^2 = 100) down to 37 (rests from |vx|: the tangential spring
  rings through the vibrated sticks) or to 72 (rests from x averaged over a plate
  period: from ~0.7 g the block slips a little in every period).
* contact fraction: share of the window's samples with ``contact`` true (sampled at the
  output interval, so it resolves contact phases longer than that interval).
* slips (:func:`slip_events`): velocity runs with hysteresis and a minimum advance; a
  slip touching either end of the window is incomplete and not counted.  Stick time is
  the time from the end of one slip to the onset of the next; slip interval the time
  between consecutive onsets; slip length the advance of x over the slip (from the
  last sample before it to the first sample after it).
* coulomb_resets: increase of the FMU's ``slip_count`` over the window, for
  information only (it depends on dt and counts the cascades before a detachment).
* slope angles (corrugated plates, attributes ``A_x`` and ``omega_x``): the local slope
  alpha = arctan(A_x omega_x cos(omega_x x)) of the surface under the block, in degrees,
  positive where it rises along +x (the drive's direction): at the window's last sample
  (where a jammed block sits) and the median over the window's samples at rest
  (as in the rest fraction: the stick sites).  Self-locking needs alpha >= arctan(1 / mu_s).
  NaN on a flat plate, or with no sample at rest.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
import xarray as xr

from .settings import ObservableSettings

STICK_SLIP, SLIDING, HOPPING, STUCK, JAMMED, FLYING = "stick_slip", "sliding", "hopping", "stuck", "jammed", "flying"
MICRO_SLIP = "micro_slip"
REGIMES = (STICK_SLIP, MICRO_SLIP, SLIDING, HOPPING, STUCK, JAMMED, FLYING)
# The regimes with phi above the threshold while the block is held (the paper's stick-slip
# criterion): a sweep's Boolean ``stick_slip``.
PHI_STICK_SLIP = (STICK_SLIP, MICRO_SLIP)
# A block drifting slower than this share of V_d over a window without slips is stuck.
STUCK_DRIFT_FRACTION = 0.5
# At rest: |vx| below this share of V_d (the creep of a stick, V_d k_d / (k_t + k_d), is
# 3e-2 V_d with the scaled drive and 2e-3 V_d with the paper's).
REST_VELOCITY_FRACTION = 0.1
# A block with phi above the threshold hops (instead of stick-slipping) when it touches the
# plate less than HOPPING_CONTACT_FRACTION of the window and rests less than
# STICK_REST_FRACTION of it (a stick-slip cycle of the scaled drive rests > 90 % of the time).
HOPPING_CONTACT_FRACTION = 0.5
STICK_REST_FRACTION = 0.1


@dataclass(frozen=True)
class Window:
    start: float
    end: float
    first: int  # index of the first sample in the window
    last: int   # index of the last sample (inclusive)

    @property
    def duration(self) -> float:
        return self.end - self.start

    def slice(self) -> slice:
        return slice(self.first, self.last + 1)


def window(ds: xr.Dataset, transient: float = 0.0, length: float | None = None) -> Window:
    """The measuring window of ``ds`` (see module doc); at least two samples or ValueError."""
    t = ds["time"].values
    t_from = t[0] + transient
    if length is not None:
        t_from = max(t_from, t[-1] - length)
    # A tolerance keeps a window boundary that falls on a sample up to rounding.
    first = int(np.searchsorted(t, t_from - 1e-9 * max(1.0, abs(t_from))))
    last = len(t) - 1
    if last - first < 1:
        raise ValueError(f"the window starting at t = {t_from:g} holds fewer than two samples of the run "
                         f"[{t[0]:g}, {t[-1]:g}]: shorten the transient or run longer")
    return Window(float(t[first]), float(t[last]), first, last)


def drive_velocity(ds: xr.Dataset) -> float:
    try:
        return float(ds.attrs["V_d"])
    except KeyError:
        raise KeyError("the Dataset has no V_d attribute (drive velocity)") from None


def phi(ds: xr.Dataset, win: Window) -> float:
    """Order parameter <(vx - V_d)^2> / V_d^2 over the window."""
    v_d = drive_velocity(ds)
    if v_d == 0.0:
        return math.nan
    if "phi_integral" in ds:
        integral = ds["phi_integral"].values
        mean_square = (integral[win.last] - integral[win.first]) / win.duration
    else:
        t = ds["time"].values[win.slice()]
        deviation = ds["vx"].values[win.slice()] - v_d
        mean_square = np.trapezoid(deviation**2, t) / win.duration
    return float(mean_square / v_d**2)


def classify(phi_value: float, threshold: float, drift: float = math.nan, v_d: float = math.nan,
             rests: float = math.nan, contact: float = math.nan) -> str:
    """Regime from phi; the contact and rest fractions (to tell stick-slip from hopping);
    the drift and drive velocities (to tell sliding from stuck).  NaN fractions do not
    count against stick-slip."""
    if phi_value > threshold:
        if contact < HOPPING_CONTACT_FRACTION and rests < STICK_REST_FRACTION:
            return HOPPING
        return STICK_SLIP
    if abs(drift) < STUCK_DRIFT_FRACTION * abs(v_d):
        return STUCK
    return SLIDING


def refine(regime: str, ds: xr.Dataset, win: Window, contact: float, slips: int | None = None,
           rests: float = math.nan, drift: float = math.nan) -> str:
    """The rules that need the trajectory: flying (no contact in the window), micro_slip
    (phi above the threshold without a counted slip, never at rest, drifting with the
    drive: ``slips`` completed slips, ``rests`` the rest fraction, ``drift`` the drift
    velocity) and jammed (stuck with the drive spring's stretch growing beyond the flat
    surface's Coulomb limit); see the module doc."""
    if contact == 0.0:
        return FLYING
    if (regime == STICK_SLIP and slips == 0 and rests < STICK_REST_FRACTION
            and drift >= STUCK_DRIFT_FRACTION * abs(drive_velocity(ds))):
        return MICRO_SLIP
    if regime != STUCK:
        return regime
    v_d = drive_velocity(ds)
    time, x = ds["time"].values, ds["x"].values
    stretch_start = v_d * time[win.first] - x[win.first]
    stretch_end = v_d * time[win.last] - x[win.last]
    growing = abs(stretch_end) > abs(stretch_start)
    if not (growing and abs(stretch_end) > nominal_slip_length(ds.attrs)):
        return STUCK
    return JAMMED if self_locking(ds, win, v_d) else STUCK


def self_locking(ds: xr.Dataset, win: Window, v_d: float) -> bool:
    """Whether friction can hold the block where it sits against the drive's pull however
    large the pull: a tangential spring (k_t > 0) and a flank rising along the pull with
    tan(alpha) >= 1 / mu_s (docs/physics.md, "Self-locking").  A block held beyond the
    flat plate's Coulomb limit anywhere else (e.g. balanced on a flank by the drive
    spring and the load alone, Eq. (9), with k_t = 0) is not held by friction: stuck."""
    if float(ds.attrs.get("k_t", 1.0)) <= 0.0 or float(ds.attrs.get("mu_s", 0.0)) <= 0.0:
        return False
    alpha_end, _ = slope_angles(ds, win)
    if math.isnan(alpha_end):  # a flat plate: its Coulomb bound does not grow with the pull
        return False
    uphill = alpha_end * math.copysign(1.0, v_d) > 0.0
    # (alpha comes in degrees: tan(alpha) mu_s = 1 is met to rounding)
    return uphill and math.tan(math.radians(abs(alpha_end))) * float(ds.attrs["mu_s"]) >= 1.0 - 1e-12


def slope_angles(ds: xr.Dataset, win: Window) -> tuple[float, float]:
    """(alpha at the window's last sample, median alpha at rest in the window), degrees."""
    a_x, omega_x = float(ds.attrs.get("A_x", 0.0)), float(ds.attrs.get("omega_x", 0.0))
    if a_x == 0.0 or omega_x == 0.0:
        return math.nan, math.nan
    part = win.slice()
    x, vx = ds["x"].values[part], ds["vx"].values[part]
    alpha = np.degrees(np.arctan(a_x * omega_x * np.cos(omega_x * x)))
    at_rest = np.abs(vx) < REST_VELOCITY_FRACTION * abs(drive_velocity(ds))
    return float(alpha[-1]), float(np.median(alpha[at_rest])) if at_rest.any() else math.nan


def drift_velocity(ds: xr.Dataset, win: Window) -> float:
    x = ds["x"].values
    return float((x[win.last] - x[win.first]) / win.duration)


def rest_fraction(ds: xr.Dataset, win: Window) -> float:
    """Share of the window's samples with |vx| < V_d / 10 (see the module doc)."""
    vx = ds["vx"].values[win.slice()]
    return float(np.mean(np.abs(vx) < REST_VELOCITY_FRACTION * abs(drive_velocity(ds))))


def contact_fraction(ds: xr.Dataset, win: Window) -> float:
    if "contact" not in ds:
        return math.nan
    return float(np.mean(ds["contact"].values[win.slice()]))


def coulomb_resets(ds: xr.Dataset, win: Window) -> int:
    """Coulomb resets in the window (-1: not recorded); ``slip_count`` is the FMUs' old
    name of the same output."""
    name = next((n for n in ("coulomb_resets", "slip_count") if n in ds), None)
    if name is None:
        return -1
    counts = ds[name].values
    return int(counts[win.last] - counts[win.first])


def nominal_slip_length(attrs) -> float:
    """mu_s N0 / k_d, the paper's slip length, with N0 = m g (models A, B) or P_l (C)."""
    load = attrs["P_l"] if "P_l" in attrs else attrs.get("m", 1.0) * attrs.get("g", 1.0)
    k_d = attrs.get("k_d", 0.0)
    return attrs.get("mu_s", 0.0) * load / k_d if k_d > 0 else math.inf


@dataclass(frozen=True)
class SlipEvents:
    """Completed slips in a window: onset and end times, advance of x."""

    onset: np.ndarray
    end: np.ndarray
    length: np.ndarray

    @property
    def count(self) -> int:
        return len(self.onset)

    @property
    def stick_times(self) -> np.ndarray:
        return self.onset[1:] - self.end[:-1]

    @property
    def intervals(self) -> np.ndarray:
        return np.diff(self.onset)


def slip_events(time: np.ndarray, x: np.ndarray, vx: np.ndarray, onset_velocity: float, release_velocity: float,
                min_length: float, merge_gap: float = 0.0) -> SlipEvents:
    """Slips in sampled (time, x, vx).

    1. Candidates: maximal runs of samples with vx > release_velocity that contain a
       sample with vx > onset_velocity (hysteresis: small wiggles around one threshold
       do not split a slip, and creep below the release velocity is never a slip).
    2. Candidates whose gap (first sample of one - last sample of the previous) is at most
       merge_gap are merged into one slip.
    3. A run touching the first or last sample is incomplete and dropped.
    4. A slip spans from the last sample before its run to the first sample after it;
       its length is the advance of x over that span; slips shorter than min_length
       (the back-and-forth of tangential ringing) are dropped.
    """
    time, x, vx = (np.asarray(a, dtype=float) for a in (time, x, vx))
    moving = vx > release_velocity
    edges = np.diff(moving.astype(np.int8))
    starts = list(np.flatnonzero(edges == 1) + 1)
    ends = list(np.flatnonzero(edges == -1))
    if moving.size and moving[0]:
        starts.insert(0, 0)
    if moving.size and moving[-1]:
        ends.append(moving.size - 1)
    runs = [(s, e) for s, e in zip(starts, ends) if np.any(vx[s:e + 1] > onset_velocity)]
    merged: list[list[int]] = []
    for s, e in runs:
        if merged and time[s] - time[merged[-1][1]] <= merge_gap:
            merged[-1][1] = e
        else:
            merged.append([s, e])
    onset, end, length = [], [], []
    last = len(time) - 1
    for s, e in merged:
        if s == 0 or e == last:
            continue
        advance = x[e + 1] - x[s - 1]
        if advance >= min_length:
            onset.append(time[s - 1])
            end.append(time[e + 1])
            length.append(advance)
    return SlipEvents(np.array(onset), np.array(end), np.array(length))


def window_slips(ds: xr.Dataset, win: Window, settings: ObservableSettings) -> SlipEvents:
    v_d = abs(drive_velocity(ds))
    min_length = settings.slip_min_length
    if min_length is None:
        nominal = nominal_slip_length(ds.attrs)
        min_length = settings.slip_min_fraction * nominal if math.isfinite(nominal) else 0.0
    part = win.slice()
    return slip_events(ds["time"].values[part], ds["x"].values[part], ds["vx"].values[part],
                       settings.slip_onset * v_d, settings.slip_release * v_d, min_length, settings.merge_gap)


def _mean(values: np.ndarray) -> float:
    return float(np.mean(values)) if len(values) else math.nan


def _std(values: np.ndarray) -> float:
    return float(np.std(values)) if len(values) > 1 else math.nan


@dataclass(frozen=True)
class Observables:
    """The observables of one run, with the settings that produced them."""

    phi: float
    regime: str
    slip_events: int  # slips in the motion, by slip_events' rule (the module doc's vocabulary)
    stick_time_mean: float
    stick_time_std: float
    slip_interval_mean: float
    slip_length_mean: float
    slip_length_std: float
    contact_fraction: float
    rest_fraction: float        # share of the window at rest (see the module doc)
    drift_velocity: float
    coulomb_resets: int         # breaks of the friction spring (the FMUs' coulomb_resets) in the window
    slope_angle_end: float      # degrees, corrugated plates only (see the module doc)
    slope_angle_at_rest: float  # degrees, median over the samples at rest
    window_start: float
    window_end: float
    transient: float
    phi_threshold: float

    @property
    def stick_slip(self) -> bool:
        """phi above the threshold while held: stick_slip or micro_slip (the paper's criterion)."""
        return self.regime in PHI_STICK_SLIP

    def as_dict(self) -> dict:
        return asdict(self)


# Observables that vary from point to point (the rest are settings, reported as attributes).
MEASURED = ("phi", "regime", "slip_events", "stick_time_mean", "stick_time_std", "slip_interval_mean",
            "slip_length_mean", "slip_length_std", "contact_fraction", "rest_fraction", "drift_velocity", "coulomb_resets",
            "slope_angle_end", "slope_angle_at_rest", "window_start", "window_end")


def observe(ds: xr.Dataset, settings: ObservableSettings = ObservableSettings()) -> Observables:
    """All observables of a run under one set of observable settings."""
    win = window(ds, settings.transient, settings.window)
    value = phi(ds, win)
    drift = drift_velocity(ds, win)
    slips = window_slips(ds, win, settings)
    contact = contact_fraction(ds, win)
    rests = rest_fraction(ds, win)
    regime = refine(classify(value, settings.phi_threshold, drift, drive_velocity(ds), rests, contact), ds, win,
                    contact, slips.count, rests, drift)
    angle_end, angle_at_rest = slope_angles(ds, win)
    return Observables(
        phi=value, regime=regime, slip_events=slips.count,
        stick_time_mean=_mean(slips.stick_times), stick_time_std=_std(slips.stick_times),
        slip_interval_mean=_mean(slips.intervals),
        slip_length_mean=_mean(slips.length), slip_length_std=_std(slips.length),
        contact_fraction=contact, rest_fraction=rests, drift_velocity=drift,
        coulomb_resets=coulomb_resets(ds, win), slope_angle_end=angle_end, slope_angle_at_rest=angle_at_rest,
        window_start=win.start, window_end=win.end,
        transient=settings.transient, phi_threshold=settings.phi_threshold)
