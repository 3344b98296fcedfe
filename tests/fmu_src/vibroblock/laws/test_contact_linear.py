"""The conservative linear contact on a curved plate (docs/physics.md, Sec. 3): its elastic
force is a gradient, a frictionless block held on a flank comes to rest under it (and
swings ever more under the old force along the normal), and the energy balance, booked
as the potential itself, closes."""
import math

import numpy as np
import pytest
from numba import njit

from vibroblock import Block
from vibroblock.dynamics import force, surface_contact


@njit(cache=False)
def elastic_force(kind, x, z, prm):
    """The contact's elastic force on a block at rest at (x, z) (no load, no drive)."""
    pen, u_n, u_t, cos_a, sin_a, normal = surface_contact(kind, x, z, 0.0, 0.0, 0.0, 0.0, prm)
    return force(kind, x, 0.0, pen > 0.0, pen, normal, u_t, cos_a, sin_a, 0.0, prm)


def bare_contact(contact):
    """kind and prm of model B with only the contact's spring acting (slope 1 at x = 0)."""
    block = Block("B", "rk4", 1, g=0.0, k_d=0.0, gamma_n=0.0, gamma_t=0.0, k_t=0.0, A_x=50.0, omega_x=0.02,
                  contact_law=contact, z_start=-1.0)
    block.start()
    return block.settings.kind, block.prm


def curl(kind, prm, x, z, step=1e-4):
    """dF_z/dx - dF_x/dz by central differences."""
    dfx_dz = (elastic_force(kind, x, z + step, prm)[0] - elastic_force(kind, x, z - step, prm)[0]) / (2 * step)
    dfz_dx = (elastic_force(kind, x + step, z, prm)[1] - elastic_force(kind, x - step, z, prm)[1]) / (2 * step)
    return dfz_dx - dfx_dz


@pytest.mark.parametrize("x", [-40.0, -10.0, 15.0, 30.0])
def test_the_elastic_force_is_a_gradient_and_the_old_one_has_the_predicted_curl(x):
    a_x, w_x, penetration = 50.0, 0.02, 1.5
    height, slope = a_x * math.sin(w_x * x), a_x * w_x * math.cos(w_x * x)
    cos_a = 1.0 / math.sqrt(1.0 + slope * slope)
    z = height - penetration / cos_a  # delta = (h - z) cos(a)
    old = curl(*bare_contact("linear_along_normal"), x, z)
    alpha_rate = -a_x * w_x * w_x * math.sin(w_x * x) * cos_a * cos_a  # d(alpha)/dx = h'' cos^2(a)
    predicted = -2.0 * penetration * (slope * cos_a) * alpha_rate  # -2 k_n delta sin(a) d(alpha)/dx
    assert old == pytest.approx(predicted, rel=1e-4)
    assert abs(curl(*bare_contact("linear"), x, z)) < 1e-6 * abs(predicted)


def flank_swing(contact, slope, gamma_t, horizon=2e4, window=1000.0):
    """x-swing (max - min) of a frictionless block on a flank of the paper's corrugation
    (A_x = 1e3, omega_x = 2e-2) near a trough, where the surface has the given slope and the
    drive spring balances it, over the first and the last window of the run.  It starts at
    rest 0.5 delta_0 downhill of that balance (near the rest point of either law: the
    conservative contact's is shifted by its curvature term)."""
    a_x, w_x = 1e3, 2e-2
    phase = -0.5 * math.pi + math.asin(slope / (a_x * w_x))  # slope a_x w_x cos(phase) right of the trough
    x0 = phase / w_x
    k_d = slope / -x0  # the drive spring (anchored at 0, V_d = 0) balances the slope: -k_d x0 = m g tan(a)
    cos_a = 1.0 / math.sqrt(1.0 + slope * slope)
    block = Block("B", "rk4", 1, dt=1e-2, k_t=0.0, gamma_t=gamma_t, k_d=k_d, V_d=0.0, A_x=a_x, omega_x=w_x,
                  contact_law=contact, x_start=x0 + 0.5, z_start=a_x * math.sin(phase) - 1.0 / cos_a ** 2)
    block.start()

    def swing(t0):
        xs = []
        for t in np.arange(t0 + 0.5, t0 + window, 0.5):
            block.advance_to(t)
            xs.append(block.output("x"))
        return max(xs) - min(xs)
    early = swing(window / 10)
    block.advance_to(horizon - window)
    return early, swing(horizon - window)


@pytest.mark.parametrize("gamma_t", [5e-3, 2.5e-4])
@pytest.mark.parametrize("slope", [0.5, 1.0, 2.0])
def test_a_frictionless_block_on_a_flank_comes_to_rest_under_the_conservative_contact(slope, gamma_t):
    early, late = flank_swing("linear", slope, gamma_t)
    assert late < 1e-2 * early  # the dashpots damp it out
    old_early, old_late = flank_swing("linear_along_normal", slope, gamma_t)
    assert old_late > 0.5 * old_early and old_late > 100.0 * late  # the old force keeps it swinging


@pytest.mark.parametrize("integrator, settings, bound", [
    ("rk4", dict(dt=1e-3), 1e-7),
    ("adaptive", dict(dt=1e-2, rtol=1e-10, atol=1e-12), 1e-10),
])
def test_the_energy_balance_closes_on_a_corrugated_plate_with_resets(integrator, settings, bound):
    """Stored energy booked as the potentials: the residual is the scheme's error under the
    conservative contact, and shows the energy the old force creates (1-20 % of the
    dissipated energy in this run)."""
    def run(contact):
        block = Block("B", integrator, 0, True, x_start=3.0, A=0.6, omega=1.3, k_d=1e-2, V_d=1e-2, gamma_t=5e-3,
                      contact_law=contact, **settings)
        block.start()
        block.advance_to(400.0)
        return block.outputs()
    out = run("linear")
    assert out["slip_count"] > 1000  # resets all along
    assert abs(out["energy_residual"]) < bound * out["energy_dissipated"]
    old = run("linear_along_normal")
    assert abs(old["energy_residual"]) > 1e-3 * old["energy_dissipated"]
