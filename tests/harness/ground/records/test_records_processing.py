"""Processing: integration consistency, drift removal, scaling, dataset output."""

from __future__ import annotations

import numpy as np
import pytest

from harness.ground.records import (
    STANDARD_GRAVITY,
    ProcessingSettings,
    Record,
    RecordError,
    integrate_linear_acceleration,
    process_record,
    scale_to_peak_acceleration,
)


def _record_window(motion):
    """Slice of the output that covers the original record."""
    i0 = int(round(motion.record_offset / motion.dt))
    return i0


def _rel(err, ref):
    return float(np.max(np.abs(err)) / np.max(np.abs(ref)))


def test_integration_scheme_is_exact_for_piecewise_linear_acceleration():
    # a = t (linear) -> v = t²/2, z = t³/6 exactly, whatever the step
    dt = 0.37
    t = np.arange(50) * dt
    v, z = integrate_linear_acceleration(t, dt, v0=1.0, z0=2.0)
    np.testing.assert_allclose(v, 1.0 + t**2 / 2, rtol=1e-13)
    np.testing.assert_allclose(z, 2.0 + t + t**3 / 6, rtol=1e-13)


@pytest.mark.parametrize("quantity", ["acceleration", "velocity", "displacement"])
def test_windowed_sinusoid_matches_analytic_integrals(analytic, quantity):
    """Any input quantity gives a, v, z equal to the analytic ones.

    The tolerance is set by sampling: integrating the piecewise-linear
    acceleration of a sinusoid sampled at ω·dt has a relative amplitude error
    (ω dt)²/12 (3.3e-4 here); the 0.1 Hz high-pass and the baseline fit add
    < 1e-4 for a 2 Hz signal.
    """
    data = {"acceleration": analytic.a, "velocity": analytic.v,
            "displacement": analytic.z}[quantity]
    rec = Record(data=data, dt=analytic.dt, quantity=quantity, source="analytic")
    m = process_record(rec)
    i0 = _record_window(m)
    sl = slice(i0, i0 + analytic.t.size)
    sampling_error = (analytic.omega * analytic.dt) ** 2 / 12
    tol = sampling_error + 2e-4
    assert _rel(m.acceleration[sl] - analytic.a, analytic.a) < 2e-4
    assert _rel(m.velocity[sl] - analytic.v, analytic.v) < tol
    assert _rel(m.displacement[sl] - analytic.z, analytic.z) < tol
    # the padding before the record stays (nearly) at rest
    assert np.max(np.abs(m.displacement[:i0])) < 1e-4 * np.max(np.abs(analytic.z))


def assert_exactly_consistent(m):
    """The discrete relations of the integration scheme hold to rounding."""
    dt = m.dt
    dv = np.diff(m.velocity)
    np.testing.assert_allclose(dv, 0.5 * dt * (m.acceleration[:-1] + m.acceleration[1:]),
                               rtol=0, atol=1e-12 * m.peak_velocity)
    dz = np.diff(m.displacement)
    np.testing.assert_allclose(
        dz, dt * m.velocity[:-1] + dt**2 * (2 * m.acceleration[:-1] + m.acceleration[1:]) / 6,
        rtol=0, atol=1e-12 * m.peak_displacement)


def test_outputs_are_kinematically_consistent(analytic):
    m = process_record(Record(data=analytic.a, dt=analytic.dt, quantity="acceleration"))
    dt = m.dt
    assert_exactly_consistent(m)
    # and numerically: v = dz/dt, a = dv/dt (central differences, error (ω dt)²/6 = 6.6e-4)
    assert _rel(np.gradient(m.displacement, dt) - m.velocity, m.velocity) < 2e-3
    assert _rel(np.gradient(m.velocity, dt) - m.acceleration, m.acceleration) < 2e-3
    # starts and ends at rest
    assert m.velocity[0] == 0.0 and m.displacement[0] == 0.0
    assert abs(m.displacement[-1]) < 1e-12 * m.peak_displacement
    assert abs(m.velocity[-1]) < 1e-12 * m.peak_velocity


def test_dc_offset_in_acceleration_does_not_drift(make_analytic):
    ref = make_analytic()
    offset = 0.02  # m/s², about 13 % of the peak acceleration
    acc = ref.a + offset
    duration = ref.t[-1]
    # naive double integration drifts by offset·T²/2 = 4 m, 4000x the true peak
    _, z_naive = integrate_linear_acceleration(acc, ref.dt)
    assert abs(z_naive[-1]) > 1000 * np.max(np.abs(ref.z))

    m = process_record(Record(data=acc, dt=ref.dt, quantity="acceleration"))
    i0 = _record_window(m)
    sl = slice(i0, i0 + ref.t.size)
    peak = np.max(np.abs(ref.z))
    slope = np.polyfit(m.time[sl], m.displacement[sl], 1)[0]
    assert abs(slope * duration) < 1e-3 * peak  # no linear trend
    assert abs(m.displacement[sl][-1]) < 1e-3 * peak  # record ends at rest
    assert abs(m.displacement[-1]) < 1e-12 * peak  # window ends exactly at rest
    assert _rel(m.displacement[sl] - ref.z, ref.z) < 1e-2


def test_baseline_correction_removes_end_offset_of_a_baseline_shift(make_analytic):
    """A step in the acceleration zero level (a typical instrument artefact)."""
    ref = make_analytic()
    acc = ref.a + 0.02 + np.where(ref.t > 12.0, 0.005, 0.0)
    rec = Record(data=acc, dt=ref.dt, quantity="acceleration")
    peak = np.max(np.abs(ref.z))
    raw = process_record(rec, ProcessingSettings(freqmin=0.3, baseline_order=None))
    fixed = process_record(rec, ProcessingSettings(freqmin=0.3, baseline_order=5))
    assert abs(raw.displacement[-1]) > 1e-3 * peak  # without the fit the end is off
    assert abs(fixed.displacement[-1]) < 1e-12 * peak
    assert abs(fixed.velocity[-1]) < 1e-12 * fixed.peak_velocity
    # the correction is large here (the end was off), and still consistent
    assert np.max(np.abs(fixed.displacement - raw.displacement)) > 1e-3 * peak
    assert_exactly_consistent(fixed)
    i0 = _record_window(fixed)
    sl = slice(i0, i0 + ref.t.size)
    slope = np.polyfit(fixed.time[sl], fixed.displacement[sl], 1)[0]
    assert abs(slope * ref.t[-1]) < 0.02 * peak


def test_trim_padding_returns_the_record_span(analytic):
    m = process_record(Record(data=analytic.a, dt=analytic.dt, quantity="acceleration"),
                       ProcessingSettings(trim_padding=True))
    assert m.time.size == analytic.t.size
    assert m.record_offset == 0.0
    assert _rel(m.displacement - analytic.z, analytic.z) < 2e-3


def test_default_settings_are_resolved_and_recorded(analytic):
    m = process_record(Record(data=analytic.a, dt=analytic.dt, quantity="acceleration"))
    assert m.settings.freqmax == pytest.approx(0.4 / analytic.dt)
    assert m.settings.pad_seconds == pytest.approx(0.75 * 4 / 0.1)
    assert m.record_offset == pytest.approx(30.0)
    ds = m.to_dataset()
    assert set(ds.data_vars) == {"acceleration", "velocity", "displacement"}
    assert ds["acceleration"].attrs["units"] == "m/s^2"
    assert ds.attrs["processing_freqmin"] == 0.1
    assert ds.attrs["processing_corners"] == 4
    assert "band-pass" in ds.attrs["history"]
    np.testing.assert_array_equal(ds["displacement"].values, m.displacement)


def test_dataset_writes_to_netcdf(analytic, tmp_path):
    xr = pytest.importorskip("xarray")
    m = process_record(Record(data=analytic.a, dt=analytic.dt, quantity="acceleration"))
    path = tmp_path / "motion.nc"
    m.to_dataset().to_netcdf(path, engine="scipy")  # NetCDF3: ASCII attributes only
    back = xr.load_dataset(path, engine="scipy")
    np.testing.assert_allclose(back["velocity"].values, m.velocity)
    assert back.attrs["processing_baseline_order"] == 5


def test_scale_to_peak_acceleration_keeps_consistency(analytic):
    m = process_record(Record(data=analytic.a, dt=analytic.dt, quantity="acceleration"))
    s = scale_to_peak_acceleration(m, 0.3)
    assert s.peak_acceleration == pytest.approx(0.3 * STANDARD_GRAVITY, rel=1e-12)
    factor = s.peak_acceleration / m.peak_acceleration
    np.testing.assert_allclose(s.velocity, factor * m.velocity)
    np.testing.assert_allclose(s.displacement, factor * m.displacement)
    s2 = scale_to_peak_acceleration(m, 1.0, gravity=9.81)
    assert s2.peak_acceleration == pytest.approx(9.81, rel=1e-12)
    with pytest.raises(RecordError, match="positive"):
        scale_to_peak_acceleration(m, -1.0)


def test_results_are_immutable(analytic):
    m = process_record(Record(data=analytic.a, dt=analytic.dt, quantity="acceleration"))
    with pytest.raises(ValueError):
        m.acceleration[0] = 1.0
    with pytest.raises(AttributeError):
        m.settings.freqmin = 1.0  # type: ignore[misc]


def test_too_short_record_for_the_high_pass(analytic):
    rec = Record(data=analytic.a[:600], dt=analytic.dt, quantity="acceleration")  # 3 s
    with pytest.raises(RecordError, match=r"shorter than one period.*1/freqmin = 10 s"):
        process_record(rec, ProcessingSettings(freqmin=0.1))
    process_record(rec, ProcessingSettings(freqmin=0.5))  # 2 s period fits


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(freqmin=0.0), "freqmin"),
        (dict(freqmin=1.0, freqmax=0.5), "freqmax"),
        (dict(corners=0), "corners"),
        (dict(taper_fraction=0.7), "taper_fraction"),
        (dict(detrend="spline"), "detrend"),
        (dict(baseline_order=2), "baseline_order"),
    ],
)
def test_invalid_settings_are_refused(kwargs, message):
    with pytest.raises(RecordError, match=message):
        ProcessingSettings(**kwargs)


def test_a_long_period_record_below_the_default_high_pass_says_which_corner_to_move(analytic):
    """A record sampled at 1 Hz has its default low-pass corner at 0.4 Hz, below the
    default high-pass corner 0.5 Hz of the record tools: one line naming both and the fix."""
    rec = Record(data=analytic.a[::200], dt=1.0, quantity="acceleration")
    with pytest.raises(RecordError, match=r"freqmin=0.5 Hz is not below .* freqmax=0.4 Hz .* 1 Hz\); "
                                          r"lower freqmin \(--freqmin\), e.g. to 0.04 Hz") as refused:
        process_record(rec, ProcessingSettings(freqmin=0.5))
    assert "\n" not in str(refused.value)


def test_freqmax_above_nyquist_is_refused(analytic):
    rec = Record(data=analytic.a, dt=analytic.dt, quantity="acceleration")
    with pytest.raises(RecordError, match="Nyquist"):
        process_record(rec, ProcessingSettings(freqmax=150.0))
