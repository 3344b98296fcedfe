"""The chain on an obliquely or horizontally shaken plate (plate_motion = 1, the single
block's law ``laws.plate_oblique``): one block is the single block to the bit, blocks below
the friction threshold ride the plate as the linear equations (solved by scipy, independent
of the kernels) say, uncoupled blocks are single blocks, and the refusals."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from vibroblock import Block
from vibroblock import layout as L

from chain_testing import chain_of, run_side_by_side
from vibroblock.chain import kernel as K
from vibroblock.settings import ModelError

# Stick-slip of the single block's benchmarks on a plate shaken along 1 rad from the vertical.
OBLIQUE = dict(A=0.6, omega=0.8, k_d=1e-2, V_d=1e-2, gamma_t=5e-3, dt=1e-2, plate_motion="oblique", drive_angle=1.0)
HORIZONTAL = math.pi / 2
K_T, GAMMA_T, MU_S = 0.28, 5e-3, 0.5  # model A's k_t and mu_s (m = g = 1)


@pytest.mark.parametrize("integrator", ["symplectic_euler", "rk4"])
@pytest.mark.parametrize("law", [{}, {"friction_law": 2, "mu_k": 0.3, "v_w": 0.5}])
def test_a_chain_of_one_block_is_the_single_oblique_block_bit_for_bit(law, integrator):
    """The same plate law, the same frame force, the same arithmetic: every state slot
    (kept in the plate's frame), the lab's x and vx, the resets and the energy residual
    equal Block("A", plate_motion = oblique)'s, through slips."""
    block = Block("A", integrator, 0, True, **OBLIQUE, **law)
    chain = chain_of(1, energy_balance=True, integrator=integrator, **OBLIQUE, **law)
    run_side_by_side(block, chain)
    assert block.counters["resets"] > 10
    assert chain.Y[0, :L.Y_E_START].tolist() == block.y[:L.Y_E_START].tolist()
    out = block.outputs()
    assert (chain.x[0], chain.vx[0]) == (out["x"], out["vx"])
    assert chain.x[0] != chain.Y[0, L.Y_X]  # (the lab's x is not the plate frame's)
    assert chain.outputs()["energy_residual"] == out["energy_residual"]
    assert chain.outputs()["coulomb_resets"] == block.counters["resets"]


def stuck_reference(amplitude, omega, k_p, times):
    """A block held by its friction spring on the horizontally shaken plate (in contact,
    no reset, V_d = 0): in the plate's frame m X'' = -k_t X - gamma_t X' - k_p (X + p_x)
    - m p_x'', p_x = A sin(omega t), from rest on the plate; scipy's DOP853 at rtol 1e-12.
    Returns the lab's x = X + p_x."""
    def rates(t, y):
        x, v = y
        p_x = amplitude * math.sin(omega * t)
        return [v, -K_T * x - GAMMA_T * v - k_p * (x + p_x) + omega * omega * p_x]
    solution = solve_ivp(rates, (0.0, times[-1]), [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-14,
                         t_eval=times)
    return solution.y[0] + amplitude * np.sin(omega * times)


def _shaken(integrator, factor, omega=0.1, k_p=1e-3):
    """Four heterogeneous blocks (mu_s and weight spread by 20 %) on a plate shaken
    horizontally at ``factor`` times the weakest block's rigid threshold A omega^2 = mu_s_i g_i."""
    chain = chain_of(4, integrator=integrator, k_c=0.5, k_p=k_p, V_d=0.0, gamma_t=GAMMA_T, omega=omega,
                   plate_motion=1, drive_angle=HORIZONTAL, mu_s_spread=0.2, load_spread=0.2, seed=3)
    weakest = float(np.min(chain.heterogeneity()[0] * chain.heterogeneity()[1]))
    chain.set_parameter("A", factor * weakest / omega ** 2)
    chain.start()
    return chain, weakest


@pytest.mark.parametrize("integrator, tolerance", [("symplectic_euler", 2e-5), ("rk4", 1e-10)])
def test_blocks_below_the_friction_threshold_ride_the_horizontally_shaken_plate(integrator, tolerance):
    """m A omega^2 at 0.6 of the weakest block's mu_s m g: no block resets, all move
    together (the coupling springs stay unstretched) and with the plate, displaced from it
    only by the friction spring's compliance, as the linear equations' reference says; at
    1.3 times the strongest block's threshold every block slips."""
    omega, k_p = 0.1, 1e-3
    chain, weakest = _shaken(integrator, 0.6, omega, k_p)
    amplitude = chain.parameter("A")
    times = np.arange(2.0, 200.0, 2.0)
    rows = []
    for t in times:
        chain.advance_to(t)
        rows.append(chain.x)
    got = np.array(rows)
    want = stuck_reference(amplitude, omega, k_p, times)
    assert chain.outputs()["coulomb_resets"] == 0 and chain.outputs()["event_count"] == 0
    assert np.max(np.abs(got - want[:, None])) < tolerance * amplitude
    relative = got - (amplitude * np.sin(omega * times))[:, None]  # the sway on the plate
    assert np.max(np.abs(relative)) < 0.1 * amplitude
    assert np.max(np.abs(got - got[:, :1])) < 1e-9 * amplitude
    strongest = float(np.max(chain.heterogeneity()[0] * chain.heterogeneity()[1]))
    slipping, _ = _shaken(integrator, 1.3 * strongest / weakest, omega, k_p)
    slipping.advance_to(2 * math.pi / omega)
    assert np.all(slipping.scratch[:, K.S_RESETS] > 0)  # every block has reset


def test_uncoupled_blocks_are_independent_single_oblique_blocks():
    """k_c = 0 on the obliquely shaken plate: each block is Block("A", plate_motion =
    oblique) with its own mu_s and g, bit for bit in its state and its lab x."""
    chain = chain_of(3, k_c=0.0, mu_s_spread=0.3, load_spread=0.3, seed=5, **OBLIQUE)
    chain.start()
    chain.advance_to(1500.0)
    resets = 0
    for i, (mu_s, gravity) in enumerate(zip(chain.mu_s, chain.gravity)):
        block = Block("A", "symplectic_euler", 0, False, **{**OBLIQUE, "mu_s": float(mu_s), "g": float(gravity)})
        block.start()
        block.advance_to(1500.0)
        assert chain.Y[i, :5].tolist() == block.y[:5].tolist()
        assert chain.x[i] == block.outputs()["x"]
        resets += block.counters["resets"]
    assert resets > 0 and len(set(chain.x)) == 3


def test_with_rk4_the_energy_balance_of_a_coupled_chain_closes_in_the_plate_s_frame():
    """Six coupled blocks of spread mu_s on the obliquely shaken plate through hundreds of
    events: the stored energy (kinetic relative to the plate, leaf, friction, contact and
    coupling springs) less the work (the frame's force included) plus the dissipation is
    1.5e-10 of the dissipated energy (rk4's first-order resets; symplectic Euler's is 4e-2
    here); a frame force left out of the books would leave the work's order."""
    chain = chain_of(6, energy_balance=True, integrator="rk4", mu_s_spread=0.3, seed=2, **OBLIQUE)
    chain.start()
    chain.advance_to(3000.0)
    out = chain.outputs()
    assert out["event_count"] > 100 and out["coulomb_resets"] > 100
    assert abs(out["energy_residual"]) < 1e-9 * out["energy_dissipated"]


def test_the_catalogue_follows_the_slip_velocity_relative_to_the_plate():
    """A plate shaken horizontally at 2 delta_0/tau_0 peak speed carries stuck blocks along:
    their lab speed exceeds v_start, their slip velocity does not, and no event opens."""
    chain, _ = _shaken("rk4", 0.6)
    chain.advance_to(200.0)
    assert chain.parameter("A") * 0.1 > 5 * chain.parameter("v_start")
    assert chain.outputs()["event_count"] == 0 and chain.outputs()["slipping_fraction"] == 0.0
    assert np.max(np.abs(chain.slip_velocity)) < chain.parameter("v_stop")


def test_horizontal_inputs_and_bad_directions_are_refused_saying_why():
    vertical = chain_of(2)
    vertical.start()
    with pytest.raises(ModelError, match="plate_motion = 1"):
        vertical.set_plate_input(0.0, 0.0, 0.0, 0.1, 0.0, 0.0)
    vertical.set_plate_input(0.1, 0.0, 0.0)  # a vertical input is taken as before
    for angle in (math.nan, math.inf):
        with pytest.raises(ModelError, match="drive_angle"):
            chain_of(2, plate_motion=1, drive_angle=angle)
    with pytest.raises(ModelError, match="rk4|symplectic_euler"):
        chain_of(2, plate_motion=1, integrator="adaptive")
