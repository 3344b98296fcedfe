"""Hertzian contact with Hunt-Crossley damping: N = max(0, delta^(3/2) (k_n - gamma_n u_n))."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from vibroblock import Block
from vibroblock.block import ModelError

LAW = "hertz_hunt_crossley"
# A block thrown at a resting plate without gravity or drive: one impact, then free flight.
IMPACT = dict(g=0.0, k_d=0.0, V_d=0.0, A=0.0, z_start=0.01, exact_flows=False, rtol=1e-11, atol=1e-13)


def impact(v0, gamma_n, k_n=1.0, dt=1e-3, t_end=30.0):
    """Contact time (the penetration's sign changes, interpolated) and coefficient of
    restitution of a block hitting the plate at speed v0, and the run's outputs."""
    block = Block("A", "adaptive", 1, True, dt=dt, k_n=k_n, gamma_n=gamma_n, vz_start=-v0, contact_law=LAW, **IMPACT)
    block.start()
    times = np.arange(dt, t_end, dt)
    penetration = np.empty_like(times)
    for i, t in enumerate(times):
        block.advance_to(t)
        penetration[i] = block.output("penetration")
    inside = np.nonzero(penetration > 0.0)[0]
    first, last = inside[0], inside[-1]
    enters = times[first - 1] + dt * -penetration[first - 1] / (penetration[first] - penetration[first - 1])
    leaves = times[last] + dt * penetration[last] / (penetration[last] - penetration[last + 1])
    assert np.all(penetration[first:last + 1] > 0.0)  # one contact
    return leaves - enters, block.output("vz") / v0, block.outputs()


@pytest.mark.parametrize("v0, k_n", [(0.5, 1.0), (2.0, 3.0)])
def test_an_undamped_impact_lasts_hertz_s_contact_time(v0, k_n):
    """m delta'' = -k_n delta^(3/2): the deepest penetration (5 m v0^2 / (4 k_n))^(2/5) and
    the contact time 2 (delta_max / v0) int_0^1 dx / sqrt(1 - x^(5/2)); all the speed
    comes back."""
    duration, restitution, _ = impact(v0, 0.0, k_n)
    deepest = (5.0 * v0 ** 2 / (4.0 * k_n)) ** 0.4
    integral, _ = quad(lambda x: 1.0 / math.sqrt(1.0 - x ** 2.5), 0.0, 1.0)
    assert duration == pytest.approx(2.0 * deepest / v0 * integral, rel=1e-6)
    assert restitution == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize("v0, gamma_n", [(0.05, 0.03), (0.2, 0.03), (0.5, 0.015), (1.0, 0.03)])
def test_restitution_falls_with_the_impact_speed_as_hunt_and_crossley_s(v0, gamma_n):
    """e = 1 - alpha v0 to first order in alpha v0, alpha = 2 gamma_n / (3 k_n) (the law's
    doc); the second-order rest is of the order of (alpha v0)^2.  The energy balance closes."""
    _, restitution, outputs = impact(v0, gamma_n)
    alpha_v0 = 2.0 * gamma_n / 3.0 * v0
    assert 1.0 - restitution == pytest.approx(alpha_v0, rel=1.5 * alpha_v0)
    assert outputs["energy_dissipated"] == pytest.approx(0.5 * v0 ** 2 * (1.0 - restitution ** 2), rel=1e-7)
    assert abs(outputs["energy_residual"]) < 1e-9 * outputs["energy_dissipated"]


@pytest.mark.parametrize("k_n", [1.0, 4.0])
def test_the_block_rests_at_the_hertzian_penetration(k_n):
    """Under its weight the block settles to (m g / k_n)^(2/3), and the at-rest start puts
    it there (it stays, and the contact force equals the weight)."""
    settled = Block("A", "rk4", 1, k_d=0.0, V_d=0.0, k_n=k_n, z_start=0.0, contact_law=LAW)
    settled.start()
    settled.advance_to(3000.0)
    rest = (1.0 / k_n) ** (2.0 / 3.0)
    assert settled.output("penetration") == pytest.approx(rest, rel=1e-8)
    started = Block("A", "rk4", 0, k_d=0.0, V_d=0.0, k_n=k_n, contact_law=LAW)
    started.start()
    started.advance_to(100.0)
    assert started.output("penetration") == pytest.approx(rest, rel=1e-12)
    assert started.output("normal_force") == pytest.approx(1.0, rel=1e-12)


BOUNCING = dict(A=2.5, omega=0.9, k_d=1e-2, V_d=1e-2, gamma_t=5e-3, gamma_n=1.0, x_start=3.0)


def test_the_contact_never_pulls_and_the_clipped_work_is_dissipated():
    """A fast separation (u_n > k_n / gamma_n) would make the dashpot pull: the force is
    clipped at 0 there (N = 0 while delta > 0), and the energy balance still closes."""
    block = Block("A", "adaptive", 0, True, dt=1e-2, contact_law=LAW, exact_flows=False, rtol=1e-10, **BOUNCING)
    block.start()
    normal, penetration = [], []
    for t in np.arange(0.01, 60.0, 0.01):
        block.advance_to(t)
        normal.append(block.output("normal_force"))
        penetration.append(block.output("penetration"))
    normal, penetration = np.array(normal), np.array(penetration)
    assert normal.min() >= 0.0
    assert np.any((normal == 0.0) & (penetration > 1e-3))  # clipped while still pressed in
    out = block.outputs()
    assert out["energy_dissipated"] > 1.0
    assert abs(out["energy_residual"]) < 1e-7 * out["energy_dissipated"]


@pytest.mark.parametrize("integrator, reason", [("event_driven", "linear"), ("implicit_contact", "Hertzian")])
def test_integrators_with_the_linear_contact_s_closed_forms_refuse_it(integrator, reason):
    with pytest.raises(ModelError, match=reason):
        Block("A", integrator, contact_law=LAW).start()
