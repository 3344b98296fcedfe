"""Observables on synthetic signals whose answers are known in closed form."""
from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr

from harness.runs.observables import (FLYING, HOPPING, JAMMED, MICRO_SLIP, SLIDING, STICK_SLIP, STUCK, classify,
                                      contact_fraction, drift_velocity, observe, phi, slip_events, slope_angles,
                                      window)
from harness.runs.settings import ObservableSettings

V_D = 0.01
PERIOD = 1000.0      # stick-slip cycle
SLIP_TIME = 60.0     # duration of each slip
SLIP_LENGTH = V_D * PERIOD  # the block keeps up with the drive on average
DT = 0.1


def cumulative(t, v):
    out = np.zeros_like(v)
    out[1:] = np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))
    return out


def stick_slip_signal(cycles=6, ringing=0.0, first_onset=500.0):
    """Half-sine slips of length SLIP_LENGTH every PERIOD, optional ringing after each."""
    t = np.arange(0.0, first_onset + cycles * PERIOD + DT / 2, DT)
    vx = np.zeros_like(t)
    peak = math.pi * SLIP_LENGTH / (2 * SLIP_TIME)
    onsets = first_onset + PERIOD * np.arange(cycles)
    for onset in onsets:
        inside = (t >= onset) & (t <= onset + SLIP_TIME)
        vx[inside] = peak * np.sin(math.pi * (t[inside] - onset) / SLIP_TIME)
        if ringing:
            tail = (t > onset + SLIP_TIME + 20) & (t < onset + SLIP_TIME + 400)
            tau = t[tail] - onset - SLIP_TIME - 20
            vx[tail] = ringing * np.sin(2 * math.pi * tau / 12.0) * np.exp(-tau / 150.0)
    return t, vx, onsets


def dataset(t, vx, contact=None, phi_integral=None, **attrs):
    data = {"x": ("time", cumulative(t, vx)), "vx": ("time", vx)}
    if contact is not None:
        data["contact"] = ("time", contact)
    if phi_integral is not None:
        data["phi_integral"] = ("time", phi_integral)
    base = {"V_d": V_D, "mu_s": 0.5, "m": 1.0, "g": 1.0, "k_d": 0.5 / SLIP_LENGTH}
    return xr.Dataset(data, coords={"time": t}, attrs={**base, **attrs})


def expected_phi():
    # Over whole cycles: (integral of vx^2 - 2 V_d L + V_d^2 P) / (P V_d^2), with L = V_d P.
    peak = math.pi * SLIP_LENGTH / (2 * SLIP_TIME)
    square = peak**2 * SLIP_TIME / 2
    return (square - 2 * V_D * SLIP_LENGTH + V_D**2 * PERIOD) / (PERIOD * V_D**2)


def test_phi_of_stick_slip_cycles_matches_closed_form():
    t, vx, _ = stick_slip_signal()
    ds = dataset(t, vx)
    win = window(ds, transient=500.0 - 100.0, length=4 * PERIOD)  # exactly four whole cycles
    assert win.duration == pytest.approx(4 * PERIOD)
    assert phi(ds, win) == pytest.approx(expected_phi(), rel=1e-4)
    assert expected_phi() > ObservableSettings().phi_threshold


def test_phi_uses_the_exact_integral_when_recorded():
    t, vx, _ = stick_slip_signal()
    integral = 3.0 * V_D**2 * (t - t[0])  # a run whose <(vx - V_d)^2> is exactly 3 V_d^2
    ds = dataset(t, vx, phi_integral=integral)
    assert phi(ds, window(ds, 1000.0)) == pytest.approx(3.0, rel=1e-12)


def test_sliding_with_the_drive_has_small_phi_and_no_slips():
    t = np.arange(0.0, 5000.0, 1.0)
    vx = V_D * (1 + 0.3 * np.sin(0.5 * t))
    ds = dataset(t, vx)
    result = observe(ds, ObservableSettings(transient=1000.0))
    assert result.phi == pytest.approx(0.045, rel=0.05)  # <(0.3 sin)^2> = 0.045
    assert result.regime == SLIDING and not result.stick_slip
    assert result.slip_events == 0 and math.isnan(result.stick_time_mean)
    assert result.drift_velocity == pytest.approx(V_D, rel=1e-3)


def test_slip_statistics_ignore_the_ringing_after_each_slip():
    t, vx, onsets = stick_slip_signal(cycles=6, ringing=30 * V_D)  # ringing swings above the onset velocity
    ds = dataset(t, vx)
    assert vx[(t > onsets[0] + SLIP_TIME + 20) & (t < onsets[0] + SLIP_TIME + 60)].max() > 10 * V_D
    result = observe(ds, ObservableSettings(transient=0.0))
    assert result.slip_events == 6
    assert result.slip_length_mean == pytest.approx(SLIP_LENGTH, rel=2e-3)
    assert result.slip_interval_mean == pytest.approx(PERIOD, abs=2 * DT)
    # A slip lasts while vx > V_d (the release velocity): a little less than SLIP_TIME.
    peak = math.pi * SLIP_LENGTH / (2 * SLIP_TIME)
    above_release = SLIP_TIME - 2 * SLIP_TIME / math.pi * math.asin(V_D / peak)
    assert result.stick_time_mean == pytest.approx(PERIOD - above_release, abs=2 * DT)
    assert result.regime == STICK_SLIP
    # Without the length criterion every ringing lobe above the onset would count.
    raw = slip_events(t, ds.x.values, vx, 10 * V_D, V_D, min_length=0.0)
    assert raw.count > 6


def test_a_slip_cut_by_the_window_start_is_not_counted():
    t, vx, onsets = stick_slip_signal(cycles=5)
    ds = dataset(t, vx)
    settings = ObservableSettings(transient=onsets[1] + SLIP_TIME / 2)  # window opens mid-slip
    result = observe(ds, settings)
    assert result.slip_events == 3
    assert result.window_start == pytest.approx(onsets[1] + SLIP_TIME / 2)
    assert result.transient == settings.transient and result.phi_threshold == settings.phi_threshold


def test_merge_gap_joins_a_slip_interrupted_by_a_short_pause():
    t = np.arange(0.0, 1000.0, DT)
    vx = np.zeros_like(t)
    for start in (400.0, 433.0):  # two halves of 30 time units, 3 apart
        inside = (t >= start) & (t <= start + 30.0)
        vx[inside] = 0.2 * np.sin(math.pi * (t[inside] - start) / 30.0)
    # vx stays below the release velocity V_d for 3 + 2 (30/pi) asin(0.05) ~ 4 time units.
    x = cumulative(t, vx)
    half = x[-1] / 2
    apart = slip_events(t, x, vx, 10 * V_D, V_D, min_length=1.5 * half)
    joined = slip_events(t, x, vx, 10 * V_D, V_D, min_length=1.5 * half, merge_gap=8.0)
    assert apart.count == 0
    assert joined.count == 1 and joined.length[0] == pytest.approx(2 * half, rel=1e-3)


def test_contact_fraction_drift_and_classification():
    t = np.arange(0.0, 1001.0, 1.0)
    contact = (np.arange(t.size) % 4) == 0  # one sample in four
    ds = dataset(t, np.full_like(t, 2 * V_D), contact=contact)
    win = window(ds, 1.0)
    assert contact_fraction(ds, win) == pytest.approx(0.25, abs=2e-3)
    assert drift_velocity(ds, win) == pytest.approx(2 * V_D)
    assert classify(10.5, 10.0) == STICK_SLIP and classify(9.5, 10.0, 0.9 * V_D, V_D) == SLIDING
    # Large phi without rests: hopping when mostly in the air, else by the drift.
    assert classify(50.0, 10.0, V_D, V_D, rests=0.0, contact=0.1) == HOPPING
    assert classify(50.0, 10.0, V_D, V_D, rests=0.5, contact=0.1) == STICK_SLIP  # sticks between bounces
    assert classify(50.0, 10.0, V_D, V_D, rests=0.0, contact=0.9) == STICK_SLIP
    assert classify(1.0, 10.0, 0.01 * V_D, V_D) == STUCK


def test_a_window_without_slips_and_without_drift_is_jammed_only_where_friction_can_self_lock():
    """The drive spring's stretch reaches 0.97 V_d 3000 = 29.1 at the end of the window,
    beyond the flat plate's slip length mu_s m g / k_d = 20.  Jammed only on a flank
    rising along the pull with tan(alpha) >= 1/mu_s = 2 and a tangential spring; stuck
    on a flat plate, on a gentler or a falling flank, with k_t = 0 (nothing can self-lock:
    e.g. Eq. (9)'s stable rest), and below the slip length."""
    t = np.arange(0.0, 3000.0, 1.0)
    creeping = np.full_like(t, 0.03 * V_D)
    settings = ObservableSettings(transient=100.0)
    x_end = cumulative(t, creeping)[-1]

    def regime(tan_alpha=None, **attrs):
        if tan_alpha is not None:  # a corrugation whose slope under the block's last position is tan_alpha
            omega_x = 1.0
            attrs.update(omega_x=omega_x, A_x=tan_alpha / (omega_x * math.cos(omega_x * x_end)))
        return observe(dataset(t, creeping, **{"k_d": 0.5 / 20.0, "k_t": 0.28, **attrs}), settings)

    flank = regime(3.0)
    assert flank.phi == pytest.approx(0.97**2) and flank.regime == JAMMED and not flank.stick_slip
    assert regime(2.0).regime == JAMMED  # tan(alpha) = 1/mu_s: the bound grows as fast as the pull
    assert regime(1.5).regime == STUCK
    assert regime(-3.0).regime == STUCK  # a pull down the flank
    assert regime(3.0, k_t=0.0).regime == STUCK
    assert regime().regime == STUCK  # a flat plate
    assert regime(3.0, k_d=0.5 / 40.0).regime == STUCK  # slip length 40 > 29.1
    # Confined by P_l (model C) instead of m g: the same rule with N0 = P_l.
    assert regime(3.0, P_l=2.0).regime == STUCK


def test_a_block_that_never_touches_the_plate_is_flying_whatever_its_phi():
    t, vx, _ = stick_slip_signal()
    in_contact = observe(dataset(t, vx, contact=np.ones_like(t, dtype=bool)), ObservableSettings(transient=0.0))
    airborne = observe(dataset(t, vx, contact=np.zeros_like(t, dtype=bool)), ObservableSettings(transient=0.0))
    assert in_contact.regime == STICK_SLIP and airborne.regime == FLYING


def test_a_hopping_block_is_not_stick_slip_however_large_its_phi():
    """Crest-to-crest hops: fast flights (vx swinging from 0 to 8 V_d every 31.4, the
    mean following the drive), a landing 3 % of the time, never at rest over a hop."""
    t = np.arange(0.0, 3000.0, 0.05)
    hop = 31.4
    phase = (t % hop) / hop
    vx = V_D * (1.0 + 7.0 * np.sin(2 * math.pi * phase))
    landed = phase > 0.97
    ds = dataset(t, vx, contact=landed)
    observed = observe(ds, ObservableSettings(transient=100.0))
    assert observed.phi > 10.0  # the paper's order parameter alone would call it stick-slip
    assert observed.regime == HOPPING and not observed.stick_slip
    assert observed.rest_fraction < 0.1 and observed.contact_fraction == pytest.approx(0.03, abs=0.005)
    # The same motion in contact half the time or more is held by friction by phi; as it
    # never rests and no slip of the counted size completes, it is micro-slip.
    held = observe(dataset(t, vx, contact=phase > 0.4), ObservableSettings(transient=100.0))
    assert held.regime == MICRO_SLIP and held.stick_slip and held.slip_events == 0


def test_a_block_mostly_in_contact_is_judged_by_phi_whatever_its_rests():
    """Held with the tangential spring ringing through the stick (vx swinging by 5 V_d
    while the block creeps at 3 % of V_d): never at rest by |vx|, yet in contact, so phi
    decides, as in the paper (the module doc says why)."""
    t = np.arange(0.0, 3000.0, 0.05)
    vx = 0.03 * V_D + 5.0 * V_D * np.cos(0.53 * t)
    ringing = observe(dataset(t, vx, contact=np.ones_like(t, dtype=bool)), ObservableSettings(transient=100.0))
    assert ringing.phi > 10.0 and ringing.rest_fraction < 0.1 and ringing.regime == STICK_SLIP


def test_a_block_sliding_with_a_short_slip_every_plate_period_is_micro_slip_not_stick_slip():
    """Below the onset, near the contact resonance (model A, A = 0.5, omega = 0.8, scaled
    drive: phi ~ 21, rest fraction 0.008, drift V_d): the Coulomb bound dips at each
    trough of N and the block slips a little every plate period, never resting.  phi is
    above the threshold, but no slip of the counted size happens: the regime says
    micro_slip beside slip_events = 0, not stick_slip."""
    omega, t = 0.8, np.arange(0.0, 4000.0, 0.25)
    vx = V_D * (1.0 + 5.0 * np.sin(omega * t))  # phi = 12.5
    observed = observe(dataset(t, vx, contact=np.ones_like(t, dtype=bool)), ObservableSettings(transient=400.0))
    assert observed.phi > 10.0 and observed.rest_fraction < 0.1
    assert observed.drift_velocity == pytest.approx(V_D, rel=0.02)
    assert observed.slip_events == 0 and observed.regime == MICRO_SLIP and observed.stick_slip
    # With slips of the counted size in the window the same phi is stick-slip.
    t, vx, _ = stick_slip_signal()
    assert observe(dataset(t, vx, contact=np.ones_like(t, dtype=bool)),
                   ObservableSettings(transient=0.0)).regime == STICK_SLIP


def test_stick_slip_locked_to_the_plate_period_is_stick_slip():
    """Below the onset the Coulomb bound dips at each trough of N: the block sticks for
    most of each plate period (omega = 0.1) and slips the rest, keeping up with the
    drive on average.  It rests, so it is stick-slip, as phi says (not sliding)."""
    omega, t = 0.1, np.arange(0.0, 6000.0, 0.1)
    phase = (omega * t / (2 * math.pi)) % 1.0
    period = 2 * math.pi / omega
    burst = 0.1  # share of the period spent slipping
    vx = np.where(phase < burst, V_D / burst * (1 - np.cos(2 * math.pi * phase / burst)), 0.0)
    locked = observe(dataset(t, vx, contact=np.ones_like(t, dtype=bool)), ObservableSettings(transient=period))
    assert locked.drift_velocity == pytest.approx(V_D, rel=0.02) and locked.phi > 10.0
    assert locked.rest_fraction > 0.7 and locked.regime == STICK_SLIP


def test_a_window_without_two_samples_is_refused():
    t = np.arange(0.0, 10.0, 1.0)
    ds = dataset(t, np.zeros_like(t))
    with pytest.raises(ValueError, match="fewer than two samples"):
        window(ds, transient=9.5)


def test_slope_angles_at_the_stick_sites_of_a_corrugated_plate():
    # Stuck at x = 10 on the paper's corrugation (A_x omega_x = 20) for the first half,
    # then sliding at 2 V_d: the stick site's slope is arctan(20 cos(0.2)) = 87.1 degrees.
    t = np.arange(0.0, 2000.0, 1.0)
    vx = np.where(t < 1000.0, 0.0, 2 * V_D)
    ds = dataset(t, vx, A_x=1e3, omega_x=2e-2)
    ds["x"] = ds["x"] + 10.0
    win = window(ds, 0.0)
    end, at_rest = slope_angles(ds, win)
    assert at_rest == pytest.approx(math.degrees(math.atan(20.0 * math.cos(0.2))), rel=1e-12)
    x_end = float(ds["x"].values[-1])
    assert end == pytest.approx(math.degrees(math.atan(20.0 * math.cos(0.02 * x_end))), rel=1e-12)
    flat = dataset(t, vx)
    assert all(math.isnan(a) for a in slope_angles(flat, window(flat, 0.0)))
