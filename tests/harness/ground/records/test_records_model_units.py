"""Model units: scales, round trips and resampling to a model-time grid."""

from __future__ import annotations

import math

import numpy as np
import pytest

from harness.ground.records import (
    ModelScales,
    ProcessingSettings,
    Record,
    RecordError,
    process_record,
    scale_to_peak_acceleration,
    to_model_grid,
)


@pytest.fixture
def scales() -> ModelScales:
    return ModelScales.from_block(mass=1.0, normal_stiffness=1e5, gravity=9.81)


@pytest.fixture
def motion(analytic):
    return process_record(Record(data=analytic.a, dt=analytic.dt, quantity="acceleration"),
                          ProcessingSettings(freqmin=0.2, pad_seconds=5.0))


def test_worked_example(scales):
    assert scales.length_scale == pytest.approx(9.81e-5, rel=1e-12)
    assert scales.time_scale == pytest.approx(math.sqrt(1e-5), rel=1e-12)
    assert scales.time_scale == pytest.approx(3.1623e-3, rel=1e-4)
    assert scales.velocity_scale == pytest.approx(0.0310219, rel=1e-5)
    assert scales.acceleration_scale == pytest.approx(9.81, rel=1e-12)  # model g = 1
    assert scales.to_model(0.1, "acceleration") == pytest.approx(0.0101937, rel=1e-5)
    assert scales.to_model(0.01, "velocity") == pytest.approx(0.322352, rel=1e-5)
    assert scales.to_model(1e-3, "displacement") == pytest.approx(10.19368, rel=1e-6)
    assert scales.to_model(10.0, "time") == pytest.approx(3162.278, rel=1e-6)
    assert scales.to_model(2 * np.pi, "angular_frequency") == pytest.approx(0.0198692, rel=1e-5)


def test_round_trips(scales):
    x = np.array([1e-4, 0.3, 12.0])
    for q in ("time", "displacement", "velocity", "acceleration", "angular_frequency"):
        np.testing.assert_allclose(scales.to_si(scales.to_model(x, q), q), x, rtol=1e-14)
        assert scales.to_model(scales.to_si(2.5, q), q) == pytest.approx(2.5, rel=1e-14)
    k_n, g = scales.block_parameters(mass=1.0)
    assert k_n == pytest.approx(1e5, rel=1e-12)
    assert g == pytest.approx(9.81, rel=1e-12)
    again = ModelScales.from_block(2.0, *scales.block_parameters(mass=2.0))
    assert again.length_scale == pytest.approx(scales.length_scale, rel=1e-12)
    assert again.time_scale == pytest.approx(scales.time_scale, rel=1e-12)


def test_scale_errors(scales):
    with pytest.raises(RecordError, match="mass"):
        ModelScales.from_block(mass=0.0, normal_stiffness=1e5)
    with pytest.raises(RecordError, match="normal_stiffness"):
        ModelScales.from_block(mass=1.0, normal_stiffness=-1.0)
    with pytest.raises(RecordError, match="cannot convert quantity 'force'"):
        scales.to_model(1.0, "force")


def test_native_grid_reproduces_the_motion(motion, scales):
    drive = to_model_grid(motion, scales)
    assert drive.dt == pytest.approx(motion.dt / scales.time_scale)
    assert drive.time.size == motion.time.size
    np.testing.assert_allclose(drive.acceleration * 9.81, motion.acceleration,
                               atol=1e-12 * motion.peak_acceleration)
    np.testing.assert_allclose(drive.displacement * scales.length_scale, motion.displacement,
                               atol=1e-9 * motion.peak_displacement)


def test_fine_grid_is_consistent_and_hits_the_samples(motion, scales):
    step = motion.dt / scales.time_scale / 8  # eight model steps per record sample
    drive = to_model_grid(motion, scales, dt=step)
    assert drive.time.size == 8 * (motion.time.size - 1) + 1
    # every 8th model sample is a record sample
    np.testing.assert_allclose(drive.velocity[::8] * scales.velocity_scale, motion.velocity,
                               atol=1e-9 * motion.peak_velocity)
    # v = dz/dt and a = dv/dt in model units
    def rel(x, y):
        return np.max(np.abs(x - y)) / np.max(np.abs(y))
    assert rel(np.gradient(drive.displacement, step), drive.velocity) < 1e-3
    assert rel(np.gradient(drive.velocity, step), drive.acceleration) < 1e-3


def test_coarse_grid_that_would_alias_is_refused(motion, scales):
    # freqmax is 80 Hz (0.4 × 200 Hz); a 0.02 s model step has a 25 Hz Nyquist
    with pytest.raises(RecordError, match="alias"):
        to_model_grid(motion, scales, dt=0.02 / scales.time_scale)


def test_duration_and_size_limits(motion, scales):
    total = motion.time[-1] / scales.time_scale
    with pytest.raises(RecordError, match="exceeds the motion"):
        to_model_grid(motion, scales, duration=2 * total)
    with pytest.raises(RecordError, match="max_samples"):
        to_model_grid(motion, scales, dt=1e-3, max_samples=1000)
    part = to_model_grid(motion, scales, duration=total / 2)
    assert part.time[-1] <= total / 2 + 1e-9


def test_peak_in_model_units_after_scaling(motion, scales):
    scaled = scale_to_peak_acceleration(motion, 0.5, gravity=scales.gravity)
    drive = to_model_grid(scaled, scales)
    assert np.max(np.abs(drive.acceleration)) == pytest.approx(0.5, rel=1e-12)


def test_drive_dataset(motion, scales):
    ds = to_model_grid(motion, scales).to_dataset()
    assert ds["displacement"].attrs["units"] == "delta0"
    assert ds["time"].attrs["units"] == "tau0"
    assert ds.attrs["length_scale_m"] == pytest.approx(9.81e-5)
    assert ds.attrs["processing_freqmin"] == 0.2


def test_module_examples_run():
    """The worked example in the model-units docstring is checked, not just shown."""
    import doctest

    from harness.ground.records import model_units, quantities

    for module in (model_units, quantities):
        result = doctest.testmod(module)
        assert result.attempted > 0 and result.failed == 0, module.__name__
