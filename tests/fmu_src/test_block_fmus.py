"""BlockA/B/C.fmu as an FMI 2.0 master sees them: validation, equality with the core,
communication-step independence, FMU state, bad input, and a second master."""
from __future__ import annotations

import contextlib
import math

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave, fmi2Error, fmi2Integer, fmi2LastSuccessfulTime, fmi2OK, fmi2ValueReference
from fmpy.validation import validate_fmu

from fmu_testing import do_step, fmu_log, set_real, status_of  # noqa: F401 (fixture)
from vibroblock import Block
from vibroblock.parameters import DEFAULT_INTEGRATOR

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
OUTPUTS = ["x", "z", "vx", "vz", "friction_force", "normal_force", "phi_integral", "penetration", "surface_z"]


@pytest.fixture(scope="module")
def extracted(fmu_path, tmp_path_factory):
    root = tmp_path_factory.mktemp("extracted")
    return {m: (read_model_description(fmu_path(m)), extract(fmu_path(m), unzipdir=str(root / m))) for m in "ABC"}


@contextlib.contextmanager
def instance(extracted, model, log, start_values=None, name="block"):
    # These checks were written for the paper's fixed-step scheme (bit-for-bit splits, dt
    # limits, the blow-up guard); the FMUs default to adaptive since, so they ask for it.
    start_values = {"integrator": 0, **(start_values or {})}
    md, unzipdir = extracted[model]
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName=name)
    slave.instantiate(callbacks=log.callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        for key, value in (start_values or {}).items():
            if isinstance(value, bool):
                slave.setBoolean([vr[key]], [value])
            elif isinstance(value, int):
                slave.setInteger([vr[key]], [value])
            else:
                slave.setReal([vr[key]], [value])
        slave.exitInitializationMode()
        yield slave, vr
    finally:
        slave.freeInstance()


def reals(slave, vr, names=OUTPUTS):
    return slave.getReal([vr[n] for n in names])


def every_kind(slave, vr):
    """The Real OUTPUTS, then contact (Boolean) and slip_count (Integer), as floats."""
    return [*reals(slave, vr), float(slave.getBoolean([vr["contact"]])[0]),
            float(slave.getInteger([vr["slip_count"]])[0])]


@pytest.mark.parametrize("model", "ABC")
def test_fmpy_validation_reports_nothing(fmu_path, model):
    assert validate_fmu(fmu_path(model)) == []
    md = read_model_description(fmu_path(model))
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    names = {v.name for v in md.modelVariables}
    required = {"m", "k_n", "k_t", "gamma_n", "gamma_t", "mu_s", "k_d", "V_d", "A", "omega", "dt",
                "plate_z", "plate_v", "plate_a", "x", "z", "vx", "vz", "friction_force", "normal_force",
                "contact", "slip_count", "phi_integral"}
    assert required <= names
    tunable = {v.name for v in md.modelVariables if v.variability == "tunable"}
    assert tunable == {"A", "omega"}


@pytest.mark.parametrize("model", "ABC")
@pytest.mark.parametrize("integrator", [None, 0])
def test_simulate_fmu_equals_the_core(fmu_path, model, integrator):
    """With the FMU's default integrator (adaptive, which the master does not set) and with
    the paper's scheme (0, set)."""
    settings = dict(SCALED, A=0.5, omega=0.9)
    chosen = {} if integrator is None else {"integrator": integrator}
    result = simulate_fmu(fmu_path(model), stop_time=200.0, output_interval=0.5,
                          start_values={**settings, "initial_state": 2, **chosen})
    block = Block(model, DEFAULT_INTEGRATOR if integrator is None else integrator, initial_state=2, **settings)
    block.start()
    expected = [block.outputs()]
    for t in result["time"][1:]:
        block.advance_to(t)
        expected.append(block.outputs())
    for name in OUTPUTS + ["contact", "coulomb_resets", "slip_count"]:
        np.testing.assert_array_equal(result[name], [row[name] for row in expected], err_msg=name)
    np.testing.assert_array_equal(result["slip_count"], result["coulomb_resets"])  # the old name, one release


COST_OUTPUTS = {"accepted_steps": "accepted", "rejected_steps": "rejected", "located_events": "events",
                "jacobian_evaluations": "jacobians", "periods_jumped": "periods_jumped"}
CREST_X = 0.5 * math.pi / 0.02  # a crest of the paper's corrugation (slope 0)
VALLEY_X = (-0.5 * math.pi + 0.005) / 0.02  # slope 0.1 near a valley


def cost_run(fmu_path, model, settings, start_time, stops):
    """The cost outputs read through the FMU after each stop, and the core's counters after
    the same advances."""
    from harness.cosim.fmu import FmuInstance
    names = list(COST_OUTPUTS)
    with FmuInstance(fmu_path(model)) as fmu:
        fmu.start(settings, start_time)
        read = fmu.reader(names)
        got, t = [], start_time
        for stop in stops:
            fmu.do_step(t, stop - t)
            t = stop
            got.append(dict(zip(names, read())))
    block = Block(model, **settings)
    block.start(start_time)
    expected = []
    for stop in stops:
        block.advance_to(stop)
        expected.append({name: float(block.counters[key]) for name, key in COST_OUTPUTS.items()})
    return got, expected


def test_the_fmus_report_what_the_adaptive_integrator_counted(fmu_path):
    # Coulomb resets from the start (the drive spring stretched by 40): events, rejections.
    resets = dict(SCALED, integrator=4, rtol=1e-6, atol=1e-8, dt=1e-2, initial_state=0, x_start=VALLEY_X - 40.0)
    got, expected = cost_run(fmu_path, "B", resets, 0.0, [50.0, 150.0])
    assert got == expected
    assert all(got[-1][name] > got[0][name] > 0 for name in ("accepted_steps", "rejected_steps", "located_events"))
    assert got[-1]["jacobian_evaluations"] >= 1 and got[-1]["periods_jumped"] == 0
    # Held at a crest at the paper's parameters on a plate vibrated at a third of the onset:
    # its periods crossed by stroboscopic jumps.
    from vibroblock import detachment_amplitude
    omega = 0.316
    held = dict(integrator=4, rtol=1e-6, atol=1e-8, dt=1.0, initial_state=2, formulation=1, x_start=CREST_X,
                omega=omega, A=float(detachment_amplitude(omega, m=1.0, g=1.0, k_n=1.0, gamma_n=0.07)) / 3.0)
    t0 = CREST_X / 2e-4  # the drive spring relaxed (the paper's V_d)
    got, expected = cost_run(fmu_path, "C", held, t0, [t0 + 2e4])
    assert got == expected
    assert got[0]["periods_jumped"] > 500 and got[0]["located_events"] == 0
    # The fixed-step integrators count nothing of this.
    got, _ = cost_run(fmu_path, "B", dict(resets, integrator=0, dt=1e-3), 0.0, [50.0])
    assert set(got[0].values()) == {0.0}


def test_block_a_takes_exact_flows_with_adaptive_unless_told_otherwise(fmu_path):
    """Only BlockA offers exact_flows.  On (the default) its adaptive run is event_driven's:
    the same outputs bit for bit, no steps, the events counted; off, adaptive's own steps,
    which agree with it to the tolerance."""
    for model in "ABC":
        names = {v.name for v in read_model_description(fmu_path(model)).modelVariables}
        assert ("exact_flows" in names) == (model == "A"), model
    stick_slip = dict(SCALED, rtol=1e-10, atol=1e-12, dt=1e-2, initial_state=0, x_start=-40.0)
    results = ["x", "z", "vx", "phi_integral", "slip_count"]
    runs = {name: simulate_fmu(fmu_path("A"), stop_time=300.0, output_interval=100.0, start_values=settings,
                               output=results + list(COST_OUTPUTS))
            for name, settings in (("exact", dict(stick_slip, integrator=4)),
                                   ("event_driven", dict(stick_slip, integrator=2)),
                                   ("steps", dict(stick_slip, integrator=4, exact_flows=False)))}
    exact, event_driven, steps = runs["exact"][-1], runs["event_driven"][-1], runs["steps"][-1]
    assert [exact[name] for name in results] == [event_driven[name] for name in results]
    assert exact["accepted_steps"] == exact["jacobian_evaluations"] == 0
    assert exact["located_events"] == event_driven["located_events"] == exact["slip_count"] > 0
    assert steps["accepted_steps"] > 100 and steps["slip_count"] == exact["slip_count"]
    for name in ("x", "vx", "phi_integral"):
        assert abs(steps[name] - exact[name]) < 1e-8 * max(1.0, abs(exact[name])), name


@pytest.mark.parametrize("model", "ABC")
def test_the_default_integrator_is_adaptive_and_says_so(fmu_path, model):
    md = read_model_description(fmu_path(model))
    variable = next(v for v in md.modelVariables if v.name == "integrator")
    assert variable.start == "4" and "default 4 = adaptive on every model" in variable.description
    outputs = {v.name: v for v in md.modelVariables if v.causality == "output"}
    assert outputs["coulomb_resets"].type == outputs["slip_count"].type == "Integer"
    assert "old name of coulomb_resets" in outputs["slip_count"].description


def test_communication_step_does_not_change_the_trajectory(fmu_path):
    # The fixed-step schemes' promise (their grid t0 + n dt); bouncing: chaotic, a strict check.
    settings = {**SCALED, "A": 1.2, "omega": 1.1, "initial_state": 2, "integrator": 0}
    runs = {h: simulate_fmu(fmu_path("A"), stop_time=300.0, output_interval=h, start_values=settings)
            for h in (0.01, 0.75, 300.0)}
    for h in (0.01, 0.75):
        at_end = runs[h][-1]
        for name in OUTPUTS:
            assert at_end[name] == runs[300.0][-1][name], (h, name)
    # a coarse grid's samples lie on the fine one
    fine = runs[0.01][::75]
    for name in OUTPUTS:
        np.testing.assert_array_equal(fine[name], runs[0.75][name])


@pytest.mark.parametrize("model", "AC")
def test_saved_state_restores_bit_for_bit_also_in_a_new_instance(extracted, fmu_log, model):
    settings = {**SCALED, "A": 0.8, "omega": 1.3, "initial_state": 2}
    with instance(extracted, model, fmu_log, settings) as (slave, vr):
        t = 0.0
        for _ in range(20):
            slave.doStep(t, 0.7)
            t += 0.7
        state = slave.getFMUstate()
        serialized = slave.serializeFMUstate(state)
        saved_t = t
        for _ in range(30):
            slave.doStep(t, 0.7)
            t += 0.7
        reference = reals(slave, vr) + [slave.getInteger([vr["slip_count"]])[0]]
        slave.setFMUstate(state)
        t = saved_t
        for _ in range(30):
            slave.doStep(t, 0.7)
            t += 0.7
        assert reals(slave, vr) + [slave.getInteger([vr["slip_count"]])[0]] == reference
        slave.freeFMUstate(state)
    with instance(extracted, model, fmu_log, name="fresh") as (fresh, vr):
        fresh.setFMUstate(fresh.deSerializeFMUstate(serialized))
        t = saved_t
        for _ in range(30):
            fresh.doStep(t, 0.7)
            t += 0.7
        assert reals(fresh, vr) + [fresh.getInteger([vr["slip_count"]])[0]] == reference


def test_tunable_drive_changes_during_a_run(extracted, fmu_log):
    with instance(extracted, "A", fmu_log, {"initial_state": 2}) as (slave, vr):
        slave.doStep(0.0, 10.0)
        assert slave.getReal([vr["surface_z"]])[0] == 0.0
        slave.setReal([vr["A"], vr["omega"]], [0.2, 0.5])
        slave.doStep(10.0, 3.0)
        assert slave.getReal([vr["surface_z"]])[0] == pytest.approx(0.2 * math.sin(0.5 * 3.0), abs=1e-12)


def test_external_input_adds_to_the_drive_and_is_held_at_constant_acceleration(extracted, fmu_log):
    """Feeding the harmonic plate motion through the inputs at each communication point
    approaches the internal drive as the communication step shrinks (O(h^3) per step).
    The plate height under the block (model A) depends on the plate motion only."""
    amplitude, omega = 0.3, 0.8

    def run(h, external):
        start = {} if external else {"A": amplitude, "omega": omega}
        with instance(extracted, "A", fmu_log, start) as (slave, vr):
            t, zs = 0.0, []
            for _ in range(int(round(20.0 / h))):
                if external:
                    slave.setReal([vr["plate_z"], vr["plate_v"], vr["plate_a"]],
                                  [amplitude * math.sin(omega * t), amplitude * omega * math.cos(omega * t),
                                   -amplitude * omega**2 * math.sin(omega * t)])
                slave.doStep(t, h)
                t += h
                zs.append(slave.getReal([vr["surface_z"]])[0])
            return np.array(zs)

    internal = run(0.5, external=False)
    errors = [np.max(np.abs(run(h, external=True)[int(round(0.5 / h)) - 1::int(round(0.5 / h))] - internal))
              for h in (0.5, 0.25)]
    assert errors[1] < errors[0] / 6  # third order per step: factor 8 expected
    assert errors[1] < 2e-3


def bad_parameter_cases():
    yield from [("m", -1.0), ("m", math.nan), ("k_n", -1.0), ("k_t", math.inf), ("gamma_n", -0.1),
                ("gamma_t", -1.0), ("mu_s", -0.5), ("dt", 0.0), ("dt", -4e-4), ("V_d", math.nan),
                ("plate_z", math.nan), ("plate_a", math.inf)]


@pytest.mark.parametrize("name, value", list(bad_parameter_cases()))
def test_bad_values_give_fmi2error_with_a_message_and_keep_the_state(extracted, fmu_log, name, value):
    with instance(extracted, "A", fmu_log, dict(SCALED)) as (slave, vr):
        slave.doStep(0.0, 5.0)
        before = reals(slave, vr)
        fmu_log.clear()
        assert set_real(slave, vr[name], value) == fmi2Error
        assert any(status == fmi2Error and name in message for _, status, _, message in fmu_log.records)
        assert reals(slave, vr) == before
        assert do_step(slave, 5.0, 5.0) == fmi2OK  # the instance goes on from its last good state


@pytest.mark.parametrize("h", [0.0, -1.0, math.nan, math.inf])
def test_bad_step_sizes_give_fmi2error(extracted, fmu_log, h):
    with instance(extracted, "B", fmu_log) as (slave, vr):
        slave.doStep(0.0, 1.0)
        before = reals(slave, vr)
        fmu_log.clear()
        assert do_step(slave, 1.0, h) == fmi2Error
        assert any("step size" in message for *_, message in fmu_log.records)
        assert reals(slave, vr) == before
        assert do_step(slave, 1.0, 1.0) == fmi2OK


def test_a_wrong_communication_point_gives_fmi2error(extracted, fmu_log):
    with instance(extracted, "C", fmu_log) as (slave, vr):
        slave.doStep(0.0, 1.0)
        assert do_step(slave, 0.5, 1.0) == fmi2Error
        assert any("differs from the FMU's time" in message for *_, message in fmu_log.records)


def test_do_step_goes_straight_to_the_slave_with_pythonfmus_bookkeeping(extracted, fmu_log):
    """The native front end calls the facade's do_step itself, not through pythonfmu
    (build/python_runtime.c): a refused step's message arrives once, with fmi2Error; the
    last successful time is the end of the last step taken (pythonfmu's doStep would
    record a refused step's start, so this also shows which way the steps went); after
    fmi2Reset the new slave is the one stepped."""
    # (the paper's scheme: its grid makes the replay after fmi2Reset bit for bit; the default,
    # adaptive, takes model A's exact flows, whose located events agree to their tolerance)
    with instance(extracted, "A", fmu_log, {"A": 0.4, "omega": 0.9, "integrator": 0}) as (slave, vr):
        assert do_step(slave, 0.0, 1.0) == fmi2OK
        assert slave.getRealStatus(fmi2LastSuccessfulTime) == 1.0
        fmu_log.clear()
        assert do_step(slave, 5.0, 1.0) == fmi2Error
        assert [(status, "differs from the FMU's time" in message) for _, status, _, message in fmu_log.records] \
            == [(fmi2Error, True)]
        assert slave.getRealStatus(fmi2LastSuccessfulTime) == 1.0
        fmu_log.clear()
        first = reals(slave, vr)  # a call through pythonfmu: the message is not passed on again
        assert do_step(slave, 1.0, 1.0) == fmi2OK and fmu_log.records == []
        after_two = reals(slave, vr)

        slave.reset()
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setReal([vr["A"], vr["omega"]], [0.4, 0.9])
        slave.setInteger([vr["integrator"]], [0])
        slave.exitInitializationMode()
        assert do_step(slave, 0.0, 1.0) == fmi2OK and reals(slave, vr) == first
        assert do_step(slave, 1.0, 1.0) == fmi2OK and reals(slave, vr) == after_two
        assert slave.getRealStatus(fmi2LastSuccessfulTime) == 2.0


def test_do_steps_through_pythonfmu_give_the_same_bits(extracted, fmu_log, monkeypatch):
    """VIBROBLOCK_PYTHONFMU_DOSTEP=1 leaves doStep to pythonfmu (for comparison): same bits."""
    runs = []
    for through_pythonfmu in (False, True):
        if through_pythonfmu:
            monkeypatch.setenv("VIBROBLOCK_PYTHONFMU_DOSTEP", "1")
        with instance(extracted, "A", fmu_log, {"A": 0.8, "omega": 0.7, "initial_state": 2}) as (slave, vr):
            rows = []
            for k in range(40):
                assert do_step(slave, k * 0.5, 0.5) == fmi2OK
                rows.append(reals(slave, vr))
            runs.append(np.array(rows))
    assert runs[0].tobytes() == runs[1].tobytes()
    assert np.ptp(runs[0][:, 1]) > 1e-3  # z moves: the run exercises the block


NATIVE_CASES = [
    ("A", {"A": 0.8, "omega": 0.7, "initial_state": 2}),
    ("A", {"A": 0.02, "omega": 0.5, "frozen_vertical": True}),  # A = 6 at step 40: the guard hands over
    ("A", {**SCALED, "A": 0.8, "omega": 0.7, "initial_state": 2, "integrator": 4}),  # adaptive's exact flows
    ("B", {**SCALED, "A": 0.2, "omega": 0.7, "integrator": 4, "formulation": 1}),
    ("C", {**SCALED, "A": 0.3, "omega": 0.85, "integrator": 3}),
]


def scripted_run(extracted, log, model, settings):
    """60 doSteps of 0.5 with a plate input set before every tenth, a refused doStep, and
    an FMU state restored: (outputs after each step, time of each doStep Python ran,
    names of the outputs Python read)."""
    from vibroblock import slave as slave_module

    python_steps, python_reads = [], []
    original, original_output = slave_module.BlockFacade.do_step, slave_module.BlockFacade._output

    def counted(self, t, h):
        python_steps.append(t)
        return original(self, t, h)

    def counted_output(self, name):
        python_reads.append(name)
        return original_output(self, name)

    rows = []
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(slave_module.BlockFacade, "do_step", counted)
        patch.setattr(slave_module.BlockFacade, "_output", counted_output)
        with instance(extracted, model, log, settings) as (slave, vr):
            t = 0.0
            for k in range(60):
                if k % 10 == 5:
                    assert set_real(slave, vr["plate_z"], 1e-3 * k) == fmi2OK
                if k == 40 and settings.get("frozen_vertical"):
                    assert set_real(slave, vr["A"], 6.0) == fmi2OK  # A omega^2 = 1.5 g
                if k == 30:
                    saved, saved_at = slave.getFMUstate(), t
                    assert do_step(slave, t + 3.0, 0.5) == fmi2Error  # not the FMU's time
                assert do_step(slave, t, 0.5) == fmi2OK
                t += 0.5
                rows.append(every_kind(slave, vr))
            slave.setFMUstate(saved)
            for t in saved_at + 0.5 * np.arange(10):
                assert do_step(slave, t, 0.5) == fmi2OK
                rows.append(every_kind(slave, vr))
            slave.freeFMUstate(saved)
    return np.array(rows), python_steps, python_reads


@pytest.mark.parametrize("model, settings", NATIVE_CASES)
def test_plain_do_steps_run_without_python_and_give_the_same_bits(extracted, fmu_log, monkeypatch, model,
                                                                    settings):
    """The front end runs a plain doStep through the Block's NativeStep record
    (vibroblock/native.py), with no Python call; a doStep after a new input, a refused
    one and the one where frozen_vertical's guard hands over go to the slave's do_step.
    The outputs read after each step (Real, Boolean and Integer) come from the record's
    observation without Python; in a reading other than the model's own (B here: the
    tangent frame) Python converts the block's height and velocities and the surface
    under it, so a Real read that asks for any of them goes to Python whole.  Left to
    pythonfmu (every doStep and read a Python call) the run has the same bits."""
    native, python_steps, python_reads = scripted_run(extracted, fmu_log, model, settings)
    monkeypatch.setenv("VIBROBLOCK_PYTHONFMU_DOSTEP", "1")
    through_python, every_step, every_read = scripted_run(extracted, fmu_log, model, settings)
    assert native.tobytes() == through_python.tobytes()
    assert len(every_step) == 71 and len(every_read) == 70 * (len(OUTPUTS) + 2)
    assert python_reads == ([n for n in every_read if n in OUTPUTS] if settings.get("formulation") else [])
    inputs = [0.5 * k for k in range(5, 60, 10)]
    refused = 18.0
    handover = set(python_steps) - {*inputs, refused}
    assert [t for t in python_steps if t not in handover] == [*inputs[:3], refused, *inputs[3:]]
    assert len(handover) == (1 if settings.get("frozen_vertical") else 0)
    assert np.ptp(native[:, 1]) > 1e-4  # z moves: the run exercises the block


def test_a_retune_that_ends_adaptives_exact_flows_goes_on_by_its_own_steps(extracted, fmu_log):
    """BlockA, adaptive, undamped contact: exact flows while the drive is off resonance; set
    onto it during the run, the doSteps go on by adaptive's own steps (event_driven has no
    closed form there), with the core's bits after every doStep."""
    settings = {**SCALED, "gamma_n": 0.0, "A": 0.05, "omega": 0.8, "integrator": 4, "rtol": 1e-10, "atol": 1e-12}
    core = Block("A", **settings)
    core.start()
    with instance(extracted, "A", fmu_log, settings) as (slave, vr):
        t = 0.0
        for k in range(40):
            if k == 20:
                assert slave.getInteger([vr["accepted_steps"]])[0] == 0
                assert set_real(slave, vr["omega"], 1.0) == fmi2OK
                core.set_parameter("omega", 1.0)
            assert do_step(slave, t, 2.5) == fmi2OK
            t += 2.5
            core.advance_to(t)
            assert reals(slave, vr) == [core.output(name) for name in OUTPUTS], k
        assert slave.getInteger([vr["accepted_steps"]])[0] == core.counters["accepted"] > 0


def test_fixed_parameters_cannot_change_during_a_run(extracted, fmu_log):
    with instance(extracted, "A", fmu_log) as (slave, vr):
        slave.doStep(0.0, 1.0)
        assert set_real(slave, vr["m"], 2.0) == fmi2Error
        assert slave.getReal([vr["m"]]) == [1.0]


def test_an_unstable_dt_is_refused_at_initialization(extracted, fmu_log):
    md, unzipdir = extracted["A"]
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="BlockA", instanceName="stiff")
    slave.instantiate(callbacks=fmu_log.callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setInteger([vr["integrator"]], [0])  # the fixed-step scheme's stability limit (adaptive has none)
        slave.setReal([vr["k_n"]], [1e8])
        assert status_of(lambda: slave.fmi2ExitInitializationMode(slave.component)) == fmi2Error
        assert any("use dt <=" in message for *_, message in fmu_log.records)
        assert do_step(slave, 0.0, 1.0) == fmi2Error  # not initialized: refused, no crash
    finally:
        slave.freeInstance()


def test_a_blow_up_is_an_error_not_a_nan(extracted, fmu_log):
    with instance(extracted, "A", fmu_log, {"k_d": 10.0, "V_d": 1e308}) as (slave, vr):
        assert do_step(slave, 0.0, 10.0) == fmi2Error
        assert any("non-finite" in message for *_, message in fmu_log.records)
        assert all(math.isfinite(v) for v in reals(slave, vr))


def test_two_instances_in_one_process_are_independent(extracted, fmu_log):
    with instance(extracted, "A", fmu_log, {"A": 0.3, "omega": 0.9, "initial_state": 2}, name="one") as (a, vr), \
         instance(extracted, "A", fmu_log, {"A": 1.5, "omega": 1.1, "initial_state": 2}, name="two") as (b, _):
        for k in range(50):
            a.doStep(k * 1.0, 1.0)
            b.doStep(k * 1.0, 1.0)
        interleaved = reals(a, vr)
    with instance(extracted, "A", fmu_log, {"A": 0.3, "omega": 0.9, "initial_state": 2}, name="alone") as (c, vr):
        for k in range(50):
            c.doStep(k * 1.0, 1.0)
        assert reals(c, vr) == interleaved


# Every axis' last law at once: the Hertz-Hunt-Crossley contact, rate-and-state friction
# with the slip law, the load-only Coulomb bound and the oblique plate.
OTHER_LAWS = {"contact_law": 3, "friction_law": 4, "rs_D_c": 0.1, "rs_V_0": 1e-3, "rs_theta_0": 100.0,
              "coulomb_normal": 2, "plate_motion": 1, "drive_angle": 0.7}
LAW_NAMES = {"contact_law": "hertz_hunt_crossley", "friction_law": "rate_state_slip", "coulomb_normal": "load_only",
             "plate_motion": "oblique"}


@pytest.mark.parametrize("laws", [{}, OTHER_LAWS], ids=["paper", "other_laws"])
@pytest.mark.parametrize("model", "ABC")
def test_libcosim_runs_the_fmus_with_the_same_results_as_fmpy(fmu_path, model, laws):
    """A second FMI 2.0 master (DNV's libcosim, through libcosimpy), with the paper's laws
    and with others chosen through the Integer parameters: by value in fmpy, by name (the
    model description's) in libcosim."""
    from harness.cosim.masters.libcosim import run_libcosim

    settings = {**SCALED, "A": 0.9, "omega": 1.1, "initial_state": 2, "integrator": 1, **laws}
    names = OUTPUTS + ["contact", "slip_count"]
    reference = simulate_fmu(fmu_path(model), stop_time=60.0, output_interval=0.1, start_values=settings)
    by_name = {**settings, **{name: LAW_NAMES[name] for name in laws if name in LAW_NAMES}}
    other = run_libcosim(fmu_path(model), start_values=by_name, stop_time=60.0, step_size=0.1, outputs=names)
    np.testing.assert_array_equal(other["time"], reference["time"])
    # libcosim passes times as integer nanoseconds / 1e9: they can differ from fmpy's in
    # the last bit, which the FMU absorbs (it steps on its own grid of dt).
    for name in names:
        np.testing.assert_array_equal(other[name], reference[name], err_msg=name)


def test_an_instance_freed_right_after_instantiation_does_not_crash_the_host(fmu_path, tmp_path):
    """Run in a child process: a crash there would otherwise take the test runner down."""
    import subprocess
    import sys
    import textwrap

    script = textwrap.dedent(f"""
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave
        md = read_model_description({fmu_path("A")!r})
        unzipdir = extract({fmu_path("A")!r})
        for logging_on in (False, True):
            slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="BlockA", instanceName="brief")
            slave.instantiate(loggingOn=logging_on)
            slave.freeInstance()
        print("freed")
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert done.returncode == 0 and "freed" in done.stdout, done.stderr[-2000:]


def set_integer(slave, vr, value) -> int:
    return status_of(lambda: slave.fmi2SetInteger(slave.component, (fmi2ValueReference * 1)(vr), 1,
                                                  (fmi2Integer * 1)(value)))


@pytest.mark.parametrize("name, value", [("formulation", 2), ("formulation", -1), ("coulomb_normal", 7),
                                         ("flight", 2)])
def test_bad_readings_give_fmi2error_with_a_message_and_the_host_goes_on(extracted, fmu_log, name, value):
    md, unzipdir = extracted["C"]
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="BlockC", instanceName="readings")
    slave.instantiate(callbacks=fmu_log.callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        assert set_integer(slave, vr[name], value) == fmi2Error
        assert any(status == fmi2Error and name in message and "0 (" in message
                   for _, status, _, message in fmu_log.records)
        assert slave.getInteger([vr[name]]) == [0]
        slave.exitInitializationMode()
        assert do_step(slave, 0.0, 1.0) == fmi2OK
    finally:
        slave.freeInstance()


def test_tangent_frame_with_free_flight_is_refused_at_initialization(extracted, fmu_log):
    md, unzipdir = extracted["B"]
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="BlockB", instanceName="combination")
    slave.instantiate(callbacks=fmu_log.callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setInteger([vr["formulation"], vr["flight"]], [1, 1])
        assert status_of(lambda: slave.fmi2ExitInitializationMode(slave.component)) == fmi2Error
        assert any("no position in the plane" in message for *_, message in fmu_log.records)
        assert do_step(slave, 0.0, 1.0) == fmi2Error  # not initialized: refused, no crash
    finally:
        slave.freeInstance()
    assert "formulation" not in {v.name for v in extracted["A"][0].modelVariables}


def test_the_tangent_frame_fmu_equals_the_core(extracted, fmu_log):
    settings = dict(SCALED, A_x=1.0, omega_x=0.5, A=1.5, omega=0.8, x_start=1.0)
    with instance(extracted, "C", fmu_log, dict(settings, formulation=1, coulomb_normal=1, initial_state=2)) \
            as (slave, vr):
        slave.doStep(0.0, 5.0)
        got = reals(slave, vr)
    block = Block("C", initial_state=2, formulation=1, coulomb_normal=1, **settings)
    block.start()
    block.advance_to(5.0)
    assert got == [block.outputs()[n] for n in OUTPUTS]


@pytest.mark.parametrize("value, message", [(-0.1, "mu_k = -0.1 is not admissible"),
                                            (0.6, "must not exceed the static one")])
def test_a_bad_kinetic_coefficient_gives_fmi2error_and_the_host_goes_on(extracted, fmu_log, value, message):
    """A negative mu_k is refused as it is set (the last good value kept); one above mu_s
    when the run starts, with friction_law = 2 chosen."""
    md, unzipdir = extracted["A"]
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="BlockA", instanceName="kinetic")
    slave.instantiate(callbacks=fmu_log.callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setInteger([vr["integrator"]], [1])
        slave.setInteger([vr["friction_law"]], [2])
        status = set_real(slave, vr["mu_k"], value)
        if value < 0.0:
            assert status == fmi2Error and slave.getReal([vr["mu_k"]]) == [0.4]
            slave.exitInitializationMode()
            assert do_step(slave, 0.0, 1.0) == fmi2OK
        else:
            assert status_of(lambda: slave.fmi2ExitInitializationMode(slave.component)) == fmi2Error
            assert do_step(slave, 0.0, 1.0) == fmi2Error  # not initialized: refused, no crash
        assert any(status == fmi2Error and message in text for _, status, _, text in fmu_log.records)
    finally:
        slave.freeInstance()


@pytest.mark.parametrize("name, value", [("rs_D_c", -1.0), ("rs_a", 0.0), ("rs_b", -0.01)])
def test_a_bad_rate_and_state_parameter_gives_fmi2error_and_the_host_goes_on(extracted, fmu_log, name, value):
    """Refused as it is set, the last good value kept; the run then starts and steps."""
    md, unzipdir = extracted["A"]
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="BlockA", instanceName="rate_state")
    slave.instantiate(callbacks=fmu_log.callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    default = slave.getReal([vr[name]])
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setInteger([vr["integrator"]], [1])
        slave.setInteger([vr["friction_law"]], [3])
        assert set_real(slave, vr[name], value) == fmi2Error
        assert slave.getReal([vr[name]]) == default
        slave.exitInitializationMode()
        assert do_step(slave, 0.0, 1.0) == fmi2OK
        assert any(status == fmi2Error and name in text for _, status, _, text in fmu_log.records)
    finally:
        slave.freeInstance()
