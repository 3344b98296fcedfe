"""The Cundall-Strack spring held at a kinetic bound mu_d(u_t) N while sliding."""
import numpy as np
import pytest

from vibroblock import Block
from vibroblock.block import ModelError

LAW = "cundall_strack_kinetic"
# Model A, no vibration, the scaled drive: the paper's law stick-slips here.
DRIVEN = dict(k_d=1e-2, V_d=1e-2, gamma_t=5e-3, A=0.0)


def started(friction_law, integrator="rk4", dt=1e-2, energy=False, **parameters):
    block = Block("A", integrator, 0, energy, dt=dt, friction_law=friction_law, **{**DRIVEN, **parameters})
    block.start()
    return block


def run(friction_law, t_end, integrator="rk4", **parameters):
    block = started(friction_law, integrator, **parameters)
    block.advance_to(t_end)
    return block.outputs()


def test_a_sliding_block_feels_the_kinetic_force_and_slides_steadily():
    """Past the static bound the spring is held at mu_k N.  With the drive overdamped
    (gamma_t = 1 > 2 sqrt(k_d m)) the slip never reverses, so the block does not stick
    again: steady sliding at V_d with the stretch (mu_k m g + gamma_t V_d) / k_d.  (The
    hold is applied after each step, so the mean force exceeds mu_k N by ~k_t V_d dt / 2.)"""
    mu_k, gamma_t = 0.3, 1.0
    out = run(LAW, 8000.0, mu_k=mu_k, gamma_t=gamma_t)
    assert abs(out["friction_force"]) == pytest.approx(mu_k * out["normal_force"], rel=1e-12)
    assert out["vx"] == pytest.approx(DRIVEN["V_d"], rel=1e-4)
    stretch = DRIVEN["V_d"] * 8000.0 - out["x"]
    assert stretch == pytest.approx((mu_k + gamma_t * DRIVEN["V_d"]) / DRIVEN["k_d"], rel=1e-3)


def test_the_kinetic_coefficient_weakens_with_the_slip_rate():
    """mu_d = mu_k / (1 + |u_t| / v_w); steady sliding is stable where the dashpot outweighs
    the weakening, gamma_t > N |d mu_d / du| (here 10 > 4.2): the stretch is
    (mu_d(V_d) m g + gamma_t V_d) / k_d."""
    mu_k, v_w, gamma_t = 0.3, 0.05, 10.0
    out = run(LAW, 20000.0, mu_k=mu_k, v_w=v_w, gamma_t=gamma_t)
    mu_d = mu_k / (1.0 + DRIVEN["V_d"] / v_w)
    assert out["vx"] == pytest.approx(DRIVEN["V_d"], rel=1e-4)
    stretch = DRIVEN["V_d"] * 20000.0 - out["x"]
    assert stretch == pytest.approx((mu_d + gamma_t * DRIVEN["V_d"]) / DRIVEN["k_d"], rel=1e-3)
    # Without the weakening the stretch would be mu_k's: 14 % more.
    assert abs(stretch - (mu_k + gamma_t * DRIVEN["V_d"]) / DRIVEN["k_d"]) > 0.1 * stretch


def test_an_undamped_slip_drops_the_spring_force_to_twice_mu_k_minus_mu_s():
    """The textbook stick-slip: a slip starts at the static force mu_s m g, oscillates about
    the kinetic force and stops when the slip reverses, half a period later, at the
    mirror image 2 mu_k m g - mu_s m g (slow drive, no damping; the hold after each step
    adds ~k_t |u_t| dt / 2 to the kinetic force, 0.2 % of it at dt = 2e-3)."""
    mu_s, mu_k, v_d = 0.5, 0.3, 1e-3
    block = started(LAW, dt=2e-3, mu_k=mu_k, V_d=v_d, gamma_t=0.0)
    times = np.arange(1.0, 1.2 * mu_s / DRIVEN["k_d"] / v_d, 0.25)
    pull = []
    for t in times:
        block.advance_to(t)
        pull.append(DRIVEN["k_d"] * (v_d * t - block.output("x")))
    pull = np.array(pull)
    first_slip = int(np.argmax(pull))
    assert block.output("coulomb_resets") == 1
    assert pull[first_slip] == pytest.approx(mu_s, rel=2e-3)
    assert pull[first_slip:].min() == pytest.approx(2.0 * mu_k - mu_s, rel=2e-2)


def test_before_the_bound_is_met_it_is_the_paper_s_spring():
    t_end = 0.8 * 0.5 / DRIVEN["k_d"] / DRIVEN["V_d"]  # the drive's pull reaches 0.8 mu_s m g
    assert run(LAW, t_end, mu_k=0.3) == run("cundall_strack", t_end)


@pytest.mark.parametrize("integrator", ["symplectic_euler", "rk4", "implicit_contact"])
def test_the_energy_the_hold_takes_from_the_spring_is_booked_as_dissipated(integrator):
    out = run(LAW, 3000.0, integrator, dt=1e-3, energy=True, A=1.5, omega=0.9, mu_k=0.3, v_w=0.05)
    assert out["coulomb_resets"] > 20
    assert abs(out["energy_residual"]) < 1e-3 * out["energy_dissipated"]


@pytest.mark.parametrize("integrator, reason", [("adaptive", "kinetic bound"), ("event_driven", "reset the spring")])
def test_integrators_that_locate_the_bound_as_events_refuse_it(integrator, reason):
    with pytest.raises(ModelError, match=reason):
        Block("A", integrator, friction_law=LAW).start()


def test_a_kinetic_coefficient_above_the_static_one_is_refused():
    with pytest.raises(ModelError, match="must not exceed the static one"):
        Block("A", "rk4", friction_law=LAW, mu_k=0.6).start()
