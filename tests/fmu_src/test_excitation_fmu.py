"""Excitation.fmu as FMI 2.0 masters see it: validation, outputs equal to the core,
kinematic consistency, record playback from a file, bad input, FMU state, libcosim."""
from __future__ import annotations

import contextlib
import math

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave, fmi2Error, fmi2OK
from fmpy.validation import validate_fmu

from fmu_testing import do_step, fmu_log, set_real, status_of  # noqa: F401 (fixture)
from harness.cosim.masters import run_libcosim
from vibroblock.excitation import Excitation, load_record

PLATE = ["plate_z", "plate_v", "plate_a"]
ALONG_X = ["plate_x", "plate_vx", "plate_ax"]
CHIRP = {"mode": 2, "amplitude": 1.5, "omega_start": 0.1, "omega_end": 1.0, "sweep_time": 60.0, "ramp_time": 5.0,
         "onset": 2.0}


@pytest.fixture(scope="module")
def excitation_fmu(fmu_dir):
    return str(fmu_dir / "Excitation.fmu")


@pytest.fixture(scope="module")
def extracted(excitation_fmu, tmp_path_factory):
    return read_model_description(excitation_fmu), extract(excitation_fmu,
                                                           unzipdir=str(tmp_path_factory.mktemp("excitation")))


@contextlib.contextmanager
def instance(extracted, log, start_values=None, name="plate", start_time=0.0):
    md, unzipdir = extracted
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName=name)
    slave.instantiate(callbacks=log.callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    try:
        slave.setupExperiment(startTime=start_time)
        slave.enterInitializationMode()
        set_values(slave, vr, start_values or {})
        slave.exitInitializationMode()
        yield slave, vr
    finally:
        slave.freeInstance()


def set_values(slave, vr, values):
    for key, value in values.items():
        if isinstance(value, str):
            slave.setString([vr[key]], [value])
        elif isinstance(value, int):
            slave.setInteger([vr[key]], [value])
        else:
            slave.setReal([vr[key]], [value])


def plate(slave, vr):
    return slave.getReal([vr[n] for n in PLATE])


def test_fmpy_validation_reports_nothing(excitation_fmu):
    assert validate_fmu(excitation_fmu) == []
    md = read_model_description(excitation_fmu)
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    kinds = {v.name: (v.type, v.causality, v.variability) for v in md.modelVariables}
    assert kinds["mode"] == ("Integer", "parameter", "fixed")
    assert kinds["record_file"] == ("String", "parameter", "fixed")
    for name in ("amplitude_scale", "time_scale", "onset", "ramp_time", "omega_end", "amplitude_4"):
        assert kinds[name] == ("Real", "parameter", "fixed")
    assert {n for n, k in kinds.items() if k[1] == "output"} == set(PLATE + ALONG_X)


@pytest.mark.parametrize("settings", [
    {"mode": 0, "amplitude": 2.0, "omega": 0.3, "phase": 0.5},
    CHIRP,
    {"mode": 1, "amplitude": 1.0, "omega_start": 0.2, "omega_end": 0.05, "sweep_time": 40.0, "time_scale": 2.0},
    {"mode": 3, "amplitude_1": 1.0, "omega_1": 0.2, "amplitude_2": 0.3, "omega_2": 0.9, "phase_2": 1.0},
    {"mode": 4, "amplitude_scale": 1e6, "time_scale": 2.0, "onset": 3.0},
    {"mode": 0, "amplitude": 2.0, "omega": 0.3, "phase": 0.5, "direction": 0.6},
], ids=["harmonic", "log_chirp", "linear_chirp_down", "sum", "playback_bundled", "oblique"])
def test_outputs_equal_the_core(excitation_fmu, settings):
    result = simulate_fmu(excitation_fmu, stop_time=80.0, output_interval=0.25, start_values=settings,
                          output=PLATE + ALONG_X)
    core = Excitation(**settings)
    core.start()
    expected = (*core.evaluate(result["time"]), *core.evaluate_horizontal(result["time"]))
    for name, values in zip(PLATE + ALONG_X, expected):
        np.testing.assert_allclose(result[name], values, rtol=1e-13, atol=1e-13 * np.max(np.abs(values)),
                                   err_msg=name)
    assert np.max(np.abs(result["plate_a"])) > 1e-3
    assert (np.max(np.abs(result["plate_ax"])) > 1e-3) == ("direction" in settings)


def test_fmu_outputs_are_kinematically_consistent(excitation_fmu):
    """Sampled finely, the FMU's height integrates to its velocity and that to its acceleration."""
    h = 0.01
    r = simulate_fmu(excitation_fmu, stop_time=70.0, output_interval=h, start_values=CHIRP)
    t, z, v, a = r["time"], r["plate_z"], r["plate_v"], r["plate_a"]
    # Euler-Maclaurin: the integral of v over a step is h (v0 + v1)/2 - h^2 (a1 - a0)/12 + O(h^5)
    # (except over the two steps where the sweep starts and ends: a jumps there)
    dz = np.diff(z) - 0.5 * h * (v[1:] + v[:-1]) + h * h / 12.0 * np.diff(a)
    smooth = np.ones(dz.size, bool)
    for kink in (CHIRP["onset"], CHIRP["onset"] + CHIRP["sweep_time"]):
        smooth[(t[:-1] < kink + 1e-9) & (t[1:] > kink - 1e-9)] = False
    assert np.count_nonzero(~smooth) <= 4
    assert np.max(np.abs(dz[smooth])) < 1e-12
    # trapezoid for v: error h^3/12 times the jerk (|jerk| <= ~A omega^3 (1 + ...) here)
    dv = np.diff(v) - 0.5 * h * (a[1:] + a[:-1])
    assert np.max(np.abs(dv[smooth])) < 3.0 * h**3 / 12.0
    assert np.max(np.abs(z)) > 1.0 and t[-1] == 70.0


def test_playback_from_a_record_file_and_time_units(extracted, fmu_log, tmp_path):
    """A record file given by path plays in model units: amplitude_scale = 1/delta_0[m],
    time_scale = 1/tau_0[s] turn the SI samples into delta_0 and tau_0."""
    dt = 0.005
    acc = np.sin(np.linspace(0.0, 4 * np.pi, 401)) ** 3 * 0.2  # m/s^2, starts and ends at rest
    path = tmp_path / "quake.npz"
    np.savez(path, dt=dt, acceleration=acc)
    length, time = 9.81e-5, math.sqrt(1e-5)  # delta_0 [m], tau_0 [s] of 1 kg on 1e5 N/m
    start = {"mode": 4, "record_file": str(path), "amplitude_scale": 1 / length, "time_scale": 1 / time}
    record = load_record(path)
    with instance(extracted, fmu_log, start) as (slave, vr):
        assert slave.getString([vr["record_file"]])[0].decode() == str(path)
        t, h = 0.0, 10 * dt / time  # ten record samples per communication step
        for k in range(1, 41):
            slave.doStep(t, h)
            t = k * h
            z, v, a = plate(slave, vr)
            i = 10 * k
            assert z * length == pytest.approx(record.displacement[i], rel=1e-9, abs=1e-18)
            assert v * length / time == pytest.approx(record.velocity[i], rel=1e-9, abs=1e-15)
            assert a * length / time**2 == pytest.approx(acc[i], rel=1e-9, abs=1e-12)


def bad_real_values():
    yield from [("time_scale", 0.0), ("time_scale", math.nan), ("amplitude", math.inf), ("omega", -0.5),
                ("sweep_time", -1.0), ("ramp_time", -2.0), ("amplitude_scale", math.nan)]


@pytest.mark.parametrize("name, value", list(bad_real_values()))
def test_bad_parameters_give_fmi2error_and_the_instance_goes_on(extracted, fmu_log, name, value):
    """Set in initialization mode (fixed parameters are refused once running anyway)."""
    md, _ = extracted
    slave = FMU2Slave(guid=md.guid, unzipDirectory=extracted[1], modelIdentifier="Excitation", instanceName="bad")
    slave.instantiate(callbacks=fmu_log.callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        before = slave.getReal([vr[name]])[0]
        fmu_log.clear()
        assert set_real(slave, vr[name], value) == fmi2Error
        assert any(status == fmi2Error and name in message for _, status, _, message in fmu_log.records)
        assert slave.getReal([vr[name]])[0] == before  # the last good value is kept
        slave.exitInitializationMode()
        assert do_step(slave, 0.0, 1.0) == fmi2OK
    finally:
        slave.freeInstance()


def test_bad_mode_and_record_files_give_fmi2error_and_keep_the_last_good_value(extracted, fmu_log, tmp_path):
    md, unzipdir = extracted
    broken = tmp_path / "broken.npz"
    broken.write_bytes(b"not a record")
    good = tmp_path / "good.npz"
    np.savez(good, dt=0.5, acceleration=np.sin(np.linspace(0.0, 3.0, 20)) ** 2)
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="Excitation", instanceName="files")
    slave.instantiate(callbacks=fmu_log.callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        set_values(slave, vr, {"mode": 4, "record_file": str(good)})
        fmu_log.clear()
        assert status_of(lambda: slave.setInteger([vr["mode"]], [9])) == fmi2Error
        for bad in (str(tmp_path / "missing.npz"), str(broken), str(tmp_path)):
            assert status_of(lambda: slave.setString([vr["record_file"]], [bad])) == fmi2Error
        messages = " | ".join(m for *_, m in fmu_log.records)
        for text in ("mode = 9", "does not exist", "cannot read record file"):
            assert text in messages
        assert slave.getInteger([vr["mode"]])[0] == 4
        assert slave.getString([vr["record_file"]])[0].decode() == str(good)
        slave.exitInitializationMode()  # goes on with the last good record
        assert do_step(slave, 0.0, 3.0) == fmi2OK
        assert plate(slave, vr)[2] == pytest.approx(load_record(good).acceleration[6], rel=1e-12)
    finally:
        slave.freeInstance()


def test_bad_steps_and_changes_while_running_give_fmi2error(extracted, fmu_log):
    with instance(extracted, fmu_log, {"mode": 0, "amplitude": 1.0, "omega": 0.4}) as (slave, vr):
        slave.doStep(0.0, 1.0)
        before = plate(slave, vr)
        fmu_log.clear()
        assert status_of(lambda: slave.setReal([vr["amplitude"]], [3.0])) == fmi2Error  # fixed once running
        assert status_of(lambda: slave.setString([vr["record_file"]], [""])) == fmi2Error
        for h in (0.0, -1.0, math.nan, math.inf):
            assert do_step(slave, 1.0, h) == fmi2Error
        assert do_step(slave, 0.5, 1.0) == fmi2Error  # not the FMU's time
        messages = " | ".join(m for *_, m in fmu_log.records)
        for text in ("fixed once the run has started", "step size", "differs from the FMU's time"):
            assert text in messages
        assert plate(slave, vr) == before
        assert do_step(slave, 1.0, 1.0) == fmi2OK
        assert plate(slave, vr)[0] == pytest.approx(math.sin(0.4 * 2.0), abs=1e-15)


def test_settings_that_do_not_fit_fail_the_initialization(extracted, fmu_log):
    md, unzipdir = extracted
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="Excitation", instanceName="init")
    slave.instantiate(callbacks=fmu_log.callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        set_values(slave, vr, {"mode": 2, "omega_start": 0.0})
        fmu_log.clear()
        assert status_of(slave.exitInitializationMode) == fmi2Error
        assert any("omega_start > 0" in m for *_, m in fmu_log.records)
        assert do_step(slave, 0.0, 1.0) == fmi2Error  # never started: every step is refused, no crash
    finally:
        slave.freeInstance()


def test_saved_state_restores_bit_for_bit_also_in_a_new_instance(extracted, fmu_log, tmp_path):
    path = tmp_path / "r.npz"
    np.savez(path, dt=0.1, acceleration=np.sin(np.linspace(0.0, 9.0, 300)) ** 2)
    start = {"mode": 4, "record_file": str(path), "time_scale": 0.5, "onset": 1.0, "ramp_time": 2.0}
    with instance(extracted, fmu_log, start) as (slave, vr):
        t = 0.0
        for _ in range(10):
            slave.doStep(t, 0.7)
            t += 0.7
        state = slave.getFMUstate()
        serialized = slave.serializeFMUstate(state)
        saved_t = t
        for _ in range(12):
            slave.doStep(t, 0.7)
            t += 0.7
        reference = plate(slave, vr)
        slave.setFMUstate(state)
        assert slave.getString([vr["record_file"]])[0].decode() == str(path)
        t = saved_t
        for _ in range(12):
            slave.doStep(t, 0.7)
            t += 0.7
        assert plate(slave, vr) == reference
        slave.freeFMUstate(state)
    with instance(extracted, fmu_log, name="fresh") as (fresh, vr):  # a harmonic until restored
        fresh.setFMUstate(fresh.deSerializeFMUstate(serialized))
        t = saved_t
        for _ in range(12):
            fresh.doStep(t, 0.7)
            t += 0.7
        assert plate(fresh, vr) == reference
        assert fresh.getInteger([vr["mode"]])[0] == 4


def test_libcosim_runs_the_fmu_like_fmpy(excitation_fmu):
    settings = {"mode": 1, "amplitude": 1.0, "omega_start": 0.1, "omega_end": 0.8, "sweep_time": 50.0}
    cosim = run_libcosim(excitation_fmu, start_values=settings, stop_time=60.0, step_size=0.5, outputs=PLATE)
    fmpy = simulate_fmu(excitation_fmu, stop_time=60.0, output_interval=0.5, start_values=settings)
    for name in PLATE:  # times k/2 are exact in both masters' clocks: the same bits
        np.testing.assert_array_equal(cosim[name], fmpy[name])
