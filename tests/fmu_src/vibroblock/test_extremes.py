"""Stability at the extremes, as a matrix: every case ends with finite results and a closed
energy balance, or with a clear error that states the limit.  Never a silent blow-up.

Energy bound: |energy_residual| <= BOUND[integrator] * scale, where scale = dissipated
energy + |work input| + the energy stored at the end (kinetic, normal spring, drive
spring): the dissipated energy alone is no scale when nothing dissipates (gamma -> 0, a
block at rest).  The stored energy is booked as the potentials at the state.  Bounds:
implicit_contact 1e-3 (exact contact flows; on a corrugated plate the conservative
contact's curvature term is held over a step, first order: the worst case here is model B
bouncing with k_n = 1e8, 6.3e-4), rk4 1e-6, symplectic_euler 2e-2 (first order in dt), event_driven 1e-9
(exact flows: the worst case, 2e-12, is V_d = 1e3; adaptive on model A, which takes
them, too), adaptive 1e-4 (on its own steps, at
its default rtol = 1e-8; the worst case, 3.4e-5, is gamma_n = 1e4: the quadratures ride along
without error control, and the stiff dashpot's dissipation is where that shows).  With k_n = 1e8 at rest on the paper's
87 degree corrugation adaptive finishes (B slides down the flank and bounces in the valley:
~4.7e5 steps, residual 5e-9 of the scale; C rests: ~1.2e6 steps, almost all while the
start's normal ringing, amplitude above atol, dies out; residual 6e-6).  Model C bouncing
with k_n = 1e8 and the steeper corrugation with stiff contact finish too (~3.7e6 and
~4.2e6 steps, residuals ~1e-10 of the scale), within the step budget of 2^24 per call.
"""
from __future__ import annotations

import contextlib
import math
import time

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2Error, fmi2OK

from fmu_testing import do_step, fmu_log  # noqa: F401 (fixture)
from vibroblock import Block, ModelError

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
BOUND = {"symplectic_euler": 2e-2, "rk4": 1e-6, "implicit_contact": 1e-3, "adaptive": 1e-4, "event_driven": 1e-9}
HORIZON = 100.0

REFUSED_STEP = r"too large for the .* use dt <="  # an explicit scheme's stability limit, with the admissible dt
TOO_FAST = r"crosses the corrugation too fast for dt"

# case -> (models, parameters, {integrator: expected error or None})
EXPLICIT_REFUSE = {"symplectic_euler": REFUSED_STEP, "rk4": REFUSED_STEP, "implicit_contact": None}
ALL_RUN = {"symplectic_euler": None, "rk4": None, "implicit_contact": None}
MATRIX = {
    # (every case below also runs adaptive at its default tolerances, and event_driven on model A;
    # see ``matrix_cases``)
    "k_n/m = 1e8, at rest": ("A", {"k_n": 1e8}, EXPLICIT_REFUSE),
    "k_n/m = 1e8, at rest, corrugated": ("BC", {"k_n": 1e8}, EXPLICIT_REFUSE),
    "k_n/m = 1e8, bouncing (A omega^2 = 2 g)": ("ABC", {"k_n": 1e8, "A": 2.0, "omega": 1.0},
                                                 EXPLICIT_REFUSE),
    "gamma_n = 0": ("ABC", {"gamma_n": 0.0, "A": 0.3, "omega": 1.2}, ALL_RUN),
    "gamma_n = 1e4": ("ABC", {"gamma_n": 1e4, "A": 0.3, "omega": 1.2}, EXPLICIT_REFUSE),
    "gamma_t = 0": ("ABC", {"gamma_t": 0.0, "A": 0.3, "omega": 1.2}, ALL_RUN),
    "gamma_t = 1e4": ("ABC", {"gamma_t": 1e4, "A": 0.3, "omega": 1.2}, EXPLICIT_REFUSE),
    "A omega^2 = 1e4 g, omega = 100": ("ABC", {"A": 1.0, "omega": 100.0}, ALL_RUN),
    "A omega^2 = 1e4 g, omega = 1e3": ("ABC", {"A": 1e-2, "omega": 1e3}, ALL_RUN),
    "omega = 1e3, A omega^2 = 0.1 g": ("ABC", {"A": 1e-7, "omega": 1e3}, ALL_RUN),
    "steep corrugation A_x omega_x = 20 (paper), vibrated": ("BC", {"A": 2.0, "omega": 1.0}, ALL_RUN),
    "steeper corrugation A_x omega_x = 50, stiff contact": ("BC", {"A_x": 2500.0, "k_n": 1e8, "A": 2.0, "omega": 1.0},
                                                             EXPLICIT_REFUSE),
    "V_d = 1e-12": ("ABC", {"V_d": 1e-12}, ALL_RUN),
    "V_d = 1e3, flat": ("A", {"V_d": 1e3}, ALL_RUN),
    # (the conservative contact holds the block on the first flank, deep in the plate: no step
    # crosses the corrugation too fast; under the force along the normal it races across,
    # which implicit_contact refuses: test_a_refused_case_keeps_the_last_good_state)
    "V_d = 1e3, corrugated": ("BC", {"V_d": 1e3}, ALL_RUN),
}


def energy_scale(block: Block) -> float:
    out, p = block.outputs(), block.parameters
    stored = (0.5 * p["m"] * (out["vx"] ** 2 + out["vz"] ** 2) + 0.5 * p["k_n"] * max(out["penetration"], 0.0) ** 2
              + 0.5 * p["k_d"] * (out["x"] - p["V_d"] * block.time) ** 2)
    return out["energy_dissipated"] + abs(out["work_input"]) + stored


# On model A adaptive runs twice: as users get it (exact flows, event_driven's kernels, held
# to event_driven's bound) and on its own error-controlled steps (exact_flows off).
STEPPED = "adaptive, exact_flows off"


def matrix_cases():
    for case, (models, parameters, expected) in MATRIX.items():
        for model in models:
            exact = {"event_driven": None, STEPPED: None} if model == "A" else {}
            for run, error in {**expected, "adaptive": expected.get("adaptive"), **exact}.items():
                if isinstance(error, dict):  # the outcome differs between the models
                    error = error.get(model)
                yield pytest.param(model, run, parameters, error, id=f"{case} | {model} | {run}")


@pytest.mark.parametrize("model, run, parameters, error", list(matrix_cases()))
def test_extreme_case_is_finite_and_balanced_or_refused_clearly(model, run, parameters, error):
    integrator, options = ("adaptive", {"exact_flows": False}) if run == STEPPED else (run, {})
    block = Block(model, integrator, initial_state=2, energy_balance=True, **{**SCALED, **parameters}, **options)
    if error is not None:
        with pytest.raises(ModelError, match=error):
            block.start()
            block.advance_to(HORIZON)
        return
    block.start()
    block.advance_to(HORIZON)
    out = block.outputs()
    assert all(math.isfinite(float(value)) for value in out.values()), out
    exact_flows = model == "A" and run == "adaptive"
    bound = BOUND["event_driven" if exact_flows else integrator]
    assert abs(out["energy_residual"]) <= bound * energy_scale(block), out


def test_a_refused_case_keeps_the_last_good_state():
    """V_d = 1e3 on the corrugation with the force along the normal: the block races across
    faster than implicit_contact's frozen frame allows."""
    block = Block("B", "implicit_contact", initial_state=2, contact_law="linear_along_normal",
                  **{**SCALED, "V_d": 1e3})
    block.start()
    before = block.outputs()
    with pytest.raises(ModelError, match=TOO_FAST):
        block.advance_to(HORIZON)
    assert block.time == 0.0 and block.outputs() == before
    with pytest.raises(ModelError, match=TOO_FAST):  # and says so again, it does not go on silently
        block.advance_to(HORIZON)


# --------------------------------------------------------------------- long horizons
def test_a_horizon_of_1e9_runs_with_a_scheme_that_can_take_it():
    """The paper's own parameters (stick time 5e7) over 1e9 tau_0: implicit_contact at
    dt = 40 (2.5e7 steps) - about 20 stick-slip cycles, a closed balance, time exact."""
    block = Block("A", "implicit_contact", energy_balance=True, dt=40.0)
    block.start()
    block.advance_to(1e9)
    out = block.outputs()
    assert block.grid_step == 25_000_000 and block.time == 1e9
    assert out["x"] == pytest.approx(2e-5 * 1e9, rel=0.1)  # follows the drive, V_d t = 2e4
    assert out["energy_dissipated"] > 20 * 0.5 * 5e-4 * 1000.0**2 * 0.5  # ~20 slips of ~mu_s m g / k_d
    assert abs(out["energy_residual"]) < 1e-8 * out["energy_dissipated"]


def test_a_vibrated_corrugated_horizon_of_1e9_runs_with_adaptive():
    """Model C at the paper's own parameters on its vibrated corrugated plate (omega = 0.316,
    a third of the detachment onset, tangent frame), held on a flank by friction, over 1e9
    tau_0 with adaptive in communication steps of 1e8 (one call of 1e9 would exceed the step
    budget a call may hold its master for): the ~5e7 plate periods are crossed by
    stroboscopic jumps and the run ends finite, with a closed energy balance and the time
    exact."""
    from vibroblock import defaults, detachment_amplitude
    flank = 1.5 * math.pi / 0.02 + 10.0  # just past a valley of the paper's corrugation
    omega = 0.316
    amplitude = float(detachment_amplitude(omega, m=1.0, g=1.0, k_n=1.0, gamma_n=0.07)) / 3.0
    block = Block("C", "adaptive", initial_state=2, A=amplitude, omega=omega, x_start=flank, dt=1e3,
                  formulation=1, rtol=1e-6, atol=1e-8, energy_balance=True)
    t0 = flank / defaults("C")["V_d"]  # the drive spring relaxed at the start
    block.start(t0)
    for k in range(1, 11):
        block.advance_to(t0 + k * 1e8)
    out = block.outputs()
    assert block.time == t0 + 1e9
    assert all(math.isfinite(float(value)) for value in out.values()), out
    assert block.counters["periods_jumped"] > 0.99 * 1e9 * omega / (2.0 * math.pi)
    assert out["slip_count"] == 0 and out["contact"] and abs(out["x"] - flank) < 1.0  # held throughout
    assert out["energy_dissipated"] > 1e5  # the contact's dashpot, every plate period
    assert abs(out["energy_residual"]) <= BOUND["adaptive"] * energy_scale(block), out


def test_a_horizon_too_long_for_a_fixed_step_is_refused_at_once_with_its_cost():
    block = Block("A")
    block.start()
    started = time.perf_counter()
    with pytest.raises(ModelError, match=r"2\.5e\+12 internal steps.*implicit_contact"):
        block.advance_to(1e9)
    assert time.perf_counter() - started < 1.0
    assert block.time == 0.0
    block.advance_to(1.0)  # and goes on


# --------------------------------------------------------------------- FMU level
@pytest.fixture(scope="module")
def extracted(fmu_path, tmp_path_factory):
    root = tmp_path_factory.mktemp("extremes")
    return {m: (read_model_description(fmu_path(m)), extract(fmu_path(m), unzipdir=str(root / m))) for m in "AB"}


@contextlib.contextmanager
def instance(extracted, model, log, start_values):
    md, unzipdir = extracted[model]
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="extreme")
    slave.instantiate(callbacks=log.callbacks)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        for key, value in start_values.items():
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


NAMES = ["x", "z", "vx", "vz", "normal_force", "phi_integral", "work_input", "energy_dissipated", "energy_residual"]


def core_outputs(model, start_values, t_end):
    integrator = start_values.get("integrator", 0)
    settings = {k: v for k, v in start_values.items() if k not in ("integrator", "initial_state", "energy_balance")}
    block = Block(model, integrator, start_values.get("initial_state", 0), start_values.get("energy_balance", False),
                  **settings)
    block.start()
    block.advance_to(t_end)
    return [block.output(n) for n in NAMES]


@pytest.mark.parametrize("integrator", [0, 3])
@pytest.mark.parametrize("h, n_steps", [(1e-6, 4000), (0.37 * 4e-4, 300), (1e3, 3)],
                         ids=["h = dt / 400", "h = 0.37 dt", "h = 2.5e6 dt"])
def test_communication_steps_far_below_and_far_above_dt(extracted, fmu_log, integrator, h, n_steps):
    """The master's step does not change the trajectory: the end matches the core run
    straight to the same time (bit for bit on the grid, to rounding off it)."""
    start = {**SCALED, "A": 1.2, "omega": 1.1, "initial_state": 2, "energy_balance": True, "integrator": integrator}
    with instance(extracted, "A", fmu_log, start) as (slave, vr):
        t = 0.0
        for _ in range(n_steps):
            assert do_step(slave, t, h) == fmi2OK
            t += h
        got = slave.getReal([vr[n] for n in NAMES])
    assert all(math.isfinite(v) for v in got)
    expected = core_outputs("A", start, t)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-15)
    dissipated, residual = got[NAMES.index("energy_dissipated")], got[NAMES.index("energy_residual")]
    assert abs(residual) <= BOUND["symplectic_euler" if integrator == 0 else "implicit_contact"] * max(dissipated, 1.0)


def test_fmu_refuses_a_do_step_of_1e9_at_once_and_goes_on(extracted, fmu_log):
    """A fixed-step scheme's step budget per call (the default, adaptive, crosses 1e9 on
    model A by its exact flows)."""
    with instance(extracted, "A", fmu_log, {"integrator": 0}) as (slave, vr):
        started = time.perf_counter()
        assert do_step(slave, 0.0, 1e9) == fmi2Error
        assert time.perf_counter() - started < 2.0
        assert any("internal steps" in message and "one call may take" in message
                   for *_, message in fmu_log.records)
        assert do_step(slave, 0.0, 1.0) == fmi2OK


def test_fmu_stiff_contact_and_long_steps_with_implicit_contact(extracted, fmu_log):
    """Through the FMU: k_n = 1e8 at the paper's dt, and dt = 40 over 1e8 tau_0."""
    with instance(extracted, "B", fmu_log, {**SCALED, "k_n": 1e8, "integrator": 3, "initial_state": 2,
                                             "A": 2.0, "omega": 1.0, "energy_balance": True}) as (slave, vr):
        for k in range(20):
            assert do_step(slave, k * 5.0, 5.0) == fmi2OK
        got = dict(zip(NAMES, slave.getReal([vr[n] for n in NAMES])))
        assert all(math.isfinite(v) for v in got.values())
        # (the stored energy booked as the potentials: implicit_contact's first-order
        # curvature term on the corrugation leaves 1.8e-3 of the dissipated energy here)
        assert abs(got["energy_residual"]) < 3e-3 * got["energy_dissipated"]
    with instance(extracted, "A", fmu_log, {"integrator": 3, "dt": 40.0, "energy_balance": True}) as (slave, vr):
        for k in range(10):
            assert do_step(slave, k * 1e7, 1e7) == fmi2OK
        got = dict(zip(NAMES, slave.getReal([vr[n] for n in NAMES])))
        assert abs(got["energy_residual"]) < 1e-8 * got["energy_dissipated"]
