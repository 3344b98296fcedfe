"""The plate-motion core (vibroblock.excitation): analytic values, kinematic consistency
of every mode, record files, scaling, and state."""
from __future__ import annotations

import math

import numpy as np
import pytest

from vibroblock.excitation import (BUNDLED_RECORD, HARMONIC_SUM, LINEAR_CHIRP, LOG_CHIRP, PLAYBACK, Chirp,
                                   Excitation, ExcitationError, Playback, envelope, integrate, load_record)

# One setting per mode, stretched, scaled, shifted and (mostly) ramped, so that every
# term of the chain rule is exercised.
MODE_CASES = {
    "harmonic": dict(mode=0, amplitude=1.5, omega=0.7, phase=0.3, time_scale=1.7, amplitude_scale=0.8, onset=2.0),
    "linear_chirp": dict(mode=1, amplitude=2.0, omega_start=0.1, omega_end=1.2, sweep_time=30.0, phase=-0.4,
                         time_scale=0.9, amplitude_scale=1.3, onset=1.0, ramp_time=5.0),
    "log_chirp": dict(mode=2, amplitude=0.5, omega_start=0.05, omega_end=2.0, sweep_time=40.0, phase=1.0,
                      onset=3.0, ramp_time=8.0),
    "harmonic_sum": dict(mode=3, amplitude_1=1.0, omega_1=0.3, phase_1=0.1, amplitude_2=-0.4, omega_2=1.1,
                         amplitude_4=0.2, omega_4=2.5, phase_4=2.0, time_scale=1.2, ramp_time=4.0),
    "playback": dict(mode=4, amplitude_scale=2.0e6, time_scale=3.0, onset=5.0, ramp_time=0.0),
}


def started(**settings) -> Excitation:
    excitation = Excitation(**settings)
    excitation.start()
    return excitation


def test_harmonic_equals_its_closed_form():
    plate = started(mode=0, amplitude=1.5, omega=0.7, phase=0.3, amplitude_scale=2.0, time_scale=4.0, onset=1.0)
    t = np.linspace(-5.0, 50.0, 301)
    s = (t - 1.0) / 4.0
    z, v, a = plate.evaluate(t)
    np.testing.assert_allclose(z, 3.0 * np.sin(0.7 * s + 0.3), rtol=0, atol=1e-14)
    np.testing.assert_allclose(v, 3.0 * 0.7 / 4.0 * np.cos(0.7 * s + 0.3), rtol=0, atol=1e-14)
    np.testing.assert_allclose(a, -3.0 * 0.49 / 16.0 * np.sin(0.7 * s + 0.3), rtol=0, atol=1e-14)
    # a scalar time gives floats, the same values
    assert plate.evaluate(float(t[7])) == (z[7], v[7], a[7])


@pytest.mark.parametrize("case", sorted(MODE_CASES))
def test_velocity_and_acceleration_are_the_derivatives(case):
    """Central differences of z and v converge to v and a at second order (playback:
    between samples, where its pieces are polynomials, the differences are exact up to
    the cubic term of z)."""
    plate = started(**MODE_CASES[case])
    if case == "playback":
        p = plate.parameters
        t = p["onset"] + p["time_scale"] * plate.record.dt * (np.arange(200, 3200, 7) + 0.5)
        steps = (1e-2, 5e-3)  # within a sample interval (0.03 here)
    else:
        t = np.linspace(0.3, 120.0, 997) + 0.0123  # off the chirps' kinks
        steps = (1e-2, 5e-3)
    z, v, a = plate.evaluate(t)
    assert np.max(np.abs(z)) > 1e-3 and np.max(np.abs(a)) > 1e-3
    errors = []
    for h in steps:
        zp, vp, _ = plate.evaluate(t + h)
        zm, vm, _ = plate.evaluate(t - h)
        dz, dv = (zp - zm) / (2 * h), (vp - vm) / (2 * h)
        errors.append((np.max(np.abs(dz - v)) / np.max(np.abs(v)), np.max(np.abs(dv - a)) / np.max(np.abs(a))))
    (ez, ev), (fz, fv) = errors
    assert fz < 1e-2 and fv < 1e-4, (case, fz, fv)  # z: the cubic term h^2 j/6 of steep records
    assert fz < ez / 3 or fz < 1e-10, (case, ez, fz)  # second order: 4x per halving
    assert fv < ev / 3 or fv < 1e-10, (case, ev, fv)


@pytest.mark.parametrize("logarithmic", [False, True])
def test_chirp_sweeps_the_frequency_from_start_to_end(logarithmic):
    chirp = Chirp(1.0, 0.2, 1.8, 50.0, 0.0, logarithmic)
    theta, rate, curvature = chirp.phase_rate(np.array([-10.0, 0.0, 25.0, 50.0, 80.0]))
    middle = math.sqrt(0.2 * 1.8) if logarithmic else 1.0
    np.testing.assert_allclose(rate, [0.2, 0.2, middle, 1.8, 1.8], rtol=1e-12)
    # constant frequency before and after the sweep, phase continuous
    assert theta[0] == pytest.approx(-2.0) and theta[1] == 0.0
    assert theta[4] == pytest.approx(theta[3] + 1.8 * 30.0, rel=1e-12)
    assert curvature[0] == 0.0 and curvature[4] == 0.0 and curvature[2] > 0.0
    # the phase is the integral of the rate
    s = np.linspace(0.0, 50.0, 20001)
    _, r, _ = chirp.phase_rate(s)
    assert chirp.phase_rate(50.0)[0] == pytest.approx(np.trapezoid(r, s), rel=1e-7)


def test_ramp_starts_the_plate_at_rest_without_jumps():
    w, dw, d2w = envelope(np.array([-1.0, 0.0, 0.5, 1.0, 2.0]))
    np.testing.assert_allclose(w, [0, 0, 0.5, 1, 1])
    np.testing.assert_allclose(dw[[0, 1, 3, 4]], 0.0)
    np.testing.assert_allclose(d2w[[0, 1, 3, 4]], 0.0, atol=1e-15)
    plate = started(mode=0, amplitude=1.0, omega=1.0, phase=1.0, onset=10.0, ramp_time=20.0)
    assert plate.evaluate(9.99) == (0.0, 0.0, 0.0)
    z, v, a = plate.evaluate(np.array([10.0, 10.0 + 1e-6]))
    assert abs(z[1]) < 1e-15 and abs(v[1]) < 1e-9 and abs(a[1]) < 1e-3
    after = plate.evaluate(35.0)
    assert after[0] == pytest.approx(math.sin(25.0 + 1.0), abs=1e-14)


def test_sum_of_harmonics_adds_its_components():
    settings = dict(amplitude_1=1.0, omega_1=0.3, phase_1=0.1, amplitude_3=-0.5, omega_3=2.0, phase_3=-1.0)
    total = started(mode=HARMONIC_SUM, **settings).evaluate(np.linspace(0, 30, 50))
    parts = [started(mode=0, amplitude=settings[f"amplitude_{i}"], omega=settings[f"omega_{i}"],
                     phase=settings[f"phase_{i}"]).evaluate(np.linspace(0, 30, 50)) for i in (1, 3)]
    for k in range(3):
        np.testing.assert_allclose(total[k], parts[0][k] + parts[1][k], rtol=0, atol=1e-14)


# ---------------------------------------------------------------------------- playback
def test_playback_integrates_the_acceleration_exactly():
    """Piecewise-linear acceleration: its samples come back, v and z are its exact integrals."""
    rng = np.random.default_rng(4)
    acc = rng.normal(size=200)
    record = Playback(acc, 0.05, velocity0=0.3, displacement0=-1.0)
    s = np.arange(200) * 0.05
    z, v, a = record(s)
    np.testing.assert_allclose(a, acc, rtol=0, atol=1e-12)
    assert v[0] == 0.3 and z[0] == -1.0
    # between samples: v(s) - v(s_i) equals the trapezoid of the linear acceleration
    mid = record(np.array([1.0 + 0.02]))
    i = 20
    expected_v = record.velocity[i] + acc[i] * 0.02 + 0.5 * (acc[i + 1] - acc[i]) / 0.05 * 0.02**2
    assert mid[1][0] == pytest.approx(expected_v, rel=1e-13)
    # continuity across samples from the left and right
    left, right = record(s[1:-1] - 1e-9), record(s[1:-1] + 1e-9)
    for k, scale in ((0, 1e-8), (1, 1e-7), (2, 1e-5)):
        assert np.max(np.abs(left[k] - right[k])) < scale * (1 + np.max(np.abs(left[k])))


def test_playback_rests_outside_the_record():
    acc = np.concatenate([[0.0], np.sin(np.linspace(0, 2 * np.pi, 50)), [0.0]])
    record = Playback(acc, 0.1)
    before, after = record(np.array([-3.0])), record(np.array([1e3]))
    assert (before[0][0], before[1][0], before[2][0]) == (0.0, 0.0, 0.0)
    assert after[0][0] == record.displacement[-1] and after[1][0] == 0.0 and after[2][0] == 0.0


def test_amplitude_and_time_scale_map_the_record_into_model_units():
    record = load_record()
    alpha, beta, onset = 1.0 / 9.81e-5, 316.2, 40.0  # metres -> delta_0, seconds -> tau_0
    plate = started(mode=PLAYBACK, amplitude_scale=alpha, time_scale=beta, onset=onset)
    k = np.array([10, 900, 1234, 3000])
    z, v, a = plate.evaluate(onset + beta * k * record.dt)
    # to rounding: a time a hair before a sample is evaluated on the previous piece
    for got, series, factor in ((z, record.displacement, alpha), (v, record.velocity, alpha / beta),
                                (a, record.acceleration, alpha / beta**2)):
        np.testing.assert_allclose(got, factor * series[k], rtol=0, atol=1e-11 * factor * np.max(np.abs(series)))


def test_bundled_record_is_the_obspy_example_in_si_units():
    record = load_record("")
    assert record.source == str(BUNDLED_RECORD) and record.dt == 0.01 and record.acceleration.size > 3000
    assert 1e-6 < np.max(np.abs(record.acceleration)) < 1e-3  # a small local event, m/s^2
    assert record.rest_problems() == []  # processed: starts and ends at rest
    assert abs(record.displacement[-1]) < 1e-6 * np.max(np.abs(record.displacement))


def test_text_and_npz_records_agree(tmp_path):
    acc = np.sin(np.linspace(0, 6, 101)) ** 3
    text = tmp_path / "quake.csv"
    text.write_text("# time, acceleration\n" + "\n".join(f"{0.02 * i:.10g}, {float(x)!r}" for i, x in enumerate(acc)))
    npz = tmp_path / "quake.npz"
    np.savez(npz, dt=0.02, acceleration=acc)
    a, b = load_record(text), load_record(npz)
    assert a.dt == pytest.approx(b.dt, rel=1e-12)
    np.testing.assert_allclose(a.displacement, b.displacement, rtol=1e-12, atol=1e-15)


def bad_records(tmp_path):
    ok = np.sin(np.linspace(0, 3, 40))
    v, z = integrate(ok, 0.1)
    cases = {
        "missing.npz": None,
        "no_dt.npz": dict(acceleration=ok),
        "nan.npz": dict(dt=0.1, acceleration=np.where(np.arange(40) == 7, np.nan, ok)),
        "zero_dt.npz": dict(dt=0.0, acceleration=ok),
        "one_sample.npz": dict(dt=0.1, acceleration=ok[:1]),
        "two_d.npz": dict(dt=0.1, acceleration=ok.reshape(4, 10)),
        "inconsistent.npz": dict(dt=0.1, acceleration=ok, velocity=v * 1.01, displacement=z),
    }
    for name, content in cases.items():
        if content is not None:
            np.savez(tmp_path / name, **content)
    (tmp_path / "uneven.txt").write_text("0 0\n0.1 1\n0.25 0\n0.3 1\n")
    (tmp_path / "three_columns.csv").write_text("0,1,2\n0.1,1,2\n")
    (tmp_path / "garbage.npz").write_bytes(b"this is not an archive")
    (tmp_path / "record.xyz").write_text("0 0\n")
    return {**{name: "does not exist" if content is None else None for name, content in cases.items()},
            "uneven.txt": "not uniformly", "three_columns.csv": "two numbers", "garbage.npz": "cannot read",
            "record.xyz": "unknown format"}


def test_bad_record_files_are_refused_with_a_reason(tmp_path):
    expected = {"no_dt.npz": "lacks dt", "nan.npz": "non-finite", "zero_dt.npz": "dt = 0.0",
                "one_sample.npz": "at least 2", "two_d.npz": "one-dimensional", "inconsistent.npz": "not the integral"}
    for name, reason in bad_records(tmp_path).items():
        with pytest.raises(ExcitationError, match=reason or expected[name]):
            load_record(tmp_path / name)


# ---------------------------------------------------------------------------- settings and state
@pytest.mark.parametrize("name, value", [("time_scale", 0.0), ("time_scale", -2.0), ("amplitude", math.nan),
                                         ("omega", -1.0), ("sweep_time", 0.0), ("ramp_time", -1.0),
                                         ("onset", math.inf), ("amplitude_scale", "big")])
def test_bad_parameters_are_refused_and_the_old_value_kept(name, value):
    plate = Excitation()
    before = plate.parameters[name]
    with pytest.raises(ExcitationError, match=name):
        plate.set_parameter(name, value)
    assert plate.parameters[name] == before


def test_settings_that_do_not_fit_together_fail_at_the_start():
    with pytest.raises(ExcitationError, match="omega_start > 0"):
        Excitation(mode=LOG_CHIRP, omega_start=0.0).start()
    with pytest.raises(ExcitationError, match="mode = 9"):
        Excitation(mode=9)
    plate = started(mode=LINEAR_CHIRP)
    with pytest.raises(ExcitationError, match="fixed once the run has started"):
        plate.set_parameter("amplitude", 2.0)
    with pytest.raises(ExcitationError, match="later than"):
        plate.advance_to(-1.0)


def test_state_round_trip_and_a_changed_record_is_refused(tmp_path):
    path = tmp_path / "r.npz"
    np.savez(path, dt=0.1, acceleration=np.sin(np.linspace(0, 5, 60)))
    plate = Excitation(mode=PLAYBACK, record_file=str(path), time_scale=2.0, onset=1.0)
    plate.start()
    plate.advance_to(7.3)
    state = plate.get_state()
    restored = Excitation.from_state(state)
    assert restored.time == 7.3 and restored.outputs() == plate.outputs()
    np.savez(path, dt=0.1, acceleration=np.cos(np.linspace(0, 5, 60)))
    with pytest.raises(ExcitationError, match="changed since the state was saved"):
        Excitation.from_state(state)
    # a record already in memory is reused when it is the same
    assert Excitation.from_state(state, known=plate.record).outputs() == plate.outputs()


@pytest.mark.parametrize("mode", [0, LINEAR_CHIRP, HARMONIC_SUM])
def test_a_direction_splits_the_signal_into_its_vertical_and_horizontal_parts(mode):
    """plate_z = cos(direction) f, plate_x = sin(direction) f, for the kinematics alike; at
    direction 0 the vertical motion is the signal's own, to the bit, and plate_x is 0."""
    settings = dict(amplitude=0.7, omega=0.4, amplitude_1=0.2, omega_1=0.3)
    times = np.linspace(0.0, 60.0, 241)
    along = Excitation(mode=mode, **settings)
    along.start()
    vertical = along.evaluate(times)
    assert np.all(np.asarray(along.evaluate_horizontal(times)) == 0.0)
    direction = math.radians(35.0)
    oblique = Excitation(mode=mode, direction=direction, **settings)
    oblique.start()
    for part, factor in ((oblique.evaluate(times), math.cos(direction)),
                         (oblique.evaluate_horizontal(times), math.sin(direction))):
        for got, signal in zip(part, vertical):
            np.testing.assert_allclose(got, factor * signal, rtol=1e-15, atol=1e-15)
    assert set(oblique.outputs()) == {"plate_z", "plate_v", "plate_a", "plate_x", "plate_vx", "plate_ax"}


def test_a_record_s_own_horizontal_component_plays_as_plate_x_on_the_same_clock():
    """use_record(vertical, horizontal=...): plate_z plays the vertical record unscaled by
    the direction, plate_x the horizontal one; the state carries both and refuses a
    restore without the same horizontal component."""
    dt = 0.01
    t = np.arange(0, 400) * dt
    vertical = Playback(np.sin(3 * t) * np.exp(-t), dt)
    horizontal = Playback(np.cos(5 * t) * np.exp(-t), dt)
    plate = Excitation(mode=PLAYBACK, direction=1.0)
    plate.use_record(vertical, "quake", horizontal=horizontal)
    plate.start()
    times = np.linspace(0.0, 5.0, 51)
    np.testing.assert_array_equal(plate.evaluate(times)[2], vertical(times)[2])
    np.testing.assert_array_equal(plate.evaluate_horizontal(times)[2], horizontal(times)[2])
    state = plate.get_state()
    again = Excitation.from_state(state, known=vertical, known_horizontal=horizontal)
    assert again.outputs() == plate.outputs()
    with pytest.raises(ExcitationError, match="horizontal component"):
        Excitation.from_state(state, known=vertical)
