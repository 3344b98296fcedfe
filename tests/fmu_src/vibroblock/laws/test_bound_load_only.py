"""The load-only Coulomb bound mu_s N_L, N_L = -load . n: it cannot self-lock."""
import math

import pytest

from vibroblock import Block
from vibroblock.block import ModelError

A_X, W_X = 1e3, 2e-2  # the paper's corrugation


def dragged_up_a_steep_flank(bound, slope=5.0, t_end=1500.0):
    """Displacement of a block on the upper part of a flank of model B's corrugation with
    tan a = ``slope`` > 1 / mu_s = 2, held at t = 0 by the drive spring (anchored uphill),
    whose pull then grows at V_d by 2.1 m g, four times the 0.5 m g that the load-only
    bound mu_s m g cos a can hold against.  The contact-force bound holds any pull: the
    pull presses the block into the flank (N = m g cos a + f sin a) faster
    than it loads the friction (T = f cos a - m g sin a) while tan a > 1 / mu_s."""
    phase = math.acos(slope / (A_X * W_X)) - 2.0 * math.pi  # below a crest, a period behind the anchor
    x0 = phase / W_X
    cos_a = 1.0 / math.sqrt(1.0 + slope * slope)
    # At rest with no friction force: N = m g / cos a (delta = N / k_n), and along x the
    # drive balances N sin a less the conservative contact's curvature term
    # C = k_n delta^2 sin a cos a h''(x) (docs/physics.md, Sec. 3): an exact equilibrium.
    delta = 1.0 / cos_a
    curvature_term = delta * delta * slope * cos_a * cos_a * (-A_X * W_X * W_X * math.sin(phase))
    k_d = (slope - curvature_term) / -x0
    block = Block("B", "rk4", 1, dt=1e-2, k_d=k_d, V_d=5e-2, A_x=A_X, omega_x=W_X, coulomb_normal=bound,
                  x_start=x0, z_start=A_X * math.sin(phase) - delta / cos_a)
    block.start()
    block.advance_to(t_end)
    return block.output("x") - x0


def test_a_block_dragged_up_a_flank_steeper_than_the_friction_angle_slides_under_the_load_only_bound():
    assert dragged_up_a_steep_flank("load_only") > 20.0


def test_and_jams_under_the_contact_force_bound():
    # held: the block creeps only by the friction spring's deflection, T / k_t ~ 1 delta_0
    assert abs(dragged_up_a_steep_flank("contact_force")) < 2.0


@pytest.mark.parametrize("model, expected", [("A", 1.0), ("B", 1.0 / math.sqrt(1.0 + (A_X * W_X) ** 2)), ("C", 2.0)])
def test_the_bound_is_the_load_alone(model, expected):
    """m g on A, m g cos a on B (at x = 0, slope A_x omega_x), P_l on C, whatever the
    contact force and the drive spring's stretch."""
    from vibroblock import laws
    extra = {"P_l": 2.0} if model == "C" else {}
    block = Block(model, "symplectic_euler", 1, k_d=1e-2, V_d=1e-2, coulomb_normal="load_only", **extra)
    block.start()
    normal = laws.law("bound", 2).module.normal
    for contact_normal, t in ((-99.0, 0.0), (3.0, 500.0)):
        assert normal(block.settings.kind, contact_normal, 0.0, t, block.prm) == pytest.approx(expected, rel=1e-12)


def test_event_driven_refuses_it_saying_why():
    with pytest.raises(ModelError, match="Coulomb resets on the oscillating contact force"):
        Block("A", "event_driven", coulomb_normal="load_only").start()
