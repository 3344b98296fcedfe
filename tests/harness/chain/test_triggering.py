"""Triggered events in the chain (``harness.chain.triggering``)."""
import math

import pytest

import numpy as np

from harness.chain.triggering import (Burst, Chirp, Harmonic, RecordSignal, TriggerSettings, burst, clock_advance,
                                      periodic_advance, reference_cycle, signal_advance)


@pytest.fixture(scope="module")
def reference():
    return reference_cycle(TriggerSettings())


def test_the_burst_is_consistent_and_starts_and_ends_at_rest():
    """Velocity and acceleration are the derivatives of the height (central differences),
    and the taper brings all three to zero at both ends."""
    amplitude, period, cycles, h = 0.3, 7.0, 3, 1e-5
    for tau in (0.4, 5.0, 13.3):
        z, v, a = burst(amplitude, period, cycles, tau)
        assert v == pytest.approx((burst(amplitude, period, cycles, tau + h)[0]
                                   - burst(amplitude, period, cycles, tau - h)[0]) / (2 * h), rel=1e-6)
        assert a == pytest.approx((burst(amplitude, period, cycles, tau + h)[1]
                                   - burst(amplitude, period, cycles, tau - h)[1]) / (2 * h), rel=1e-6)
    for tau in (0.0, cycles * period):
        assert all(abs(value) < 1e-12 for value in burst(amplitude, period, cycles, tau))


def test_a_burst_of_no_amplitude_changes_nothing(reference):
    """Restored from a snapshot and run on with a still plate: the reference event, to the
    last bit of its start time."""
    row = clock_advance(reference, TriggerSettings(), 0.5, 20.0, 0.0)
    assert row["advance"] == 0.0 and not row["triggered"]
    assert row["T0"] == pytest.approx(0.5 * reference.cycle)


def test_a_strong_short_burst_triggers_the_event_during_the_burst(reference):
    """A burst whose acceleration lowers the normal force by half a g each period: the
    Coulomb bound drops below the held load long before the event was due."""
    settings = TriggerSettings()
    row = clock_advance(reference, settings, 0.7, 10.0, 0.5)
    assert row["triggered"] and 0.0 < row["advance"] <= row["T0"]
    assert row["t_event"] <= reference.t_s + 0.7 * reference.cycle + settings.cycles * 10.0
    assert math.isfinite(row["t_event"])


def _derivatives_agree(signal, taus, scale, h=1e-5, rel=1e-6):
    """Velocity and acceleration are the derivatives of the height (central differences),
    to ``rel`` or to 1e-9 of the signal's acceleration ``scale`` near a zero."""
    for tau in taus:
        z, v, a = signal(tau)
        (z_minus, v_minus, _), (z_plus, v_plus, _) = signal(tau - h), signal(tau + h)
        assert v == pytest.approx((z_plus - z_minus) / (2 * h), rel=rel, abs=1e-9 * scale)
        assert a == pytest.approx((v_plus - v_minus) / (2 * h), rel=rel, abs=1e-9 * scale)


@pytest.mark.parametrize("sweep", ["linear", "log"])
def test_the_chirp_is_consistent_and_its_ends_are_the_taper_s(sweep):
    """Height and velocity vanish at both ends; the Hann taper's curvature 2 (pi/D)^2
    leaves an acceleration a P^2 sin(phi) / (2 D^2) there: 0 at the start, and at the end
    (phi(D) of the closed form) under 1e-3 a for these periods."""
    a, duration = 0.3, 200.0
    chirp = Chirp(a, 40.0, 8.0, duration, sweep)
    _derivatives_agree(chirp, (0.7, 31.0, 99.9, 150.2, 199.0), a)
    for tau, period in ((0.0, 40.0), (duration, 8.0)):
        z, v, acceleration = chirp(tau)
        assert abs(z) < 1e-12 and abs(v) < 1e-12
        expected = a * period ** 2 * math.sin(chirp.phase(tau)) / (2.0 * duration ** 2)
        assert acceleration == pytest.approx(expected, rel=1e-9, abs=1e-15)


@pytest.mark.parametrize("sweep", ["linear", "log"])
def test_the_chirp_s_zero_crossings_are_where_its_closed_form_phase_is_a_multiple_of_pi(sweep):
    """phi(tau) = k pi, inverted in closed form: linear, tau_k = (-w0 + sqrt(w0^2 + 2 c k pi)) / c;
    log, tau_k = ln(1 + r k pi / w0) / r.  The crossings of the height, found by bisection,
    are there; and the acceleration's envelope in mid-sweep is the amplitude a."""
    period_start, period_end, duration, a = 40.0, 8.0, 200.0, 0.3
    chirp = Chirp(a, period_start, period_end, duration, sweep)
    w0, w1 = 2 * math.pi / period_start, 2 * math.pi / period_end
    if sweep == "linear":
        c = (w1 - w0) / duration
        closed = lambda k: (-w0 + math.sqrt(w0 * w0 + 2 * c * k * math.pi)) / c  # noqa: E731
    else:
        r = math.log(w1 / w0) / duration
        closed = lambda k: math.log(1 + r * k * math.pi / w0) / r  # noqa: E731
    crossings = 0
    for k in range(1, 200):
        tau_k = closed(k)
        if tau_k >= duration - 1.0:
            break
        lo, hi = tau_k - 0.3, tau_k + 0.3  # (half a crossing's spacing at the shortest period is 2)
        assert chirp(lo)[0] * chirp(hi)[0] < 0.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if chirp(lo)[0] * chirp(mid)[0] <= 0.0 else (mid, hi)
        assert 0.5 * (lo + hi) == pytest.approx(tau_k, abs=1e-9)
        crossings += 1
    assert crossings > 20
    taus = np.linspace(0.45 * duration, 0.55 * duration, 20001)
    peak = max(abs(chirp(t)[2]) for t in taus)
    assert peak == pytest.approx(a, rel=0.05)  # (the taper is ~1 there; the slow terms are small)


def test_the_record_is_consistent_and_peaks_at_the_requested_acceleration():
    """obspy's example event through the Excitation FMU's playback: velocity and
    acceleration are the derivatives of the height between samples, and the peak
    acceleration (at a sample: the acceleration is linear between them) is the one asked for."""
    record = RecordSignal(0.4, time_scale=200.0)
    sample = record.step * 2.0  # (the step is half a sample)
    _derivatives_agree(record, [sample * (k + 0.37) for k in (5, 400, 600, 750)], 0.4, h=1e-4, rel=1e-5)
    samples = np.arange(0.0, record.duration, sample)
    assert max(abs(record(t)[2]) for t in samples) == pytest.approx(0.4, rel=1e-9)
    assert record.duration == pytest.approx(200.0 * 10.0, rel=1e-3)  # 8 s of record and a pad of 1 s each side


@pytest.mark.parametrize("signal", [lambda: Chirp(0.0, 60.0, 10.0, 300.0, "log"),
                                    lambda: RecordSignal(0.0, time_scale=50.0)], ids=["chirp", "record"])
def test_a_chirp_or_record_of_no_amplitude_changes_nothing(reference, signal):
    """The plate given zeros: the reference event, to the last bit of its start time."""
    row = signal_advance(reference, TriggerSettings(), 0.5, signal())
    assert row["advance"] == 0.0 and row["t_event"] == reference.t_ref and not row["triggered"]


def test_a_burst_through_the_general_signal_is_the_burst(reference):
    settings = TriggerSettings()
    row = clock_advance(reference, settings, 0.6, 10.0, 0.2)
    general = signal_advance(reference, settings, 0.6, Burst(0.2, 10.0, settings.cycles, settings.steps_per_period))
    assert general["t_event"] == row["t_event"] and row["triggered"] == general["triggered"]


def test_a_strong_chirp_through_the_contact_s_band_triggers_the_event(reference):
    """A sweep from P = 100 to 10 at 0.5 g: its acceleration lowers the normal force by half
    a g each period, as the strong burst above does."""
    chirp = Chirp(0.5, 100.0, 10.0, 200.0, "log")
    row = signal_advance(reference, TriggerSettings(), 0.7, chirp)
    assert row["triggered"] and 0.0 < row["advance"] <= row["T0"]


def test_periodic_loading_starts_at_rest_and_its_acceleration_is_a_sine():
    """The plate's acceleration is exactly a sin(2 pi tau / P); height and velocity are its
    integrals from rest (central differences), and after the duration the plate goes on
    uniformly at its last velocity."""
    a, period, duration = 0.02, 300.0, 1000.0
    harmonic = Harmonic(a, period, duration)
    assert harmonic(0.0) == (0.0, 0.0, 0.0)
    _derivatives_agree(harmonic, (0.3, 77.0, 510.5, 999.0), a, h=1e-4, rel=1e-6)
    for tau in (13.0, 290.0, 640.0):
        assert harmonic(tau)[2] == pytest.approx(a * math.sin(2 * math.pi * tau / period), rel=1e-12)
    z_end, v_end, _ = harmonic(duration)
    assert harmonic(duration + 10.0) == pytest.approx((z_end + 10.0 * v_end, v_end, 0.0), rel=1e-12)


def test_periodic_loading_of_no_amplitude_changes_nothing(reference):
    row = periodic_advance(reference, TriggerSettings(), 0.4, 50.0, 0.0)
    assert row["advance"] == 0.0 and row["t_event"] == reference.t_ref and row["smaller_events"] == 0


def test_a_slow_bursts_normal_force_dip_is_the_plates_downward_acceleration():
    """A burst far slower than the contact (P = 2000 against 2 pi sqrt(m/k_n) = 6.3): the
    block follows the plate, so m times the plate's acceleration is all the normal force
    changes by (to the contact's lag, (2 pi/P)^2 m/k_n ~ 1e-5)."""
    from harness.chain.triggering import normal_force_dip

    signal = Burst(1.0, 2000.0, 3, 64)
    taus, dips = normal_force_dip(signal, {"m": 1.0, "k_n": 1.0, "gamma_n": 0.07}, 25.0)
    plate = np.array([signal(tau)[2] for tau in taus])
    assert np.max(np.abs(dips + plate)) < 1e-3 * np.max(np.abs(plate))


@pytest.mark.parametrize("phase, period", [(0.9, 7.84), (0.6, 19.51), (0.9, 30.76)])
def test_the_trigger_threshold_is_the_first_blocks_static_one(reference, phase, period):
    """The bisected threshold of a burst brackets the static prediction for the first block:
    the acceleration at which the contact's dip lowers its Coulomb bound below the load its
    spring holds (to 3 %: the bracket's 2 % and the sampling).  Half the chain's static
    threshold is several times higher: one block's slip sets off the large event."""
    from harness.chain.triggering import predicted_threshold, trigger_threshold

    settings = TriggerSettings()
    bracket = trigger_threshold(reference, settings, phase, period)
    assert not clock_advance(reference, settings, phase, period, bracket["below"])["triggered"]
    assert clock_advance(reference, settings, phase, period, bracket["above"])["triggered"]
    assert bracket["above"] / bracket["below"] <= 1.02
    predicted = predicted_threshold(reference, settings, phase, period)
    assert bracket["below"] / 1.03 <= predicted["first_block"] <= bracket["above"] * 1.03
    assert predicted["half_chain"] > 2.5 * predicted["first_block"]
