"""Records into blocks (harness.ground.excitation): the bundled record, fmpy input tables, and the
SI -> model-unit round trip through the composition."""
from __future__ import annotations

import numpy as np
import pytest
from fmpy import simulate_fmu

from harness.ground.excitation import (INPUT_NAMES, bundled_ground_motion, excitation_of, peak_scaled_parameters,
                                plate_input, playback_parameters, simulate_block, write_record)
from harness.ground.records import ModelScales, RecordError, to_model_grid
from vibroblock.excitation import BUNDLED_RECORD, Excitation, load_record

SCALES = ModelScales.from_block(mass=1.0, normal_stiffness=1e5)  # delta_0 = 9.81e-5 m, tau_0 = 3.16e-3 s


@pytest.fixture(scope="module")
def motion():
    return bundled_ground_motion()


def test_the_bundled_record_is_obspys_example_processed_as_documented(motion):
    packed = load_record(BUNDLED_RECORD)
    assert packed.dt == motion.dt
    scale = np.max(np.abs(motion.acceleration))
    np.testing.assert_allclose(packed.acceleration, motion.acceleration, rtol=0, atol=1e-12 * scale)
    # the FMU's own integration reproduces the processed velocity and displacement
    for mine, theirs in ((packed.velocity, motion.velocity), (packed.displacement, motion.displacement)):
        np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-9 * np.max(np.abs(theirs)))
    with np.load(BUNDLED_RECORD) as data:
        assert str(data["trace_id"]) == "BW.RJOB..EHZ" and "removed instrument response" in str(data["history"])


def test_unit_round_trip_through_the_excitation_fmu(motion, fmu_dir, tmp_path):
    """SI record -> record file -> Excitation FMU with playback_parameters(scales) ->
    plate outputs in delta_0, tau_0 -> back to SI: the record's own samples."""
    path = write_record(motion, tmp_path / "rjob.npz")
    h = 25 * motion.dt / SCALES.time_scale  # model step of 25 record samples
    n = (motion.time.size - 1) // 25
    result = simulate_fmu(str(fmu_dir / "Excitation.fmu"), stop_time=n * h, output_interval=h,
                          start_values={"mode": 4, "record_file": str(path), **playback_parameters(SCALES)})
    samples = 25 * np.arange(n + 1)
    for name, series, quantity in (("plate_z", motion.displacement, "displacement"),
                                   ("plate_v", motion.velocity, "velocity"),
                                   ("plate_a", motion.acceleration, "acceleration")):
        back = SCALES.to_si(result[name], quantity)
        np.testing.assert_allclose(back, series[samples], rtol=0, atol=1e-9 * np.max(np.abs(series)), err_msg=name)
    assert np.max(np.abs(result["plate_a"])) == pytest.approx(np.max(np.abs(motion.acceleration)) / 9.81, rel=0.2)
    # and the table the harness feeds through fmpy's input holds the same values
    table = plate_input(motion, scales=SCALES, step_size=h, stop_time=n * h)
    for name in INPUT_NAMES:
        np.testing.assert_allclose(table[name], result[name], rtol=0, atol=1e-12 * np.max(np.abs(table[name])))


def test_a_plate_drive_is_reproduced_on_its_own_grid_and_off_it(motion):
    drive = to_model_grid(motion, SCALES, dt=2.0)  # resampled: 2 tau_0 = 6.3 ms steps
    packed = plate_input(drive)
    np.testing.assert_array_equal(packed["plate_z"], drive.displacement)
    evaluated = plate_input(drive, step_size=drive.dt, stop_time=drive.time[-1])
    for name, series in zip(INPUT_NAMES, (drive.displacement, drive.velocity, drive.acceleration)):
        np.testing.assert_allclose(evaluated[name], series, rtol=0, atol=1e-9 * np.max(np.abs(series)))
    # a plate drive played with an onset starts later, at rest before
    late = excitation_of(drive, onset=100.0)
    assert late.evaluate(50.0) == (0.0, 0.0, 0.0)
    assert late.evaluate(100.0 + drive.time[400])[2] == pytest.approx(drive.acceleration[400], rel=1e-9)


def test_peak_scaling_and_time_stretch(motion):
    record = load_record()
    params = peak_scaled_parameters(record, 0.4, 50.0, onset=7.0)
    plate = Excitation(mode=4, **params)
    plate.start()
    t = 7.0 + 50.0 * record.dt * np.arange(record.acceleration.size)
    assert np.max(np.abs(plate.evaluate(t)[2])) == pytest.approx(0.4, rel=1e-12)
    with pytest.raises(RecordError, match="peak_acceleration"):
        peak_scaled_parameters(record, -1.0, 50.0)


def test_block_driven_through_fmpy_input(motion, fmu_path):
    """Composition (a): the record reaches a block through fmpy's input table."""
    scaled = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
    record = load_record()
    table = plate_input(record, step_size=0.5, stop_time=600.0, **peak_scaled_parameters(record, 0.5, 15.0))
    assert table.dtype.names == ("time", *INPUT_NAMES) and table["time"][-1] == 600.0
    result = simulate_block(fmu_path("A"), table, start_values=scaled)
    at_rest = simulate_fmu(fmu_path("A"), stop_time=600.0, output_interval=0.5, start_values=scaled)
    shaken = np.max(np.abs(result["normal_force"] - at_rest["normal_force"]))
    assert 0.2 < shaken < 2.0  # about m times the plate's acceleration, which peaks at 0.5 g


def test_bad_requests_are_refused(motion, tmp_path):
    with pytest.raises(RecordError, match="in SI units: give scales"):
        plate_input(motion, step_size=1.0, stop_time=10.0)
    with pytest.raises(RecordError, match="end in .npz"):
        write_record(motion, tmp_path / "rjob.csv")
    with pytest.raises(ValueError, match="give stop_time"):
        plate_input(Excitation(mode=0), step_size=1.0)
    with pytest.raises(ValueError, match="whole number of steps"):
        plate_input(Excitation(mode=0), step_size=0.3, stop_time=1.0)
