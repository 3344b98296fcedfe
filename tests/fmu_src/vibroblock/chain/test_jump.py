"""Jumping through the chain's sticks (``vibroblock.chain.jump``, ``Chain(jump_sticks=True)``):
the same catalogue as the stepped run, the state to rounding, most steps jumped; no jump
outside the domain."""
import numpy as np
import pytest

from vibroblock import Block
from vibroblock import layout as L
from vibroblock.chain import Chain
from vibroblock.chain import jump as J
from vibroblock.chain.runner import BLOCK_DEFAULTS
from vibroblock.settings import ModelError

# The stepped run's own rounding is set by its positions: x ~ V_d t grows, and each step
# rounds x + h vx at |x| eps.  So x, F, vx (per tau_0) and the potencies are compared to
# POSITIONS times the largest |x| (measured: 2e-14 to 5e-14), phi relative to itself.
POSITIONS = 1e-12
RELATIVE = 1e-9


def stepped_and_jumped(n_blocks, t_end, **settings):
    runs = []
    for jump in (False, True):
        chain = Chain(n_blocks, jump_sticks=jump, **settings)
        chain.start()
        chain.advance_to(t_end)
        runs.append(chain)
    return runs


def assert_same_run(stepped, jumped):
    """The same catalogue (start, end, first block and blocks to the bit, potency and peak
    to rounding), the same resets, the state to rounding, the height to the bit."""
    a, b = (np.array(chain.events).reshape(-1, 6) for chain in (stepped, jumped))
    assert a.shape == b.shape
    assert a[:, :4].tolist() == b[:, :4].tolist()
    reach = POSITIONS * np.max(np.abs(stepped.Y[:, L.Y_X]))
    np.testing.assert_allclose(b[:, 4], a[:, 4], rtol=0.0, atol=stepped.n_blocks * reach)
    np.testing.assert_allclose(b[:, 5], a[:, 5], rtol=RELATIVE, atol=0.0)
    assert jumped.outputs()["coulomb_resets"] == stepped.outputs()["coulomb_resets"]
    assert jumped.cnt[L.C_STEP] == stepped.cnt[L.C_STEP]
    for slot in (L.Y_X, L.Y_F, L.Y_VX):
        assert np.max(np.abs(jumped.Y[:, slot] - stepped.Y[:, slot])) <= reach, slot
    np.testing.assert_allclose(jumped.Y[:, L.Y_PHI], stepped.Y[:, L.Y_PHI], rtol=RELATIVE, atol=0.0)
    assert jumped.Y[:, L.Y_Z].tolist() == stepped.Y[:, L.Y_Z].tolist()
    assert jumped.Y[:, L.Y_VZ].tolist() == stepped.Y[:, L.Y_VZ].tolist()


@pytest.mark.parametrize("n_blocks, t_end, settings, events, jumped_fraction", [
    (1, 6e4, {}, 10, 0.9),
    (3, 6e4, {"periodic": True, "mu_s_spread": 0.3, "load_spread": 0.2, "seed": 2}, 10, 0.6),
    (16, 4e4, {"mu_s_spread": 0.3, "seed": 1}, 10, 0.4),
    (16, 4e4, {"mu_s_spread": 0.3, "load_spread": 0.3, "seed": 4, "clusters": True}, 10, 0.4),
    (64, 2e4, {"periodic": True, "mu_s_spread": 0.3, "seed": 1}, 10, 0.2),
    (8, 4e4, {"mu_s_spread": 0.2, "friction_law": 2, "mu_k": 0.25}, 10, 0.6),
    # (the spring held at the bound: blocks creep at their bounds, below v_start, and make
    # no event; only the first loading is jumped)
    (8, 4e4, {"mu_s_spread": 0.2, "friction_law": 1}, 0, 0.02),
])
def test_a_jumped_run_is_the_stepped_run(n_blocks, t_end, settings, events, jumped_fraction):
    """Through at least ten events, free and periodic ends, spread mu_s and loads, both
    catalogues, the three friction laws whose stick is the plain spring.  (The kinetic law
    with velocity weakening, v_w > 0, is chaotic: rounding-level differences grow by one
    to two decades per event, as between any two stepped runs that round differently.)"""
    stepped, jumped = stepped_and_jumped(n_blocks, t_end, **settings)
    assert len(stepped.events) >= events and stepped.outputs()["coulomb_resets"] > 0
    assert_same_run(stepped, jumped)
    assert jumped.jumped_steps > jumped_fraction * jumped.cnt[L.C_STEP]
    assert stepped.jumped_steps == 0


def test_a_jumped_chain_of_one_block_is_the_single_block():
    """N = 1 jumped against Block("A", "symplectic_euler") stepped: the state to rounding,
    the same resets."""
    block = Block("A", "symplectic_euler", 0, False, **BLOCK_DEFAULTS)
    block.start()
    block.advance_to(5e4)
    chain = Chain(1, jump_sticks=True)
    chain.start()
    chain.advance_to(5e4)
    assert chain.jumped_steps > 0.8 * chain.cnt[L.C_STEP]
    assert block.counters["resets"] > 10 and chain.outputs()["coulomb_resets"] == block.counters["resets"]
    reach = POSITIONS * abs(block.y[L.Y_X])
    for slot in (L.Y_X, L.Y_F, L.Y_VX):
        assert abs(chain.Y[0, slot] - block.y[slot]) <= reach, slot
    assert abs(chain.Y[0, L.Y_PHI] - block.y[L.Y_PHI]) <= RELATIVE * abs(block.y[L.Y_PHI])
    assert chain.Y[0, L.Y_Z] == block.y[L.Y_Z]


def test_a_jump_through_strong_ringing_does_not_pass_the_next_failure():
    """Right after an event (gamma_t = 5e-3: the ringing decays over ~400 tau_0) every
    block sticks while the chain still rings far above its creep: the run jumps there,
    and the next events start and end at the stepped run's grid steps."""
    settings = {"mu_s_spread": 0.3, "seed": 1}
    stepped, jumped = (Chain(16, jump_sticks=jump, **settings) for jump in (False, True))
    for chain in (stepped, jumped):
        chain.start()
    t, stride = 0.0, 3 * J.JUMP_EVERY * BLOCK_DEFAULTS["dt"]  # (each stride holds two tests for a jump)
    while not stepped.events:
        t += stride
        stepped.advance_to(t)
    jumped.advance_to(t)
    creep = BLOCK_DEFAULTS["k_d"] * BLOCK_DEFAULTS["V_d"] / (BLOCK_DEFAULTS["k_d"] + 0.28)
    before = jumped.jumped_steps
    while jumped.jumped_steps == before:
        ringing = np.max(np.abs(jumped.Y[:, L.Y_VX] - creep))
        t += stride
        jumped.advance_to(t)
    assert ringing > 30.0 * creep  # (measured: 0.116, 340 times the creep, one stride before the jump)
    stepped.advance_to(3e4)
    jumped.advance_to(3e4)
    assert len(stepped.events) > 10
    assert_same_run(stepped, jumped)


@pytest.mark.parametrize("settings", [
    {"A": 0.05, "omega": 0.8},
    {"integrator": "rk4"},
    {"friction_law": 3, "rs_D_c": 0.1, "rs_V_0": 1e-3, "rs_theta_0": 100.0},
    {"model": "B", "A_x": 0.3, "omega_x": 0.5},
])
def test_outside_its_domain_a_run_does_not_jump(settings):
    """A vibrated plate, rk4, rate-and-state friction, a corrugated plate: jump_sticks changes
    nothing, to the bit."""
    stepped, jumped = stepped_and_jumped(4, 3000.0, mu_s_spread=0.3, **settings)
    assert not jumped.jumps_possible()
    assert jumped.jumped_steps == 0
    assert jumped.Y.tolist() == stepped.Y.tolist() and jumped.events == stepped.events


def test_plate_inputs_stop_the_jumps_while_they_move_the_plate():
    chain = Chain(4, jump_sticks=True)
    chain.start()
    assert chain.jumps_possible()
    chain.set_plate_input(0.0, 0.0, 1e-3)
    assert not chain.jumps_possible()
    chain.set_plate_input(0.0, 0.0, 0.0)
    assert chain.jumps_possible()


def test_jumps_with_the_energy_balance_are_refused():
    with pytest.raises(ModelError, match="jump_sticks with energy_balance"):
        Chain(4, jump_sticks=True, energy_balance=True).start()


def test_a_restored_state_jumps_as_the_run_did():
    """get_state in the middle of a stick, then on: a chain set to that state continues to
    the same bits, jumps included."""
    chain = Chain(8, jump_sticks=True, mu_s_spread=0.3)
    chain.start()
    chain.advance_to(2000.0)
    state = chain.get_state()
    chain.advance_to(2e4)
    again = Chain(8)
    again.set_state(state)
    assert again.jump_sticks
    again.advance_to(2e4)
    assert again.jumped_steps == chain.jumped_steps > state["jumped_steps"]
    assert again.Y.tolist() == chain.Y.tolist() and again.events == chain.events


@pytest.mark.parametrize("n_blocks, periodic", [(1, False), (1, True), (2, True), (5, False), (6, True)])
def test_the_modes_diagonalize_the_kernels_coupling(n_blocks, periodic):
    """J.laplacian is the kernel's pull (two blocks with periodic ends pull each other
    twice), J.pull sums it as the kernel does, and the modes are orthonormal."""
    x = np.random.default_rng(3).normal(size=n_blocks)
    lap = J.laplacian(n_blocks, periodic)
    np.testing.assert_allclose(J.pull(x, periodic), lap @ x, atol=1e-14)
    if n_blocks == 2 and periodic:
        assert lap.tolist() == [[-2.0, 2.0], [2.0, -2.0]]
    modes = J.Modes(n_blocks, periodic)
    np.testing.assert_allclose(modes.Q @ np.diag(modes.eigenvalues) @ modes.Q.T, -lap, atol=1e-13)
    np.testing.assert_allclose(modes.Q.T @ modes.Q, np.eye(n_blocks), atol=1e-13)
