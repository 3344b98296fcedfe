"""``vibroblock record``: records in formats the product does not ship (obspy's own test
data), end to end through the command line, and the processed record through the
Excitation FMU in fmpy.

The FMUs are built without the shipped kernels (quick to build); the block's run
compiles what it needs once into the shared kernel cache.
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import obspy
import pytest

REPO = Path(__file__).resolve().parents[3]
OBSPY = Path(obspy.__file__).parent
ULN_RECORD = OBSPY / "core" / "tests" / "data" / "IU_ULN_00_LH1_2015-07-18T02.mseed"  # MiniSEED, counts
ULN_INVENTORY = OBSPY / "core" / "tests" / "data" / "IU_ULN_00_LH1.xml"            # its StationXML
SAC_VOLTS = OBSPY / "io" / "sac" / "tests" / "data" / "seism.sac"                    # SAC, idep = volts


def record(args, env, timeout=900):
    return subprocess.run([sys.executable, "-m", "harness", "record", *map(str, args)], capture_output=True,
                          text=True, cwd=str(REPO), env=env, timeout=timeout)


def test_a_miniseed_record_with_its_stationxml_runs_and_plays_in_the_excitation_fmu(quick_fmus, tmp_path,
                                                                                      subprocess_env):
    from fmpy import simulate_fmu

    saved = tmp_path / "uln.npz"
    done = record([ULN_RECORD, "--inventory", ULN_INVENTORY, "--fmu", quick_fmus / "BlockA.fmu", "--freqmin", "0.02",
                   "--time-stretch", "0.001", "--peak-g", "0.2", "--stop-time", "400", "--step", "1",
                   "--save-record", saved, "--out", tmp_path], subprocess_env)
    assert done.returncode == 0, done.stderr[-3000:]
    result = json.loads(done.stdout.strip().splitlines()[-1])
    # 1 kg on 1e5 N/m: tau_0 = 3.16 ms, so 1.11e4 s of record played 1000x faster last 3.5e3 tau_0.
    assert result["record_duration"] == pytest.approx(1.11e4 * 0.001 / 3.1623e-3, rel=0.01)
    assert result["stop_time"] == 400.0
    assert len(result["notes"]) == 1 and "shorter than the processed record" in result["notes"][0]
    assert "400 tau_0 = 1265 s of the record" in result["notes"][0]  # 400 x 3.1623 ms x 1000
    assert (tmp_path / "record_response.png").is_file()
    assert "peak_plate_acceleration_g" in done.stdout and "one slip holds many" in done.stdout
    # The processed record (SI) plays in the Excitation FMU in fmpy.
    played = simulate_fmu(str(quick_fmus / "Excitation.fmu"), stop_time=100.0, output_interval=1.0,
                          start_values={"mode": 4, "record_file": str(saved), "amplitude_scale": 1.0,
                                        "time_scale": 1.0})
    with np.load(saved) as data:
        assert data["acceleration"].size == result_samples(done.stdout)
    assert np.any(played["plate_z"] != 0.0) and np.all(np.isfinite(played["plate_a"]))


def test_a_record_too_long_to_play_whole_asks_for_a_shorter_run(quick_fmus, subprocess_env):
    """The ULN record (1.11e4 s at 1 Hz) at its own pace is 3.5e6 tau_0 of a 1 kg block on
    1e5 N/m: 1.4e7 communication steps, which would hold gigabytes.  One line, exit status 2,
    naming the count and the three ways out."""
    refused = record([ULN_RECORD, "--inventory", ULN_INVENTORY, "--fmu", quick_fmus / "BlockA.fmu", "--freqmin",
                      "0.02"], subprocess_env, timeout=300)
    assert refused.returncode == 2 and "Traceback" not in refused.stderr
    [line] = refused.stderr.strip().splitlines()
    assert line.startswith("vibroblock record: error: the run would take 1.4e+07 communication steps")
    assert "--stop-time 500000 or less" in line and "--step" in line and "--time-stretch 0.14 or less" in line


def result_samples(printed: str) -> int:
    line = next(line for line in printed.splitlines() if line.startswith("record: "))
    return int(line.split("), ", 1)[1].split(" samples")[0])


def test_a_sac_record_in_volts_needs_a_sensitivity_and_runs_with_one(quick_fmus, tmp_path, subprocess_env):
    refused = record([SAC_VOLTS, "--fmu", quick_fmus / "BlockA.fmu", "--quantity", "velocity", "--unit", "m/s"],
                     subprocess_env)
    assert refused.returncode == 2 and "Traceback" not in refused.stderr
    assert "counts or volts" in refused.stderr and "--sensitivity" in refused.stderr
    done = record([SAC_VOLTS, "--fmu", quick_fmus / "BlockA.fmu", "--quantity", "velocity", "--unit", "m/s",
                   "--sensitivity", "1e3", "--freqmin", "1", "--peak-g", "0.3", "--time-stretch", "30", "--step", "5",
                   "--out", tmp_path], subprocess_env)
    assert done.returncode == 0, done.stderr[-3000:]
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["notes"] == [] and result["stop_time"] == pytest.approx(result["record_duration"], abs=5.0)
    assert "counts divided by the stated sensitivity" not in done.stdout  # the history is not printed
    peak = next(line for line in done.stdout.splitlines() if "peak_plate_acceleration_g" in line)
    assert float(peak.split()[1]) == pytest.approx(0.3, rel=0.05)  # --peak-g is the plate's peak, after stretching


def test_the_excitation_fmu_plays_a_miniseed_record_with_its_response_in_fmpy(quick_fmus, tmp_path, subprocess_env):
    """record_file names obspy's MiniSEED (counts), record_inventory its StationXML: the FMU
    processes it at initialization as harness.ground.records does (same acceleration)."""
    from fmpy import simulate_fmu

    from harness.ground.records import load_ground_motion

    fmu = str(quick_fmus / "Excitation.fmu")
    played = simulate_fmu(fmu, stop_time=4000.0, output_interval=1.0,
                          start_values={"mode": 4, "record_file": str(ULN_RECORD),
                                        "record_inventory": str(ULN_INVENTORY), "amplitude_scale": 1.0,
                                        "time_scale": 1.0})
    motion = load_ground_motion(str(ULN_RECORD), inventory=str(ULN_INVENTORY))
    # Played in the record's own seconds and metres: the samples at whole seconds are its own.
    index = np.round(played["time"] / motion.dt).astype(int)
    np.testing.assert_allclose(played["plate_a"], motion.acceleration[index], rtol=0,
                               atol=1e-9 * np.max(np.abs(motion.acceleration)))
    # Counts without their response are refused at initialization, with the parameter to set.
    script = ("import sys\nfrom fmpy import simulate_fmu\ntry:\n    simulate_fmu(sys.argv[1], stop_time=1.0, "
              "start_values={'mode': 4, 'record_file': sys.argv[2]})\nexcept Exception as exc:\n"
              "    print('raised:', exc)\n")
    done = subprocess.run([sys.executable, "-c", script, fmu, str(ULN_RECORD)], capture_output=True, text=True,
                          env=subprocess_env, timeout=300)
    errors = [line for line in done.stdout.splitlines() if line.startswith("[ERROR]")]
    assert len(errors) == 1 and "holds counts without an instrument response" in errors[0]
    assert "set record_inventory" in errors[0] and "raised:" in done.stdout


def test_the_excitation_fmu_restores_a_seismic_record_s_state_in_a_new_instance(quick_fmus, tmp_path):
    """A serialized state of an instance playing a MiniSEED record (counts, with its
    StationXML) continues bit for bit in a fresh instance that never read the record."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    fmu = str(quick_fmus / "Excitation.fmu")
    md, unzipped = read_model_description(fmu), extract(fmu, unzipdir=str(tmp_path / "x"))
    vr = {v.name: v.valueReference for v in md.modelVariables}

    def instance(name):
        slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                          instanceName=name)
        slave.instantiate()
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        return slave

    def play(slave, t, steps):
        samples = []
        for _ in range(steps):
            slave.doStep(t, 7.0)  # fmpy raises on an error status
            t += 7.0
            samples.append(tuple(slave.getReal([vr["plate_z"], vr["plate_v"], vr["plate_a"]])))
        return samples

    first = instance("first")
    first.setInteger([vr["mode"]], [4])
    first.setString([vr["record_file"], vr["record_inventory"]], [str(ULN_RECORD), str(ULN_INVENTORY)])
    first.exitInitializationMode()
    play(first, 0.0, 100)
    serialized = first.serializeFMUstate(first.getFMUstate())
    reference = play(first, 700.0, 100)
    first.terminate()
    first.freeInstance()

    fresh = instance("fresh")  # harmonic, no record, until restored
    fresh.exitInitializationMode()
    fresh.setFMUstate(fresh.deSerializeFMUstate(serialized))
    assert fresh.getString([vr["record_file"]])[0].decode() == str(ULN_RECORD)
    assert play(fresh, 700.0, 100) == reference
    fresh.terminate()
    fresh.freeInstance()


def test_a_three_component_record_shakes_the_plate_vertically_and_along_its_slip_azimuth(quick_fmus, tmp_path,
                                                                                         subprocess_env):
    """obspy's example event (BW.RJOB, Z, N, E in counts, with its StationXML) end to end:
    each channel processed, the horizontal motion along 30 degrees played as plate_x of an
    oblique plate (plate_motion = 1) by rk4 (adaptive, the default, takes the plate as
    vertical: the run says so), scaled so that the larger component peaks at 1.2 g; the
    horizontal shaking above mu_s g drags the block (Coulomb resets)."""
    from harness.ground.records import ProcessingSettings, load_ground_motion_components

    obspy.read().write(str(tmp_path / "rjob.mseed"), format="MSEED")
    obspy.read_inventory().write(str(tmp_path / "rjob.xml"), format="STATIONXML")
    done = record([tmp_path / "rjob.mseed", "--inventory", tmp_path / "rjob.xml", "--azimuth", "30", "--fmu",
                   quick_fmus / "BlockA.fmu", "--freqmin", "1", "--peak-g", "1.2", "--stop-time", "6000",
                   "--step", "0.5", "--out", tmp_path], subprocess_env)
    assert done.returncode == 0, done.stderr[-3000:]
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert any("running rk4" in note for note in result["notes"])
    peaks = {line.split()[0]: float(line.split()[1]) for line in done.stdout.splitlines()
             if line.strip().startswith("peak_plate_")}
    assert max(peaks["peak_plate_acceleration_g"], peaks["peak_plate_horizontal_acceleration_g"]) == \
        pytest.approx(1.2, rel=0.02)
    vertical, horizontal = load_ground_motion_components(str(tmp_path / "rjob.mseed"), 30.0,
                                                         ProcessingSettings(freqmin=1.0),
                                                         inventory=str(tmp_path / "rjob.xml"))
    ratio = horizontal.peak_acceleration / vertical.peak_acceleration  # the record's own, kept by the scaling
    assert peaks["peak_plate_horizontal_acceleration_g"] / peaks["peak_plate_acceleration_g"] == \
        pytest.approx(ratio, rel=0.05)
    if peaks["peak_plate_horizontal_acceleration_g"] > 0.5:
        assert result["coulomb_resets"] > 0


def test_the_excitation_fmu_plays_a_three_component_record_s_vertical_and_horizontal_motions(quick_fmus, tmp_path,
                                                                                             capsys):
    """record_components = 2: plate_z plays the vertical channel, plate_x the horizontal
    motion along record_azimuth, both as harness.ground.records computes them;
    record_components = 2 outside a seismic playback fails the initialization."""
    from fmpy import simulate_fmu

    from harness.ground.records import load_ground_motion_components

    obspy.read().write(str(tmp_path / "rjob.mseed"), format="MSEED")
    obspy.read_inventory().write(str(tmp_path / "rjob.xml"), format="STATIONXML")
    fmu = str(quick_fmus / "Excitation.fmu")
    settings = {"mode": 4, "record_file": str(tmp_path / "rjob.mseed"), "record_inventory": str(tmp_path / "rjob.xml"),
                "record_components": 2, "record_azimuth": 30.0, "amplitude_scale": 1.0, "time_scale": 1.0}
    played = simulate_fmu(fmu, stop_time=30.0, output_interval=0.01, start_values=settings,
                          output=["plate_z", "plate_a", "plate_x", "plate_ax"])
    vertical, horizontal = load_ground_motion_components(str(tmp_path / "rjob.mseed"), 30.0,
                                                         inventory=str(tmp_path / "rjob.xml"))
    index = np.round(played["time"] / vertical.dt).astype(int)
    for name, motion in (("plate_a", vertical), ("plate_ax", horizontal)):
        np.testing.assert_allclose(played[name], motion.acceleration[index], rtol=0,
                                   atol=1e-9 * motion.peak_acceleration, err_msg=name)
    assert np.max(np.abs(played["plate_ax"])) > 0.1 * np.max(np.abs(played["plate_a"]))
    # The failing initialization in this process, after the instances above and whatever
    # else this process ran: fmi2Error with the FMU's message, printed by fmpy's logger.
    capsys.readouterr()
    with pytest.raises(Exception, match=r"fmi2ExitInitializationMode failed with status 3 \(error\)"):
        simulate_fmu(fmu, stop_time=1.0, start_values={"mode": 0, "record_components": 2})
    errors = [line for line in capsys.readouterr().out.splitlines() if line.startswith("[ERROR]")]
    assert len(errors) == 1 and "record_components = 2 plays a three-component" in errors[0]
