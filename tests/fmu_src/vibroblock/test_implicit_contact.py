"""implicit_contact: exact contact flows, stability at any contact stiffness, order 2."""
import math

import numpy as np
import pytest
from scipy.linalg import expm

from vibroblock import Block, ModelError, steady_orbit
from vibroblock.integrators.implicit_contact import oscillator_flow

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}


def test_propagator_matches_the_matrix_exponential():
    """(p, q, r, i1) of y'' + 2a y' + w2 y = b, over under-, critically and overdamped,
    small and large arguments."""
    rng = np.random.default_rng(3)
    for _ in range(3000):
        tau = 10 ** rng.uniform(-6, 1)
        a = rng.choice([0.0, 1.0]) * 10 ** rng.uniform(-8, 1.5) / tau
        w2 = rng.choice([0.0, 1.0, 1.0]) * (10 ** rng.uniform(-8, 1.5) / tau) ** 2
        if rng.uniform() < 0.1:
            w2 = a * a * (1.0 + rng.uniform(-1e-3, 1e-3))  # near critical damping
        exact = expm(np.array([[0.0, 1.0, 0.0], [-w2, -2.0 * a, 1.0], [0.0, 0.0, 0.0]]) * tau)
        p, q, r, i1 = oscillator_flow(a, w2, tau)
        np.testing.assert_allclose([p, r], [exact[0, 0], exact[1, 1]], rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose([q, -w2 * q], [exact[0, 1], exact[1, 0]], rtol=1e-9, atol=1e-12 * tau)
        np.testing.assert_allclose(i1, exact[0, 2], rtol=1e-9, atol=1e-12 * tau * tau)


def test_second_order_against_the_analytic_steady_orbit():
    amplitude, omega, t_end = 0.3, 0.8, 20.0
    phase = omega * t_end
    offset, _ = steady_orbit(1.0, 1.0, 0.07, 1.0, amplitude, omega, phase)
    exact_z = amplitude * math.sin(phase) + offset
    steps = (0.04, 0.02, 0.01)
    errors = []
    for dt in steps:
        block = Block("A", "implicit_contact", initial_state=2, A=amplitude, omega=omega, dt=dt, k_d=0.0, V_d=0.0)
        block.start()
        block.advance_to(t_end)
        errors.append(abs(block.output("z") - exact_z))
    assert np.diff(np.log(errors)) / np.diff(np.log(steps)) == pytest.approx([2.0, 2.0], abs=0.05)


@pytest.mark.parametrize("model", "BC")
@pytest.mark.parametrize("contact_law, fall", [("linear_along_normal", (3.0, 5.5)), ("linear", (1.4, math.inf))])
def test_order_on_the_corrugated_plate(model, contact_law, fall):
    """Curvature, centripetal and Coriolis terms included: successive differences of the
    state fall by 4 per halving of dt with the force along the normal (no resets: k_t =
    mu_s = 0; a gentle corrugation).  The conservative contact's curvature term is held
    over the step at its midpoint value, and the scheme converges at first order with it
    (measured: the differences fall by 1.6-2 here): the order the README states."""
    settings = dict(SCALED, A=0.3, omega=1.1, mu_s=0.0, k_t=0.0, A_x=10.0, omega_x=0.1, initial_state=2,
                    contact_law=contact_law)
    finals = []
    for dt in (4e-3, 2e-3, 1e-3):
        block = Block(model, "implicit_contact", dt=dt, **settings)
        block.start()
        block.advance_to(20.0)
        finals.append(np.array([block.output(n) for n in ("x", "z", "vx", "vz")]))
    first, second = np.abs(finals[1] - finals[0]), np.abs(finals[2] - finals[1])
    assert np.all(second < first / fall[0]) and np.all(second > first / fall[1])


@pytest.mark.parametrize("model", "AC")
def test_stiff_contact_at_the_paper_step_rests_at_the_load_over_kn(model):
    """k_n/m = 1e8 at dt = 4e-4 (omega_n dt = 4), damping ratio 0.5: explicit schemes refuse
    the step; dropped from above, this one settles at the penetration load / k_n and keeps
    the energy balance closed."""
    stiff = {"k_n": 1e8, "gamma_n": 1e4}
    with pytest.raises(ModelError, match="use dt <="):
        Block(model, **stiff).start()
    # Without the drive: on C's 87 degree slope its pull would add to the normal force.
    block = Block(model, "implicit_contact", energy_balance=True, initial_state=1, z_start=1e-6, **stiff,
                  **dict(SCALED, k_d=0.0, V_d=0.0))
    block.start()
    block.advance_to(50.0)
    out = block.outputs()
    assert out["penetration"] == pytest.approx(1e-8, rel=1e-6)
    assert out["normal_force"] == pytest.approx(1.0, rel=1e-6)
    assert abs(out["energy_residual"]) < 1e-9 * out["energy_dissipated"] + 1e-15


def test_an_impact_shorter_than_a_step_has_the_exact_restitution():
    """A block falling at 1 onto a resting plate without gravity, k_n = 1e8 and damping
    ratio 0.1: contact lasts 3.2e-4 < dt, and the rebound is exp(-zeta pi / sqrt(1 - zeta^2))."""
    zeta, k_n = 0.1, 1e8
    block = Block("A", "implicit_contact", energy_balance=True, initial_state=1, g=0.0, k_d=0.0, V_d=0.0,
                  k_n=k_n, gamma_n=2.0 * zeta * math.sqrt(k_n), z_start=2e-3, vz_start=-1.0)
    block.start()
    block.advance_to(0.01)
    out = block.outputs()
    restitution = math.exp(-zeta * math.pi / math.sqrt(1.0 - zeta * zeta))
    assert out["vz"] == pytest.approx(restitution, rel=1e-12)
    assert out["energy_dissipated"] == pytest.approx(0.5 * (1.0 - restitution**2), rel=1e-12)
    assert abs(out["energy_residual"]) < 1e-14


@pytest.mark.parametrize("amplitude", [0.3, 1.0])
def test_models_b_and_c_reduce_to_a_on_a_flat_plate(amplitude):
    common = dict(SCALED, A=amplitude, omega=0.8, initial_state=2)
    runs = {}
    for model, extra in (("A", {}), ("B", {"A_x": 0.0}), ("C", {"A_x": 0.0, "P_l": 1.0})):
        block = Block(model, "implicit_contact", **common, **extra)
        block.start()
        rows = []
        for t in np.arange(0.5, 150.0, 0.5):
            block.advance_to(t)
            rows.append([block.output(n) for n in ("x", "z", "vx", "vz", "friction_force", "phi_integral")])
        runs[model] = np.array(rows)
    np.testing.assert_allclose(runs["B"], runs["A"], rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(runs["C"], runs["A"], rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("model", "ABC")
def test_results_do_not_depend_on_how_the_horizon_is_split(model):
    def final(stops):
        block = Block(model, "implicit_contact", A=1.2, omega=1.3, initial_state=2, k_n=1e6, **SCALED)
        block.start()
        for t in stops:
            block.advance_to(t)
        return block.outputs(), block.get_state()

    rng = np.random.default_rng(2)
    ragged = np.cumsum(rng.uniform(0.0, 0.9, 200))
    one, state_one = final([80.0])
    many, state_many = final(list(ragged[ragged < 80.0]) + [80.0])
    assert one == many
    assert state_one["y"] == state_many["y"] and state_one["cnt"] == state_many["cnt"]


@pytest.mark.parametrize("model", "ABC")
def test_energy_residual_falls_with_the_step(model):
    """The residual (stored energy booked as the potentials) falls at second order on a flat
    plate and at first order on a corrugated one under the conservative contact."""
    def residual(dt):
        block = Block(model, "implicit_contact", energy_balance=True, dt=dt, A=0.3, omega=1.2, initial_state=2,
                      **SCALED, **({"k_t": 0.0, "mu_s": 0.0, "A_x": 10.0, "omega_x": 0.1} if model != "A" else {}))
        block.start()
        block.advance_to(300.0)
        out = block.outputs()
        assert out["energy_dissipated"] > 0.0
        return abs(out["energy_residual"]) / out["energy_dissipated"]

    coarse, fine = residual(2e-3), residual(1e-3)
    assert fine == pytest.approx(coarse / (4.0 if model == "A" else 2.0), rel=0.3)
    assert coarse < (1e-6 if model == "A" else 2e-5)


def test_long_steps_on_a_flat_plate_stay_stable():
    """The drive spring is part of the exact tangential flow: at dt = 40 (dt sqrt(k_t/m) = 21)
    the paper's stick-slip runs with a closed energy balance (an explicit drive spring
    resonated there)."""
    block = Block("A", "implicit_contact", energy_balance=True, dt=40.0)
    block.start()
    block.advance_to(2e8)
    out = block.outputs()
    assert out["slip_count"] > 0 and out["energy_dissipated"] > 100.0
    assert abs(out["energy_residual"]) < 1e-8 * out["energy_dissipated"]
    assert out["x"] == pytest.approx(2e-5 * 2e8, rel=0.3)  # follows the drive on average


def test_limits_that_remain_are_stated():
    with pytest.raises(ModelError, match=r"corrugated plate.*use dt <="):
        Block("B", "implicit_contact", dt=2.0).start()  # (k_d + m g A_x omega_x^2)/m = 0.4
    Block("A", "implicit_contact", dt=2.0).start()  # flat: no limit from the drive spring
    with pytest.raises(ModelError, match="half periods of the normal contact"):
        Block("A", "implicit_contact", k_n=1e20).start()


def test_outputs_between_grid_points_are_at_the_requested_time():
    block = Block("A", "implicit_contact", A=0.3, omega=0.7, dt=0.01, initial_state=2)
    block.start()
    block.advance_to(1.2345)
    assert block.output("surface_z") == pytest.approx(0.3 * math.sin(0.7 * 1.2345), abs=1e-14)


def test_selected_by_its_fmu_id():
    block = Block("B", 3)
    assert block.integrator == "implicit_contact"
