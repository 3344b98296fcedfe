"""Closed forms of harness.paper.analytic against the core and known values."""
from __future__ import annotations

import math

import pytest

from harness.paper.analytic import bouncing_floor, bouncing_floor_omega, restitution


@pytest.mark.parametrize("k_n, gamma_n, m", [(1.0, 0.035, 1.0), (1.0, 0.07, 1.0), (1.0, 0.28, 1.0), (4.0, 0.5, 2.0)])
def test_restitution_matches_a_simulated_single_impact(k_n, gamma_n, m):
    """Without gravity the block falls onto the resting plate, rebounds once and flies off:
    its outgoing speed over its incoming speed is e (the core's exact event-driven scheme)."""
    from vibroblock import Block

    incoming = 1.0
    block = Block("A", "event_driven", 1, False, A=0.0, omega=0.0, g=0.0, V_d=0.0, k_d=0.0, k_n=k_n,
                  gamma_n=gamma_n, m=m, z_start=1.0, vz_start=-incoming)
    block.start(0.0)
    contact_time = math.pi / math.sqrt(k_n / m - (gamma_n / (2 * m)) ** 2)
    block.advance_to(1.0 / incoming + 2.0 * contact_time)  # fall, one impact, then flight
    out = block.outputs()
    assert not out["contact"] and out["vz"] > 0.0
    assert out["vz"] / incoming == pytest.approx(float(restitution(k_n, gamma_n, m)), rel=1e-6)


def test_bouncing_floor_limits_and_the_design_values():
    assert bouncing_floor(1.0) == 0.0  # an elastic ball bounces on any vibration
    assert bouncing_floor(0.0) == pytest.approx(math.pi)  # a plastic one needs A omega^2 = pi g
    # docs/physics.md, Sec. 8: for A = 10, omega* = 0.093, 0.131, 0.186, 0.262 at gamma_n = 0.035 ... 0.28.
    found = [float(bouncing_floor_omega(10.0, gamma_n=g)) for g in (0.035, 0.07, 0.14, 0.28)]
    assert found == pytest.approx([0.093, 0.131, 0.186, 0.262], abs=1e-3)


def test_overdamped_contact_is_refused():
    with pytest.raises(ValueError, match="overdamped"):
        restitution(k_n=1.0, gamma_n=3.0, m=1.0)
