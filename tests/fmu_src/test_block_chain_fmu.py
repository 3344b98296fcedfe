"""BlockChain.fmu as FMI 2.0 masters see it: validation, the core's bits, the catalogue
file, FMU state, bad input, another N at build time, libcosim."""
from __future__ import annotations

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave, fmi2Error
from fmpy.validation import validate_fmu

from fmu_testing import do_step, fmu_log, status_of, with_another_core  # noqa: F401 (fixture)
from harness.chain.catalog import read_catalog
from harness.chain.run import simulate_chain
from harness.cosim.masters import run_libcosim
from vibroblock.chain import Chain

SETTINGS = {"mu_s_spread": 0.3, "load_spread": 0.2, "seed": 4, "A": 0.05, "omega": 1.3}


@pytest.fixture(scope="module")
def chain_fmu(fmu_dir):
    return str(fmu_dir / "BlockChain.fmu")


def test_fmpy_validation_reports_nothing_and_every_block_has_its_outputs(chain_fmu):
    assert validate_fmu(chain_fmu) == []
    names = {v.name for v in read_model_description(chain_fmu).modelVariables}
    assert {f"x[{i}]" for i in range(1, 17)} <= names and "x[17]" not in names and "vx[16]" in names


@pytest.mark.parametrize("clusters, integrator", [(False, 0), (True, 0), (False, 1)],
                         ids=["chain_wide", "clusters", "rk4"])
def test_outputs_and_catalogue_equal_the_cores(chain_fmu, tmp_path, clusters, integrator):
    result, events = simulate_chain(chain_fmu, stop_time=15000.0, step_size=50.0, catalog=tmp_path / "events.csv",
                                    start_values={**SETTINGS, "cluster_catalog": clusters, "integrator": integrator},
                                    outputs=("event_count", "x[1]", "x[16]"))
    chain = Chain(16, clusters=clusters, integrator=integrator, **SETTINGS)
    chain.start()
    for t in result["time"][1:]:
        chain.advance_to(t)
    assert result["x[16]"][-1] == chain.x[15] and result["x[1]"][-1] == chain.x[0]
    assert result["event_count"][-1] == len(chain.events) == len(events) > 3
    assert events["t_start"].tolist() == [e[0] for e in chain.events]
    assert events["first_block"].tolist() == [int(e[2]) + 1 for e in chain.events]  # 1-based, as x[i]
    assert "v_start = 0.3" in events.attrs["thresholds"] and "v_stop = 0.1" in events.attrs["thresholds"]
    assert ("clusters" in events.attrs["thresholds"]) == clusters


@pytest.fixture
def instance(chain_fmu, tmp_path, fmu_log):
    md = read_model_description(chain_fmu)
    slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(chain_fmu, unzipdir=str(tmp_path / "x")),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="chain")
    slave.instantiate(callbacks=fmu_log.callbacks)
    yield slave, {v.name: v.valueReference for v in md.modelVariables}
    slave.freeInstance()


@pytest.mark.parametrize("integrator", [0, 1])
def test_fmu_state_restores_the_run_bit_for_bit(instance, integrator):
    slave, vr = instance
    slave.setReal([vr["mu_s_spread"]], [0.3])
    slave.setInteger([vr["integrator"]], [integrator])
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    slave.doStep(0.0, 2000.0)
    state = slave.serializeFMUstate(slave.getFMUstate())
    outputs = [vr[f"x[{i}]"] for i in range(1, 17)] + [vr["energy_residual"]]
    slave.doStep(2000.0, 3000.0)
    first = slave.getReal(outputs), slave.getInteger([vr["event_count"]])
    slave.setFMUstate(slave.deSerializeFMUstate(state))
    slave.doStep(2000.0, 3000.0)
    assert (slave.getReal(outputs), slave.getInteger([vr["event_count"]])) == first
    assert first[1][0] > 0


def test_jump_sticks_runs_the_cores_jumped_chain_and_restores_bit_for_bit(instance):
    """Off by default; on, the FMU's outputs are the jumped core's at the same communication
    points, the run jumps, and a restored state jumps as the run did."""
    slave, vr = instance
    assert slave.getBoolean([vr["jump_sticks"]]) == [False]
    slave.setReal([vr["mu_s_spread"]], [0.3])
    slave.setBoolean([vr["jump_sticks"]], [True])
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    chain = Chain(16, jump_sticks=True, mu_s_spread=0.3)
    chain.start()
    outputs = [vr[f"x[{i}]"] for i in range(1, 17)]
    for t in (2000.0, 4000.0, 6000.0):
        slave.doStep(t - 2000.0, 2000.0)
        chain.advance_to(t)
    assert slave.getReal(outputs) == chain.x.tolist() and chain.jumped_steps > 0
    assert slave.getInteger([vr["event_count"]]) == [len(chain.events)]
    state = slave.serializeFMUstate(slave.getFMUstate())
    slave.doStep(6000.0, 6000.0)
    first = slave.getReal(outputs), slave.getInteger([vr["event_count"]])
    slave.setFMUstate(slave.deSerializeFMUstate(state))
    slave.doStep(6000.0, 6000.0)
    assert (slave.getReal(outputs), slave.getInteger([vr["event_count"]])) == first


def test_jump_sticks_with_the_energy_balance_gives_fmi2error(instance, fmu_log):
    slave, vr = instance
    slave.setBoolean([vr["jump_sticks"], vr["energy_balance"]], [True, True])
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    assert status_of(slave.exitInitializationMode) == fmi2Error
    assert any("jump_sticks with energy_balance" in record[3] for record in fmu_log.records)


def test_bad_settings_and_inputs_give_fmi2error_with_a_message(instance, fmu_log):
    slave, vr = instance
    slave.setReal([vr["v_stop"]], [1.0])  # above v_start = 0.3
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    assert status_of(slave.exitInitializationMode) == fmi2Error
    assert any("0 < v_stop <= v_start" in record[3] for record in fmu_log.records)
    slave.setReal([vr["v_stop"]], [0.1])
    slave.exitInitializationMode()
    assert status_of(lambda: slave.setReal([vr["plate_z"]], [float("nan")])) == fmi2Error
    assert status_of(lambda: slave.setReal([vr["k_c"]], [2.0])) == fmi2Error  # fixed once running
    assert do_step(slave, 0.0, 100.0) == 0  # the instance goes on


OTHER_CORE_SCRIPT = """
import sys
import vibroblock  # the process holds the checkout's core, as the harness's do
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi1 import FMICallException
other, folder = sys.argv[1], sys.argv[2]
md = read_model_description(other)
slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(other, unzipdir=folder),
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName="other")
slave.instantiate(loggingOn=True)
for name, call in (("setupExperiment", lambda: slave.setupExperiment(startTime=0.0)),
                   ("enterInitializationMode", slave.enterInitializationMode),
                   ("exitInitializationMode", slave.exitInitializationMode),
                   ("doStep", lambda: slave.doStep(0.0, 10.0))):
    try:
        call()
        print(name, "ok", flush=True)
    except FMICallException as exc:
        print(name, "refused, status", exc.status, flush=True)
slave.freeInstance()
print("process still alive", flush=True)
"""


def test_a_chain_fmu_of_another_core_than_the_process_holds_refuses_to_start(chain_fmu, tmp_path):
    """A process that imported the checkout's core (as the harness does) loads a
    BlockChain.fmu whose bundled core differs: the FMU says so in its log and refuses to
    initialize, rather than running the process's core under its own model description."""
    import os
    import subprocess
    import sys

    other = with_another_core(chain_fmu, tmp_path / "Other.fmu")
    done = subprocess.run([sys.executable, "-c", OTHER_CORE_SCRIPT, other, str(tmp_path / "other")],
                          env=dict(os.environ), capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "different vibroblock core" in done.stdout
    # No call runs the process's core in its place: initialization and steps are refused (fmi2Error).
    assert "exitInitializationMode refused, status 3" in done.stdout and "doStep refused, status 3" in done.stdout
    assert done.stdout.strip().endswith("process still alive")


def test_another_number_of_blocks_at_build_time(tmp_path):
    import build_fmus

    fmu = build_fmus.build("BlockChain", tmp_path, chain_blocks=3)
    result = simulate_fmu(str(fmu), stop_time=500.0, output_interval=50.0, start_values={"k_c": 0.0},
                          output=["x[1]", "x[3]"])
    names = {v.name for v in read_model_description(str(fmu)).modelVariables}
    assert "x[3]" in names and "x[4]" not in names
    single = Chain(1, k_c=0.0)  # uncoupled, uniform blocks: each is the one-block chain
    single.start()
    single.advance_to(500.0)
    assert result["x[3]"][-1] == result["x[1]"][-1] == single.x[0]


def test_libcosim_gives_fmpys_bits(chain_fmu, tmp_path):
    outputs = ["x[1]", "x[8]", "moment_rate", "event_count"]
    cosim = run_libcosim(chain_fmu, start_values=SETTINGS, stop_time=3000.0, step_size=50.0, outputs=outputs)
    fmpy = simulate_fmu(chain_fmu, stop_time=3000.0, output_interval=50.0, start_values=SETTINGS, output=outputs)
    for name in outputs:
        np.testing.assert_array_equal(np.asarray(cosim[name], dtype=float), fmpy[name].astype(float))


HORIZONTAL_DRIVE = {"A": 0.05, "omega": 0.3, "drive_angle": float(np.pi / 2)}


def _shaken_run(slave, vr, amplitude, step, stop=60.0):
    """Run the instance on a horizontally shaken plate (rk4): by its own drive at
    ``amplitude``, else (amplitude 0) by the inputs plate_x, plate_vx, plate_ax, the drive's
    values sampled at each communication point and held over the step.  Returns x[1],
    x[16], vx[16] at the communication points."""
    slave.setInteger([vr["plate_motion"], vr["integrator"]], [1, 1])
    slave.setReal([vr[name] for name in HORIZONTAL_DRIVE], [*HORIZONTAL_DRIVE.values()])
    slave.setReal([vr["A"]], [amplitude])
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    a, w = HORIZONTAL_DRIVE["A"], HORIZONTAL_DRIVE["omega"]
    rows, outputs = [], [vr["x[1]"], vr["x[16]"], vr["vx[16]"]]
    for t in np.arange(step, stop + step / 2, step):
        s = t - step
        if amplitude == 0.0:
            slave.setReal([vr["plate_x"], vr["plate_vx"], vr["plate_ax"]],
                          [a * np.sin(w * s), a * w * np.cos(w * s), -a * w * w * np.sin(w * s)])
        slave.doStep(s, step)
        rows.append(slave.getReal(outputs))
    return np.array(rows)


def _fresh(chain_fmu, unzipped, fmu_log):
    """A new instance from the FMU extracted once into ``unzipped`` (extracting again over
    the loaded binary would pull it from under the process)."""
    md = read_model_description(chain_fmu)
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="chain")
    slave.instantiate(callbacks=fmu_log.callbacks)
    return slave, {v.name: v.valueReference for v in md.modelVariables}


def test_the_horizontal_inputs_shake_the_chain_like_its_own_drive(chain_fmu, tmp_path, fmu_log):
    """plate_motion = 1 with drive_angle = pi/2 through fmpy: the inputs plate_x, plate_vx,
    plate_ax sampled from the drive and held over each communication step give the internal
    drive's run to ~A omega H / 2, halving with H (the held acceleration lags by half a
    step); and the FMU driven by the inputs is the core driven by them, to the bit."""
    errors, unzipped = [], extract(chain_fmu, unzipdir=str(tmp_path / "x"))
    for step in (0.1, 0.05):
        runs = []
        for amplitude in (HORIZONTAL_DRIVE["A"], 0.0):
            slave, vr = _fresh(chain_fmu, unzipped, fmu_log)
            runs.append(_shaken_run(slave, vr, amplitude, step))
            slave.terminate()
            slave.freeInstance()
        internal, driven = runs
        assert np.max(np.abs(internal[:, 1])) > 0.9 * HORIZONTAL_DRIVE["A"]  # the blocks travel with the plate
        errors.append(np.max(np.abs(driven - internal)))
        assert errors[-1] < HORIZONTAL_DRIVE["A"] * HORIZONTAL_DRIVE["omega"] * step / 2
    assert 1.6 < errors[0] / errors[1] < 2.4
    a, w, step = HORIZONTAL_DRIVE["A"], HORIZONTAL_DRIVE["omega"], 0.05
    chain = Chain(16, integrator="rk4", plate_motion="oblique", **{**HORIZONTAL_DRIVE, "A": 0.0})
    chain.start()
    for t in np.arange(step, 60.0 + step / 2, step):
        s = t - step
        chain.set_plate_input(0.0, 0.0, 0.0, a * np.sin(w * s), a * w * np.cos(w * s), -a * w * w * np.sin(w * s))
        chain.advance_to(chain.time + step)  # (the FMU's doStep ends at its time + the step)
    assert [chain.x[0], chain.x[15], chain.vx[15]] == driven[-1].tolist()


def test_plate_motion_is_named_in_the_model_description_as_the_block_fmus_name_it(chain_fmu):
    """Masters that set an Integer switch by name (``harness.cosim``, libcosim) read the
    names from the description: the chain's are the single block's."""
    from harness.cosim.fmu import FmuInterface

    described = {v.name: v.description for v in read_model_description(chain_fmu).modelVariables}
    assert FmuInterface.parse_choices(described["plate_motion"]) == {"vertical": 0, "oblique": 1}
    assert "drive_angle" in described and {"plate_x", "plate_vx", "plate_ax", "plate_z"} <= set(described)


def test_bad_plate_motion_settings_give_fmi2error_and_the_instance_goes_on(instance, fmu_log):
    slave, vr = instance
    assert status_of(lambda: slave.setReal([vr["drive_angle"]], [float("nan")])) == fmi2Error
    assert any("drive_angle = nan" in record[3] for record in fmu_log.records)
    assert status_of(lambda: slave.setInteger([vr["plate_motion"]], [7])) == fmi2Error
    assert any("plate_motion = 7" in record[3] for record in fmu_log.records)
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()  # the vertical plate of before
    slave.setReal([vr["plate_x"]], [0.1])
    assert do_step(slave, 0.0, 100.0) == fmi2Error
    assert any("plate_motion = 1" in record[3] for record in fmu_log.records)
    assert status_of(lambda: slave.setInteger([vr["plate_motion"]], [1])) == fmi2Error  # fixed once running
    slave.setReal([vr["plate_x"]], [0.0])
    assert do_step(slave, 0.0, 100.0) == 0  # the instance goes on
