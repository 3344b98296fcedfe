"""The independent scipy reference: against analytic results, and the core against it."""
import math

import numpy as np
import pytest

from harness.paper import reference
from vibroblock import Block

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
COMPARED = ("x", "z", "vx", "vz", "phi", "work", "dissipated")
CORE_NAMES = {"x": "x", "z": "z", "vx": "vx", "vz": "vz", "phi": "phi_integral", "work": "work_input",
              "dissipated": "energy_dissipated"}


def core_samples(model, integrator, times, dt=1e-3, initial_state=0, **parameters):
    block = Block(model, integrator, dt=dt, energy_balance=True, initial_state=initial_state, **parameters)
    block.start()
    rows = []
    for t in times:
        block.advance_to(t)
        out = block.outputs()
        rows.append([out[CORE_NAMES[n]] for n in COMPARED])
    return dict(zip(COMPARED, np.array(rows).T))


def test_reference_reproduces_the_stick_time_and_slip_of_claim_c1():
    expected = reference.stick_slip_cycle(SCALED)
    run = reference.simulate("A", SCALED, 5700.0, np.arange(100.0, 5701.0, 100.0))
    first_reset = next(t for t, kind in run.event_log if kind == "reset")
    assert first_reset == pytest.approx(expected["stick_time"], rel=1e-4)
    creep = (run["x"][30] - run["x"][20]) / 1000.0  # t = 2100 .. 3100
    assert creep == pytest.approx(expected["creep"], rel=1e-4)
    assert run.final("x") - run["x"][50] == pytest.approx(expected["slip_length"], rel=5e-2)  # t = 5100 -> 5700


def test_reference_follows_the_steady_orbit_and_closes_its_energy_balance():
    params = dict(A=0.3, omega=0.8, k_d=0.0, V_d=0.0)
    times = np.linspace(1.0, 200.0, 40)
    run = reference.simulate("A", params, 200.0, times, initial=2)
    exact = [reference.steady_orbit_height(params, t) for t in times]
    np.testing.assert_allclose(run["z"], exact, atol=1e-10)
    assert np.max(np.abs(run.energy_residual())) < 1e-9


@pytest.mark.parametrize("settings, horizon, tol", [
    (dict(SCALED, A=0.3, omega=0.8), 300.0, 1e-9),   # vibrated stick, no event
    (dict(SCALED, A=1.0, omega=0.8), 40.0, 1e-9),    # bouncing: contacts, detachments, resets
    (dict(SCALED), 5300.0, 1e-6),                     # first slip: 28 resets
])
def test_event_driven_core_matches_the_reference(settings, horizon, tol):
    times = np.linspace(horizon / 10, horizon, 10)
    ref = reference.simulate("A", settings, horizon, times, initial=2, solver=reference.Solver.reference())
    ours = core_samples("A", "event_driven", times, initial_state=2, **settings)
    for name in COMPARED:
        scale = max(1.0, np.max(np.abs(ref[name])))
        np.testing.assert_allclose(ours[name], ref[name], atol=tol * scale, err_msg=name)


@pytest.mark.parametrize("model, extra", [("B", {}), ("C", {})])
def test_rk4_core_matches_the_reference_on_the_corrugated_plate(model, extra):
    """The paper's corrugation (A_x = 1e3, omega_x = 0.02), near a valley where the slope
    is 0.1 and friction holds under sub-threshold vibration: no switch in 60 tau_0, so
    RK4 at dt = 1e-3 is at its fourth-order accuracy, on a curved, tilted contact."""
    x_start = (-0.5 * math.pi + 0.005) / 0.02  # slope A_x omega_x cos(omega_x x) = 0.1
    settings = dict(A=0.2, omega=0.8, **extra)
    times = np.linspace(6.0, 60.0, 10)
    ref = reference.simulate(model, settings, 60.0, times, initial=2, x_start=x_start)
    assert ref.events == 0 and ref["contact"].all()
    ours = core_samples(model, "rk4", times, initial_state=2, x_start=x_start, **settings)
    for name in COMPARED:
        scale = max(1.0, np.max(np.abs(ref[name])))
        np.testing.assert_allclose(ours[name], ref[name], atol=1e-8 * scale, err_msg=name)


def test_reference_b_and_c_reduce_to_a_on_a_flat_plate():
    common = dict(SCALED, A=1.0, omega=0.8)
    times = np.linspace(5.0, 40.0, 8)
    a = reference.simulate("A", common, 40.0, times, initial=2)
    b = reference.simulate("B", dict(common, A_x=0.0), 40.0, times, initial=2)
    c = reference.simulate("C", dict(common, A_x=0.0, P_l=1.0), 40.0, times, initial=2)
    for other in (b, c):
        for name in ("x", "z", "vx", "vz", "phi"):
            np.testing.assert_allclose(other[name], a[name], atol=1e-9, err_msg=name)


def test_unknown_model_or_parameter_is_refused():
    with pytest.raises(ValueError, match="unknown model"):
        reference.simulate("D")
    with pytest.raises(ValueError, match="P_l"):
        reference.simulate("A", {"P_l": 1.0})
    assert math.isclose(reference.stick_slip_cycle({})["slip_length"], 1000.0)
