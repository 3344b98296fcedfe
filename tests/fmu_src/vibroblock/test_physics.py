"""The core against analytic results of the paper and of the contact model."""
import math

import numpy as np
import pytest

from vibroblock import Block, detachment_amplitude, steady_orbit

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}


def sample(block, times, *names):
    rows = []
    for t in times:
        block.advance_to(t)
        out = block.outputs()
        rows.append([out[n] for n in names])
    return np.array(rows, dtype=float).T


def test_rest_penetration_is_mg_over_kn():
    """Dropped from touching contact (z = 0), the block settles at z = -m g / k_n."""
    m, g, k_n = 2.0, 1.5, 3.0
    block = Block("A", initial_state=1, m=m, g=g, k_n=k_n, z_start=0.0, k_d=0.0, V_d=0.0)
    block.start()
    block.advance_to(800.0)  # amplitude decays as exp(-gamma_n t / 2m) ~ 1e-6
    assert block.output("z") == pytest.approx(-m * g / k_n, abs=1e-5)
    assert block.output("normal_force") == pytest.approx(m * g, rel=1e-5)


def test_stick_slip_without_vibration_matches_claim_c1():
    """Creep V_S = V_d k_d/(k_t+k_d), stick time mu_s m g/(k_t V_S), slip ~ mu_s m g/k_d."""
    p = {"k_t": 0.28, "mu_s": 0.5, **SCALED}
    v_creep = p["V_d"] * p["k_d"] / (p["k_t"] + p["k_d"])
    t_stick = p["mu_s"] / (p["k_t"] * v_creep)
    slip = p["mu_s"] / p["k_d"]

    block = Block("A", **p)
    block.start()
    times = np.arange(1.0, 6001.0, 1.0)
    x, vx = sample(block, times, "x", "vx")

    creeping = (times > 2000) & (times < 4000)
    assert np.mean(vx[creeping]) == pytest.approx(v_creep, rel=5e-3)
    first_slip = times[np.argmax(vx > 10 * v_creep)]
    assert first_slip == pytest.approx(t_stick, rel=1e-2)
    # The main slip: from its start until the block first comes to rest again.
    start = np.argmax(vx > 10 * v_creep)
    stop = start + np.argmax(vx[start:] < 10 * v_creep)
    # Resets quantise the slip into whole multiples of mu_s m g / k_t of travel:
    # a few percent off the paper's energy argument (docs/claims.md, Conventions).
    assert x[stop] - x[start - 1] == pytest.approx(slip, rel=5e-2)


@pytest.mark.parametrize("omega", [0.05, 1.0, 3.0])
def test_detachment_onset_follows_the_steady_orbit_threshold(omega):
    """Started on the steady in-contact orbit, the block stays embedded just below
    A_c(omega) and detaches just above it: below, near and above omega_n = 1."""
    a_c = float(detachment_amplitude(omega))
    period = 2 * math.pi / omega
    times = np.arange(0.02, 3 * period, 0.02)
    for factor, detaches in ((0.97, False), (1.03, True)):
        block = Block("A", initial_state=2, A=factor * a_c, omega=omega, k_d=0.0, V_d=0.0)
        block.start()
        (contact,) = sample(block, times, "contact")
        assert (not contact.all()) == detaches, f"A = {factor} A_c at omega = {omega}"


def test_paper_line_is_the_low_frequency_limit_of_the_onset():
    omega = 0.05
    assert detachment_amplitude(omega) == pytest.approx(1.0 / omega**2, rel=5e-3)
    assert detachment_amplitude(1.0) == pytest.approx(0.07)  # resonance of the soft contact
    assert detachment_amplitude(100.0) == pytest.approx(1.0, rel=1e-3)  # tends to delta_0


@pytest.mark.parametrize("amplitude", [0.3, 1.0])  # embedded, and bouncing above A_c(0.8) = 0.57
def test_models_b_and_c_reduce_to_a_on_a_flat_plate(amplitude):
    common = dict(SCALED, A=amplitude, omega=0.8, initial_state=2)
    times = np.arange(0.5, 300.0, 0.5)
    names = ("x", "z", "vx", "vz", "friction_force", "normal_force", "phi_integral")
    runs = {}
    for model, extra in (("A", {}), ("B", {"A_x": 0.0}), ("C", {"A_x": 0.0, "P_l": 1.0})):
        block = Block(model, **common, **extra)
        block.start()
        runs[model] = sample(block, times, *names)
    np.testing.assert_allclose(runs["B"], runs["A"], rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(runs["C"], runs["A"], rtol=1e-13, atol=1e-13)


def test_model_c_without_tangential_stiffness_shows_no_stick_slip():
    """k_t = 0: the normal load offers no barrier along the surface, the block never stops
    and phi stays small; with k_t > 0 the same block sticks (phi ~ 1).  On the steep flank
    the conservative contact's tangential force (the normal at the foot of the penetration,
    docs/physics.md Sec. 3) slows the block to about half the drive velocity, so phi is a
    few 1e-2, not 0."""
    times = np.arange(1.0, 8001.0, 1.0)
    phi = {}
    for k_t in (0.0, 0.28):
        block = Block("C", k_t=k_t, **SCALED)
        block.start()
        (vx,) = sample(block, times, "vx")
        late = vx[times > 2000]
        phi[k_t] = np.mean((late - SCALED["V_d"]) ** 2) / SCALED["V_d"] ** 2
        if k_t == 0.0:
            assert late.min() > 0.25 * SCALED["V_d"], "never stuck"
    assert phi[0.0] < 0.1
    assert phi[0.28] > 0.5


@pytest.mark.parametrize("integrator, order", [("symplectic_euler", 1), ("rk4", 4)])
def test_convergence_order_against_the_analytic_steady_orbit(integrator, order):
    """Below threshold the vertical motion is a driven damped oscillator whose steady
    orbit is known in closed form; the error must fall as dt^order."""
    amplitude, omega, t_end = 0.3, 0.8, 20.0
    phase = omega * t_end
    offset, _ = steady_orbit(1.0, 1.0, 0.07, 1.0, amplitude, omega, phase)
    exact_z = amplitude * math.sin(phase) + offset
    errors = []
    steps = (0.02, 0.01, 0.005)
    for dt in steps:
        block = Block("A", integrator, initial_state=2, A=amplitude, omega=omega, dt=dt, k_d=0.0, V_d=0.0)
        block.start()
        block.advance_to(t_end)
        errors.append(abs(block.output("z") - exact_z))
    slopes = np.diff(np.log(errors)) / np.diff(np.log(steps))
    assert slopes == pytest.approx([order, order], abs=0.35)


def test_friction_never_exceeds_the_coulomb_bound():
    block = Block("A", A=0.4, omega=0.9, initial_state=2, **SCALED)
    block.start()
    times = np.arange(0.25, 6000.0, 0.25)
    friction, normal, contact = sample(block, times, "friction_force", "normal_force", "contact")
    loaded = friction != 0.0
    assert np.all(np.abs(friction[loaded]) < 0.5 * normal[loaded])
    assert np.all(friction[contact == 0] == 0.0)
    assert loaded.mean() > 0.5  # the check is not vacuous


@pytest.mark.parametrize("model", "ABC")
def test_energy_balance_closes_as_the_step_shrinks(model):
    """Work in = stored energy change + dissipation (dashpots and resets), up to the
    integration error: first order for symplectic Euler, far smaller for RK4."""
    def residual(integrator, dt):
        block = Block(model, integrator, energy_balance=True, dt=dt, A=0.3, omega=1.2, initial_state=2, **SCALED)
        block.start()
        block.advance_to(1500.0)
        out = block.outputs()
        assert out["work_input"] != 0.0 and out["energy_dissipated"] > 0.0
        return abs(out["energy_residual"]) / out["energy_dissipated"]

    euler = [residual("symplectic_euler", dt) for dt in (2e-3, 1e-3)]
    assert euler[1] == pytest.approx(euler[0] / 2, rel=0.25)
    assert residual("rk4", 2e-3) < 1e-3 * euler[0]


def test_energy_accounting_is_off_by_default_and_costs_nothing_then():
    block = Block("A", A=0.3, omega=1.2, **SCALED)
    block.start()
    block.advance_to(100.0)
    out = block.outputs()
    assert out["work_input"] == out["energy_dissipated"] == out["energy_residual"] == 0.0
