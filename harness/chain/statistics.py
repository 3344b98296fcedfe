"""The statistics of an event catalogue: Gutenberg-Richter b-value by maximum likelihood
with its uncertainty and the magnitude of completeness, recurrence intervals of large
events, and the exponent of the size distribution with its fit range.

Written here from the published estimators (a few lines each); the seismology package
that offers them (seismostats) needs a map stack (cartopy, geopandas) at import.

* b-value: Aki (1965), Bull. Earthq. Res. Inst. 43, 237, with Utsu's (1966) correction
  for magnitudes binned at ``delta_m``: b = log10(e) / (mean(M) - (M_c - delta_m / 2));
  uncertainty: Shi and Bolt (1982), BSSA 72, 1677: sigma_b = 2.3 b^2 sqrt(sum (M - mean)^2
  / (n (n - 1))).
* M_c: maximum curvature (Wiemer and Wyss 2000, BSSA 90, 859): the most frequent
  magnitude bin, plus a stated correction (0.2 is the usual one; 0 by default).
* size exponent: the continuous power-law maximum-likelihood estimator over a fit range
  [s_min, s_max] (Clauset, Shalizi and Newman 2009, SIAM Rev. 51, 661, Eq. 3.1, with
  the upper cut by a bisection on the truncated likelihood), P(s) ~ s^(-tau).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class BValue:
    b: float
    sigma: float  # Shi and Bolt's standard error
    completeness: float  # M_c used
    n_events: int  # events with M >= M_c

    def __str__(self) -> str:
        return f"b = {self.b:.3f} +- {self.sigma:.3f} (M >= {self.completeness:.2f}, {self.n_events} events)"


def completeness(magnitudes, delta_m: float = 0.1, correction: float = 0.0) -> float:
    """M_c by maximum curvature: the centre of the most populated bin of width delta_m."""
    m = np.asarray(magnitudes, dtype=float)
    m = m[np.isfinite(m)]
    if m.size == 0:
        raise ValueError("no finite magnitude: no completeness")
    bins = np.round(m / delta_m).astype(np.int64)
    values, counts = np.unique(bins, return_counts=True)
    return float(values[np.argmax(counts)] * delta_m + correction)


def b_value(magnitudes, completeness_magnitude: float | None = None, delta_m: float = 0.0) -> BValue:
    """Maximum-likelihood b-value of the magnitudes at or above M_c (by maximum curvature
    if not given); ``delta_m``: their binning (0: continuous magnitudes)."""
    m = np.asarray(magnitudes, dtype=float)
    m = m[np.isfinite(m)]
    mc = completeness(m, delta_m or 0.1) if completeness_magnitude is None else float(completeness_magnitude)
    above = m[m >= mc - 1e-12]
    if above.size < 2:
        raise ValueError(f"{above.size} event(s) at or above M_c = {mc:.2f}: too few for a b-value")
    mean = float(above.mean())
    b = math.log10(math.e) / (mean - (mc - delta_m / 2.0))
    sigma = 2.3 * b * b * math.sqrt(float(np.sum((above - mean) ** 2)) / (above.size * (above.size - 1)))
    return BValue(b, sigma, mc, int(above.size))


def recurrence_intervals(start_times, magnitudes, minimum_magnitude: float) -> np.ndarray:
    """Times between successive events of magnitude >= ``minimum_magnitude``."""
    t = np.asarray(start_times, dtype=float)[np.asarray(magnitudes, dtype=float) >= minimum_magnitude]
    return np.diff(np.sort(t))


@dataclass(frozen=True)
class SizeExponent:
    tau: float
    sigma: float
    s_min: float
    s_max: float
    n_events: int

    def __str__(self) -> str:
        return (f"tau = {self.tau:.3f} +- {self.sigma:.3f} over {self.s_min:.3g} <= s <= {self.s_max:.3g} "
                f"({self.n_events} events)")


def size_exponent(sizes, s_min: float, s_max: float = math.inf) -> SizeExponent:
    """Maximum-likelihood exponent tau of P(s) ~ s^(-tau) for sizes in [s_min, s_max]."""
    s = np.asarray(sizes, dtype=float)
    s = s[(s >= s_min) & (s <= s_max)]
    if s.size < 2:
        raise ValueError(f"{s.size} event(s) in the fit range [{s_min:g}, {s_max:g}]: too few for an exponent")
    logs = float(np.mean(np.log(s / s_min)))
    tau = 1.0 + 1.0 / logs  # Clauset et al., Eq. 3.1 (no upper cut)
    if math.isfinite(s_max):
        tau = _truncated_tau(logs, math.log(s_max / s_min), tau)
    # The standard error of the untruncated estimator (Clauset et al., Eq. 3.2).
    return SizeExponent(tau, (tau - 1.0) / math.sqrt(s.size), s_min, s_max, int(s.size))


def _truncated_tau(mean_log: float, log_range: float, start: float) -> float:
    """The maximum-likelihood tau of a power law truncated to [s_min, s_max]: u = log(s/s_min)
    has density ~ exp(a u) on [0, R] (a = 1 - tau, R = log(s_max/s_min)), whose mean
    R e^(aR)/(e^(aR) - 1) - 1/a must equal the sample's; the mean falls as tau grows, so
    bisection on tau in (-10, 10) finds the root."""
    def mean_log_of(tau):
        a = 1.0 - tau
        if abs(a) < 1e-12:
            return log_range / 2.0
        return (log_range * math.exp(a * log_range)) / math.expm1(a * log_range) - 1.0 / a

    low, high = -10.0, 10.0
    for _ in range(200):
        middle = 0.5 * (low + high)
        if mean_log_of(middle) > mean_log:
            low = middle
        else:
            high = middle
    return 0.5 * (low + high)


def magnitudes(potencies) -> np.ndarray:
    """(2/3) log10 of the positive potencies: the magnitudes of the forward events (a
    back-slip, potency <= 0, has none)."""
    p = np.asarray(potencies, dtype=float)
    return (2.0 / 3.0) * np.log10(p[p > 0])


SMALL_QUANTILE = 0.2  # the size exponent's fit starts at this quantile of the small events' potencies


def catalogue_summary(n_blocks: int, sizes, potencies, t_start) -> dict:
    """What a catalogue of a chain of ``n_blocks`` says in numbers: event counts by size,
    the b-value of the finite magnitudes (by maximum curvature), the size exponent of the
    forward events smaller than half the chain from their SMALL_QUANTILE up, and the
    recurrence of system-wide events.  An estimate the catalogue is too small for holds
    its reason (``{"error": ...}``)."""
    sizes, potencies, t_start = np.asarray(sizes), np.asarray(potencies, float), np.asarray(t_start, float)
    whole = sizes == n_blocks
    small = potencies[(sizes < n_blocks / 2) & (potencies > 0)]
    measured = {"events": int(sizes.size), "system_wide": int(whole.sum()),
                "at_least_half": int((sizes >= n_blocks / 2).sum()), "single_block": int((sizes == 1).sum()),
                "back_slips": int((potencies < 0).sum()), "small_forward": int(small.size)}
    try:
        b = b_value(magnitudes(potencies))
        measured["b_value"] = {"b": b.b, "sigma": b.sigma, "completeness": b.completeness, "n_events": b.n_events}
    except ValueError as exc:
        measured["b_value"] = {"error": str(exc)}
    try:
        tau = size_exponent(small, float(np.quantile(small, SMALL_QUANTILE)) if small.size else math.inf)
        measured["size_exponent"] = {"tau": tau.tau, "sigma": tau.sigma, "s_min": tau.s_min, "s_max": tau.s_max,
                                     "n_events": tau.n_events}
    except ValueError as exc:
        measured["size_exponent"] = {"error": str(exc)}
    intervals = np.diff(np.sort(t_start[whole]))
    if intervals.size:
        measured["system_wide_recurrence"] = {"mean": float(intervals.mean()), "std": float(intervals.std())}
    return measured
