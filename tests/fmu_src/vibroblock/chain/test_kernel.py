"""The chain's step (``vibroblock.chain.kernel``): the single block's physics per block,
the coupling springs' normal modes, the energy balance, and the event catalogue."""
import math

import numpy as np
import pytest

from vibroblock import Block
from vibroblock import layout as L
from vibroblock.chain import Chain

from chain_testing import chain_of, run_side_by_side
from vibroblock.chain import runner
from vibroblock.settings import ModelError

# Stick-slip of the single block's benchmarks, on a vibrating plate (resets, detachments).
VIBRATED = dict(A=0.3, omega=0.8, k_d=1e-2, V_d=1e-2, gamma_t=5e-3, dt=1e-2)


RATE_STATE = {"friction_law": 3, "rs_D_c": 0.1, "rs_V_0": 1e-3, "rs_theta_0": 100.0}


@pytest.mark.parametrize("integrator", ["symplectic_euler", "rk4"])
@pytest.mark.parametrize("law", [{}, {"friction_law": 2, "mu_k": 0.3, "v_w": 0.5}, RATE_STATE])
def test_a_chain_of_one_block_is_the_single_block_bit_for_bit(law, integrator):
    """Same laws, same scheme, same arithmetic: every state slot and the energy residual
    (under the paper's friction, and under the kinetic and the rate-and-state laws, whose
    state rides along), with either scheme."""
    block = Block("A", integrator, 0, True, **VIBRATED, **law)
    chain = chain_of(1, energy_balance=True, integrator=integrator, **VIBRATED, **law)
    run_side_by_side(block, chain)
    if law is RATE_STATE:  # the run exercised the friction rule: theta moved (it has no resets)
        assert abs(block.y[L.Y_FRICTION_STATE] - RATE_STATE["rs_theta_0"]) > 1.0
    else:
        assert block.counters["resets"] > 10
    assert chain.Y[0, :L.Y_E_START].tolist() == block.y[:L.Y_E_START].tolist()  # (the chain books E_start itself)
    assert chain.Y[0, L.Y_FRICTION_STATE] == block.y[L.Y_FRICTION_STATE]
    assert chain.outputs()["energy_residual"] == block.outputs()["energy_residual"]
    assert chain.outputs()["coulomb_resets"] == block.counters["resets"]


# A corrugated plate the block stick-slips over (wavelength 12.6 delta_0, slope up to 0.15),
# followed over 2e4 tau_0 (the drive travels 16 wavelengths).
CORRUGATION = {"A_x": 0.3, "omega_x": 0.5}


@pytest.mark.parametrize("integrator", ["symplectic_euler", "rk4"])
@pytest.mark.parametrize("model", ["B", "C"])
def test_a_chain_of_one_block_on_a_corrugated_plate_is_the_single_block_bit_for_bit(model, integrator):
    """Models B and C: the same profile, load, contact and friction per block, so every
    state slot, the resets and the energy residual are Block(model)'s."""
    block = Block(model, integrator, 0, True, **VIBRATED, **CORRUGATION)
    chain = chain_of(1, model=model, energy_balance=True, integrator=integrator, **VIBRATED, **CORRUGATION)
    run_side_by_side(block, chain, np.arange(1, 201) * 100.0)
    assert block.counters["resets"] > 100 and block.y[L.Y_X] > 10 * 2 * math.pi / CORRUGATION["omega_x"]
    assert chain.Y[0, :L.Y_E_START].tolist() == block.y[:L.Y_E_START].tolist()
    assert chain.outputs()["energy_residual"] == block.outputs()["energy_residual"]
    assert chain.outputs()["coulomb_resets"] == block.counters["resets"]


def test_uncoupled_blocks_on_a_corrugated_plate_are_single_blocks_with_their_own_mu_s():
    chain = chain_of(3, model="B", k_c=0.0, mu_s_spread=0.4, load_spread=0.3, seed=7, **VIBRATED, **CORRUGATION)
    chain.start()
    chain.advance_to(1500.0)
    for i, (mu_s, gravity) in enumerate(zip(chain.mu_s, chain.gravity)):
        block = Block("B", "symplectic_euler", 0, False, **{**VIBRATED, **CORRUGATION, "mu_s": float(mu_s),
                                                            "g": float(gravity)})
        block.start()
        block.advance_to(1500.0)
        assert chain.Y[i, :5].tolist() == block.y[:5].tolist()


def test_model_c_has_no_weight_to_spread():
    with pytest.raises(ModelError, match="load_spread = 0.2 spreads g, which model C does not have"):
        Chain(3, model="C", load_spread=0.2).start()
    with pytest.raises(ModelError, match="unknown model 'D'"):
        Chain(3, model="D")


def test_uncoupled_blocks_are_independent_single_blocks_with_their_own_mu_s():
    chain = chain_of(3, k_c=0.0, mu_s_spread=0.4, seed=7, **VIBRATED)
    chain.start()
    chain.advance_to(1500.0)
    assert len(set(chain.mu_s)) == 3
    for i, mu_s in enumerate(chain.mu_s):
        block = Block("A", "symplectic_euler", 0, False, **{**VIBRATED, "mu_s": float(mu_s)})
        block.start()
        block.advance_to(1500.0)
        assert chain.Y[i, :5].tolist() == block.y[:5].tolist()


def test_uncoupled_blocks_with_spread_loads_are_single_blocks_of_those_weights():
    """k_c = 0 and both spreads: each block is Block("A") with its own mu_s and g, bit for
    bit, on a vibrated plate; a block of the model's weight would sit elsewhere on its
    contact (the loads reach the contact)."""
    chain = chain_of(3, k_c=0.0, mu_s_spread=0.3, load_spread=0.5, seed=9, **VIBRATED)
    chain.start()
    chain.advance_to(1500.0)
    assert len(set(chain.gravity)) == 3 and not np.any(chain.gravity == 1.0)
    runs = []
    for i, (mu_s, gravity) in enumerate(zip(chain.mu_s, chain.gravity)):
        block = Block("A", "symplectic_euler", 0, False, **{**VIBRATED, "mu_s": float(mu_s), "g": float(gravity)})
        block.start()
        block.advance_to(1500.0)
        assert chain.Y[i, :5].tolist() == block.y[:5].tolist()
        runs.append(block.y[L.Y_Z])
    same_load = Block("A", "symplectic_euler", 0, False, **{**VIBRATED, "mu_s": float(chain.mu_s[0])})
    same_load.start()
    same_load.advance_to(1500.0)
    assert same_load.y[L.Y_Z] != runs[0]


def test_uncoupled_blocks_with_spread_rate_state_parameters_are_single_blocks_of_those():
    """k_c = 0, rate-and-state friction with a, b and D_c spread: each block is Block("A")
    with its own a, b, D_c and weight, bit for bit (state slots and theta), on a vibrated
    plate; the blocks' thetas part (the laws reach each block)."""
    spreads = {"rs_a_spread": 0.3, "rs_b_spread": 0.4, "rs_D_c_spread": 0.5, "load_spread": 0.2}
    chain = chain_of(3, k_c=0.0, seed=5, **VIBRATED, **RATE_STATE, **spreads)
    chain.start()
    chain.advance_to(1500.0)
    drawn = chain.drawn()
    assert all(len(set(drawn[name])) == 3 for name in ("rs_a", "rs_b", "rs_D_c"))
    for i in range(3):
        own = {name: float(drawn[name][i]) for name in ("rs_a", "rs_b", "rs_D_c", "g")}
        block = Block("A", "symplectic_euler", 0, False, **{**VIBRATED, **RATE_STATE, **own})
        block.start()
        block.advance_to(1500.0)
        assert chain.Y[i, :5].tolist() == block.y[:5].tolist()
        assert chain.Y[i, L.Y_FRICTION_STATE] == block.y[L.Y_FRICTION_STATE]
    assert len(set(chain.Y[:, L.Y_FRICTION_STATE].tolist())) == 3


def _laplacian(n, periodic):
    lap = 2.0 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    if periodic:
        lap[0, -1] = lap[-1, 0] = -1.0
    else:
        lap[0, 0] = lap[-1, -1] = 1.0
    return lap


def _frequency(samples, dt):
    """Angular frequency of a sampled sinusoid from its first and last upward zero crossings."""
    crossings = []
    for k in range(len(samples) - 1):
        if samples[k] < 0.0 <= samples[k + 1]:
            crossings.append(k + samples[k] / (samples[k] - samples[k + 1]))
    return 2.0 * math.pi * (len(crossings) - 1) / ((crossings[-1] - crossings[0]) * dt)


@pytest.mark.parametrize("n, periodic", [(2, False), (3, False), (3, True)])
def test_small_oscillations_of_stuck_blocks_ring_at_the_normal_mode_frequencies(n, periodic):
    """Stuck blocks (the Cundall-Strack spring holds, no damping): horizontal stiffness
    (k_p + k_t) I + k_c L, L the chain's Laplacian; each mode, kicked alone, rings at
    omega_j = sqrt(eigenvalue / m), as symplectic Euler renders it:
    (2/h) arcsin(omega_j h / 2)."""
    k_p, k_t, k_c, dt = 1e-2, 0.28, 0.5, 1e-2
    values, vectors = np.linalg.eigh((k_p + k_t) * np.eye(n) + k_c * _laplacian(n, periodic))
    for j in range(n):
        if j > 0 and abs(values[j] - values[j - 1]) < 1e-12:
            continue  # a degenerate pair (periodic): the first of it is enough
        chain = chain_of(n, periodic=periodic, k_d=k_p, k_t=k_t, k_c=k_c, dt=dt, V_d=0.0, gamma_t=0.0,
                       v_start=1.0, v_stop=0.5)
        chain.start()
        chain.set_velocities(1e-4 * vectors[:, j])
        samples = []
        for step in range(1, 40001):
            chain.advance_to(step * 5 * dt)
            samples.append(vectors[:, j] @ chain.x)
        expected = 2.0 / dt * math.asin(math.sqrt(values[j]) * dt / 2.0)
        assert _frequency(np.array(samples), 5 * dt) == pytest.approx(expected, rel=2e-5)
        assert chain.outputs()["coulomb_resets"] == 0


@pytest.mark.parametrize("n, periodic", [(4, False), (2, True)])
def test_the_energy_balance_closes_at_first_order_in_dt(n, periodic):
    """Stored energy (blocks and coupling springs) - stored at start - work + dissipated:
    symplectic Euler's first-order error, halved with dt; a coupling energy left out of
    the books would not shrink (two blocks with periodic ends: two springs between them)."""
    residuals = []
    for dt in (1e-2, 5e-3):
        chain = chain_of(n, energy_balance=True, periodic=periodic, k_c=1.0, mu_s_spread=0.2, seed=3,
                       **{**VIBRATED, "dt": dt})
        chain.start()
        chain.advance_to(3000.0)
        outputs = chain.outputs()
        assert outputs["event_count"] > 5
        residuals.append(abs(outputs["energy_residual"]))
        assert residuals[-1] < 2e-2 * outputs["work_input"]
    assert 1.6 < residuals[0] / residuals[1] < 2.5


def test_an_event_of_one_uncoupled_block_has_that_blocks_slip_as_potency():
    """k_c = 0: an event of one block is that block's slip between the event's start and
    end, which an independent single-block run gives."""
    chain = chain_of(2, k_c=0.0, mu_s_spread=0.3, seed=2, **VIBRATED)
    chain.start()
    chain.advance_to(4000.0)
    single = [event for event in chain.events if event[3] == 1]
    assert len(single) >= 3
    for t_start, t_end, first, _, potency, peak in single[:3]:
        block = Block("A", "symplectic_euler", 0, False, **{**VIBRATED, "mu_s": float(chain.mu_s[int(first)])})
        block.start()
        block.advance_to(t_start)
        before = block.output("x")
        block.advance_to(t_end)
        assert potency == pytest.approx(block.output("x") - before, rel=1e-12, abs=1e-12)
        assert peak > chain.chain_parameters["v_start"]


def test_a_full_catalogue_loses_no_event_and_changes_nothing(monkeypatch):
    """Without vibration the run does not depend on where the kernel stops: a catalogue of
    two rows, emptied whenever full, gives the same events and the same state."""
    parameters = dict(VIBRATED, A=0.0, omega=0.0)
    big = chain_of(8, mu_s_spread=0.3, seed=5, **parameters)
    big.start()
    big.advance_to(6000.0)
    monkeypatch.setattr(runner, "CATALOG_ROWS", 2)
    small = chain_of(8, mu_s_spread=0.3, seed=5, **parameters)
    small.start()
    small.advance_to(6000.0)
    assert len(big.events) > 4
    assert small.events == big.events
    assert small.Y.tolist() == big.Y.tolist()
    assert small.outputs()["event_count"] == len(big.events)


@pytest.mark.parametrize("periodic, amplitude", [(False, 0.3), (True, 0.0)], ids=["vibrated", "still-periodic"])
def test_the_default_physics_compiled_as_constants_gives_the_bits_of_the_run_time_branches(periodic, amplitude):
    """The default physics runs a pass compiled with its kind as a constant, every other
    kind the same pass branching at run time.  contact_law = 1 is the default contact on
    a flat plate (the same functions, docs: laws) under another kind: a coupled,
    heterogeneous chain through stick-slip events gives the same bits either way, state,
    catalogue and energy balance."""
    chains = []
    for contact_law in (0, 1):
        chain = chain_of(12, periodic=periodic, energy_balance=True, mu_s_spread=0.3, load_spread=0.2, seed=3,
                         contact_law=contact_law, **dict(VIBRATED, V_d=2e-2, A=amplitude))
        chain.start()
        chain.advance_to(6000.0)
        chains.append(chain)
    default, other = chains
    assert default.settings.kind == 0 and other.settings.kind != 0
    assert len(default.events) >= 5 and default.outputs()["coulomb_resets"] > 100
    assert other.Y.tolist() == default.Y.tolist()
    assert other.events == default.events
    assert other.outputs() == default.outputs()


def _catalogue_by_the_rule(chain, t_end):
    """Step ``chain`` one grid step at a time and apply the chain-wide catalogue's rule
    (docs/chain.md) to the slip speeds after each step: an event opens at the first step
    with a block's |vx| > v_start (its start: that step's start and its positions then),
    holds every block that exceeds v_start while it is open, and closes at the first step
    after which every |vx| < v_stop, its potency the sum of its blocks' slips."""
    v_start, v_stop = chain.chain_parameters["v_start"], chain.chain_parameters["v_stop"]
    dt, events, event = chain.parameter("dt"), [], None
    while chain.grid_time + dt <= t_end:
        t, before = chain.grid_time, chain.x
        chain.advance_to(t + dt)
        speeds = np.abs(chain.slip_velocity)
        if event is None and np.any(speeds > v_start):
            event = {"start": t, "first": int(np.argmax(speeds > v_start)), "x": before, "peak": 0.0,
                     "joined": np.zeros(chain.n_blocks, dtype=bool)}
        if event is None:
            continue
        event["joined"] |= speeds > v_start
        event["peak"] = max(event["peak"], float(speeds.max()))
        if np.all(speeds < v_stop):
            potency = 0.0
            for i in np.flatnonzero(event["joined"]):  # (in the blocks' order, as the kernel sums)
                potency += chain.x[i] - event["x"][i]
            events.append((event["start"], chain.grid_time, float(event["first"]), float(event["joined"].sum()),
                           potency, event["peak"]))
            event = None
    return events


def test_the_catalogue_is_its_rule_applied_to_the_steps():
    """The catalogue the step's pass keeps on the way equals the rule applied step by
    step from outside to the same run (a chain stepped one grid step per call, which
    changes nothing: the test of a full catalogue)."""
    parameters = dict(VIBRATED, A=0.0, omega=0.0, V_d=5e-2)
    reference = chain_of(8, mu_s_spread=0.3, seed=5, **parameters)
    reference.start()
    expected = _catalogue_by_the_rule(reference, 1500.0)
    chain = chain_of(8, mu_s_spread=0.3, seed=5, **parameters)
    chain.start()
    chain.advance_to(reference.grid_time)
    assert len(expected) >= 3 and any(event[3] > 1 for event in expected)
    assert chain.events == reference.events == expected


@pytest.mark.parametrize("law, tolerance", [({}, 1e-9), (RATE_STATE, 1e-12)], ids=["paper", "rate_state"])
def test_with_rk4_the_energy_balance_closes_to_rounding_between_resets(law, tolerance):
    """Eight heterogeneous blocks through stick-slip events, no vibration: rk4 is one
    fourth-order system over all blocks (each stage's coupling from the stage's
    positions).  The residual is the resets' first-order share under the paper's law
    (1e-10 of the dissipated energy at dt = 1e-2, and a thirtieth of it at dt = 5e-3),
    rounding under rate-and-state friction, which has no reset; symplectic Euler's is
    of order dt (3e-3 here)."""
    residuals = {}
    for integrator in ("symplectic_euler", "rk4"):
        chain = chain_of(8, integrator=integrator, energy_balance=True, mu_s_spread=0.2, seed=1, **law)
        chain.start()
        chain.advance_to(20000.0)
        outputs = chain.outputs()
        assert outputs["event_count"] >= 10
        residuals[integrator] = abs(outputs["energy_residual"]) / outputs["energy_dissipated"]
    assert residuals["rk4"] < tolerance
    assert residuals["symplectic_euler"] > 1e-4


@pytest.mark.parametrize("integrator", ["implicit_contact", "adaptive", 4])
def test_the_chain_runs_symplectic_euler_or_rk4_and_says_so(integrator):
    with pytest.raises(ModelError, match="the chain runs symplectic_euler .0. or rk4 .1."):
        Chain(3, integrator=integrator)


def test_rk4_s_looser_step_bound_is_checked_with_the_coupling():
    """rk4 asks dt^2 k/m <= 4 where symplectic Euler asks <= 1 (k: the stiffest mode's)."""
    Chain(4, integrator="rk4", k_c=1.0, dt=0.9).start()
    with pytest.raises(ModelError, match="> 1 .symplectic_euler.; take dt <= 0.483"):
        Chain(4, integrator="symplectic_euler", k_c=1.0, dt=0.9).start()
    with pytest.raises(ModelError, match="> 4 .rk4."):
        Chain(4, integrator="rk4", k_c=1.0, dt=1.1).start()


def test_a_state_of_another_layout_is_refused_and_the_run_goes_on():
    """A state whose constants or scratch arrays have another length (saved by another
    version of the chain) would be read past its end by the kernel: refused."""
    chain = chain_of(3)
    chain.start()
    chain.advance_to(10.0)
    state = chain.get_state()
    for name, cut in (("chn", lambda a: a[:-1]), ("scratch", lambda a: [row[:6] for row in a])):
        with pytest.raises(ModelError, match="another layout"):
            chain.set_state({**state, name: cut(state[name])})
    chain.advance_to(20.0)
    assert chain.time == 20.0
