"""BlockChain3.fmu (FMI 3.0) as fmpy's FMI 3 co-simulation sees it: BlockChain.fmu's bits
for the same settings and inputs, N as a structural parameter sizing x and vx, refused
settings, FMU state."""
from __future__ import annotations

import math

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave, fmi3Error

from fmu_testing import status_of
from vibroblock import layout as L
from vibroblock.chain import Chain

SETTINGS = {"mu_s_spread": 0.3, "seed": 4, "A": 0.05, "omega": 1.3, "k_c": 0.8}
STEP, STEPS = 100.0, 100


def plate(t: float) -> dict:
    """A plate motion fed through the inputs, the same for both FMUs."""
    return {"plate_z": 0.02 * math.sin(0.01 * t), "plate_v": 2e-4 * math.cos(0.01 * t),
            "plate_a": -2e-6 * math.sin(0.01 * t)}


class Fmi3Chain:
    """One BlockChain3 instance through fmpy's low-level FMI 3 interface, its log kept."""

    def __init__(self, fmu: str, folder: str):
        self.model_description = read_model_description(fmu)
        self.vr = {v.name: v.valueReference for v in self.model_description.modelVariables}
        self.log = []
        described = self.model_description
        self.slave = FMU3Slave(guid=described.guid, unzipDirectory=extract(fmu, unzipdir=folder),
                               modelIdentifier=described.coSimulation.modelIdentifier, instanceName="chain3")
        self.slave.instantiate(logMessage=self._log)

    def _log(self, environment, status, category, message):
        self.log.append((status, message.decode()))

    def configure(self, n_blocks: int) -> None:
        """Set N in configuration mode (fmpy raises for a call that does not return fmi3OK)."""
        self.slave.enterConfigurationMode()
        self.slave.setUInt64([self.vr["N"]], [n_blocks])
        self.slave.exitConfigurationMode()

    def set(self, values: dict) -> None:
        for name, value in values.items():
            kind = next(v.type for v in self.model_description.modelVariables if v.name == name)
            {"Float64": self.slave.setFloat64, "Int32": self.slave.setInt32}[kind]([self.vr[name]], [value])

    def initialize(self) -> None:
        self.slave.enterInitializationMode()
        self.slave.exitInitializationMode()

    def blocks(self, name: str) -> list:
        n_blocks = self.slave.getUInt64([self.vr["N"]])[0]
        return self.slave.getFloat64([self.vr[name]], n_blocks)

    def close(self) -> None:
        self.slave.terminate()
        self.slave.freeInstance()


@pytest.fixture
def chain3(fmu_dir, tmp_path):
    instance = Fmi3Chain(str(fmu_dir / "BlockChain3.fmu"), str(tmp_path / "x3"))
    yield instance
    instance.close()


def fmi2_run(fmu: str, folder: str, settings: dict) -> list:
    """BlockChain.fmu (16 blocks) under ``plate``: x[i], vx[i] and event_count at each point."""
    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu, unzipdir=folder),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="chain2")
    slave.instantiate()
    for name, value in settings.items():
        (slave.setInteger if name == "integrator" else slave.setReal)([vr[name]], [value])
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    points = []
    for k in range(STEPS):
        slave.setReal([vr[name] for name in plate(k * STEP)], list(plate(k * STEP).values()))
        slave.doStep(k * STEP, STEP)
        points.append((slave.getReal([vr[f"x[{i}]"] for i in range(1, 17)]),
                       slave.getReal([vr[f"vx[{i}]"] for i in range(1, 17)]), slave.getInteger([vr["event_count"]])))
    slave.terminate()
    slave.freeInstance()
    return points


def test_model_description_declares_x_and_vx_as_arrays_sized_by_n(fmu_dir):
    from fmpy.validation import validate_fmu

    fmu = str(fmu_dir / "BlockChain3.fmu")
    assert validate_fmu(fmu) == []
    variables = {v.name: v for v in read_model_description(fmu).modelVariables}
    size = variables["N"]
    assert size.causality == "structuralParameter" and size.type == "UInt64" and int(size.start) == 16
    for name in ("x", "vx"):
        assert [d.variable for d in variables[name].dimensions] == [size]
    assert "x[1]" not in variables


@pytest.mark.parametrize("integrator", [0, 1], ids=["symplectic_euler", "rk4"])
def test_x_vx_and_events_are_blockchains_bits(chain3, fmu_dir, tmp_path, integrator):
    settings = {**SETTINGS, "integrator": integrator}
    reference = fmi2_run(str(fmu_dir / "BlockChain.fmu"), str(tmp_path / "x2"), settings)
    chain3.set(settings)
    chain3.initialize()
    vr = chain3.vr
    for k, (x, vx, events) in enumerate(reference):
        chain3.slave.setFloat64([vr[name] for name in plate(k * STEP)], list(plate(k * STEP).values()))
        assert chain3.slave.doStep(k * STEP, STEP)[0] is False  # no event handling, no termination
        assert (chain3.blocks("x"), chain3.blocks("vx")) == (x, vx)
        assert chain3.slave.getInt32([vr["event_count"]]) == events
    assert reference[-1][2][0] > 0 and len(set(reference[-1][0])) == 16  # events, and the blocks differ


def test_structural_parameter_n_sizes_the_arrays(chain3):
    chain3.configure(3)
    chain3.set({"k_c": 0.0})  # uncoupled uniform blocks: each is the one-block chain
    chain3.initialize()
    chain3.slave.doStep(0.0, 500.0)
    single = Chain(1, k_c=0.0)
    single.start()
    single.advance_to(500.0)
    assert chain3.slave.getUInt64([chain3.vr["N"]]) == [3] and chain3.log == []
    assert chain3.blocks("x") == [single.x[0]] * 3
    assert chain3.blocks("vx") == [float(single.Y[0, L.Y_VX])] * 3


def test_n_set_after_other_settings_keeps_them(chain3):
    chain3.set({"k_c": 0.25})
    chain3.configure(5)
    assert chain3.slave.getFloat64([chain3.vr["k_c"]]) == [0.25]
    assert len(chain3.blocks("x")) == 5


@pytest.mark.parametrize("request_, message", [
    ({"N": 0}, "a chain has 1 to 10000 blocks"),
    ({"v_stop": 1.0}, "0 < v_stop <= v_start"),
], ids=["N", "v_stop"])
def test_a_refused_setting_is_logged_as_error_and_no_step_runs(chain3, request_, message):
    if "N" in request_:
        chain3.configure(request_["N"])
        assert chain3.slave.getUInt64([chain3.vr["N"]]) == [16]  # the last good value
    else:
        chain3.set(request_)
    chain3.initialize()
    assert any(status == fmi3Error and message in text for status, text in chain3.log)
    assert status_of(lambda: chain3.slave.doStep(0.0, 10.0)) == fmi3Error
    assert any(status == fmi3Error and "doStep before a successful initialization" in text
               for status, text in chain3.log)


def test_a_refused_step_returns_fmi3error_and_the_instance_goes_on(chain3):
    chain3.initialize()
    assert status_of(lambda: chain3.slave.doStep(5.0, 10.0)) == fmi3Error  # not the FMU's time
    assert status_of(lambda: chain3.slave.doStep(0.0, -1.0)) == fmi3Error
    assert any("differs from the FMU's time" in text for _, text in chain3.log)
    assert chain3.slave.doStep(0.0, 10.0)[0] is False
    assert chain3.slave.getFloat64([chain3.vr["time"]]) == [10.0]
    chain3.slave.setUInt64([chain3.vr["N"]], [4])  # fixed once running
    assert chain3.slave.getUInt64([chain3.vr["N"]]) == [16] and len(chain3.blocks("x")) == 16
    assert any(status == fmi3Error and "N cannot change during a run" in text for status, text in chain3.log)
    assert chain3.slave.doStep(10.0, 10.0)[0] is False


@pytest.mark.parametrize("serialized", [False, True])
def test_fmu_state_restores_the_run_bit_for_bit(chain3, serialized):
    chain3.configure(7)
    chain3.set({"mu_s_spread": 0.3, "integrator": 1})
    chain3.initialize()
    chain3.slave.doStep(0.0, 2000.0)
    state = chain3.slave.getFMUState()
    if serialized:
        state = chain3.slave.deserializeFMUState(chain3.slave.serializeFMUState(state))
    chain3.slave.doStep(2000.0, 3000.0)
    first = chain3.blocks("x"), chain3.blocks("vx"), chain3.slave.getInt32([chain3.vr["event_count"]])
    chain3.slave.setFMUState(state)
    chain3.slave.doStep(2000.0, 3000.0)
    assert (chain3.blocks("x"), chain3.blocks("vx"), chain3.slave.getInt32([chain3.vr["event_count"]])) == first
    assert first[2][0] > 0 and len(first[0]) == 7


def test_simulate_fmu_records_the_arrays_as_blockchains_scalars(fmu_dir):
    from fmpy import simulate_fmu

    grid = {"stop_time": 3000.0, "output_interval": 50.0, "start_values": SETTINGS}
    fmi3 = simulate_fmu(str(fmu_dir / "BlockChain3.fmu"), output=["x", "vx"], **grid)
    fmi2 = simulate_fmu(str(fmu_dir / "BlockChain.fmu"), output=[f"{name}[{i}]" for name in ("x", "vx")
                                                                  for i in range(1, 17)], **grid)
    for name in ("x", "vx"):
        assert fmi3[name].shape == (len(fmi2), 16)
        for i in range(16):
            assert fmi3[name][:, i].tolist() == fmi2[f"{name}[{i + 1}]"].tolist()


def test_simulate_fmu_sets_n_and_the_aggregates_follow(fmu_dir):
    """fmpy sizes recorded arrays by N's start (16), so with another N only scalars are recorded."""
    from fmpy import simulate_fmu

    result = simulate_fmu(str(fmu_dir / "BlockChain3.fmu"), stop_time=500.0, output_interval=50.0,
                          start_values={"N": 3, "k_c": 0.0}, output=["moment_rate", "mean_slip_velocity"])
    single = Chain(1, k_c=0.0)
    single.start()
    single.advance_to(500.0)
    three = np.full(3, single.Y[0, L.Y_VX])  # three uncoupled uniform blocks: the single block thrice
    assert result["moment_rate"][-1] == np.sum(three) != 0.0 and result["mean_slip_velocity"][-1] == np.mean(three)


def test_the_libcosim_runner_refuses_fmi3_before_libcosim_sees_it(fmu_dir):
    """libcosim 0.11 (libcosimpy 0.0.6) is FMI 2.0 only and dies loading an FMI 3.0 FMU."""
    from harness.cosim.masters import SetupError, run_libcosim

    with pytest.raises(SetupError, match="not an FMI 2.0 co-simulation FMU"):
        run_libcosim(fmu_dir / "BlockChain3.fmu", stop_time=100.0, step_size=50.0, outputs=["event_count"])
