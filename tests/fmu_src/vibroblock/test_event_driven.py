"""The event-driven exact scheme (model A): analytic results, RK4, and the integrator contract."""
import json
import math

import numpy as np
import pytest

from vibroblock import Block, ModelError, defaults, detachment_amplitude, steady_orbit
from vibroblock.integrators import event_driven

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
STATE = ("x", "z", "vx", "vz", "friction_force", "normal_force", "phi_integral")


def exact(**settings) -> Block:
    block = Block("A", "event_driven", **settings)
    block.start()
    return block


def sample(block, times, *names):
    rows = []
    for t in times:
        block.advance_to(t)
        out = block.outputs()
        rows.append([out[n] for n in names])
    return np.array(rows, dtype=float).T


def c1(p):
    creep = p["V_d"] * p["k_d"] / (p["k_t"] + p["k_d"])
    return creep, p["mu_s"] * p["m"] * p["g"] / (p["k_t"] * creep), p["mu_s"] * p["m"] * p["g"] / p["k_d"]


def test_scaled_stick_slip_matches_claim_c1_closely():
    """Creep velocity and stick time are exact up to the start transient (here < 1e-4);
    the slip is a whole number of resets, a few percent off mu_s m g / k_d."""
    p = {**defaults("A"), **SCALED}
    creep, t_stick, slip = c1(p)
    block = exact(**SCALED)
    x_a, x_b = sample(block, [2000.0, 4000.0], "x")[0]
    assert (x_b - x_a) / 2000.0 == pytest.approx(creep, rel=1e-4)
    times = np.arange(t_stick - 20.0, t_stick + 20.0, 0.01)
    slips, x = sample(block, times, "slip_count", "x")
    onset = times[np.argmax(slips > 0)]
    assert onset == pytest.approx(t_stick, rel=1e-4)
    block.advance_to(t_stick + 400.0)  # the slip is over
    assert block.output("x") - x[np.argmax(slips > 0) - 1] == pytest.approx(slip, rel=5e-2)


def test_paper_parameters_three_cycles_in_well_under_a_second():
    """k_d = 5e-4, V_d = 2e-5: stick time 5e7 tau_0 (1.25e11 paper steps) and slip 1000."""
    p = defaults("A")
    creep, t_stick, slip = c1(p)
    block = exact()
    times = np.linspace(t_stick / 50, 3.2 * t_stick, 160)
    (x,) = sample(block, times, "x")
    jumps = np.flatnonzero(np.diff(x) > 0.1 * slip)
    assert len(jumps) == 3
    intervals = np.diff(times[jumps])
    assert intervals == pytest.approx(t_stick, rel=2 * (times[1] - times[0]) / t_stick)
    lengths = x[jumps + 1] - x[jumps]
    assert lengths == pytest.approx(slip, rel=5e-2)


def test_steady_orbit_below_onset_is_followed_exactly_at_any_dt():
    amplitude, omega = 0.5 * float(detachment_amplitude(0.8)), 0.8
    for dt in (1e-3, 0.77):
        block = exact(initial_state=2, A=amplitude, omega=omega, k_d=0.0, V_d=0.0, dt=dt)
        for t in (0.5, 13.0, 977.3, 1e5 + 0.1):
            block.advance_to(t)
            offset, _ = steady_orbit(1.0, 1.0, 0.07, 1.0, amplitude, omega, omega * t)
            assert block.output("z") == pytest.approx(amplitude * math.sin(omega * t) + offset, abs=1e-10)


@pytest.mark.parametrize("omega", [0.05, 1.0, 3.0])
def test_detachment_onset_is_sharp_at_the_steady_orbit_threshold(omega):
    a_c = float(detachment_amplitude(omega))
    for factor, detaches in ((0.995, False), (1.005, True)):
        block = exact(initial_state=2, A=factor * a_c, omega=omega, k_d=0.0, V_d=0.0)
        times = np.linspace(0.01, 3 * 2 * math.pi / omega, 3000)
        (contact,) = sample(block, times, "contact")
        assert (not contact.all()) == detaches, f"A = {factor} A_c at omega = {omega}"


def test_agrees_with_rk4_to_its_own_accuracy_before_any_event():
    common = dict(SCALED, A=0.3, omega=0.8, initial_state=2)
    times = np.linspace(10.0, 300.0, 30)
    ours = sample(exact(**common), times, *STATE)
    rk4 = Block("A", "rk4", dt=1e-3, **common)
    rk4.start()
    np.testing.assert_allclose(sample(rk4, times, *STATE), ours, rtol=1e-9, atol=1e-11)


def test_rk4_converges_to_it_at_first_order_across_resets():
    """RK4 is first order across a reset; its error after 28 resets halves with dt."""
    ours = exact(**SCALED)
    ours.advance_to(5600.0)
    errors = []
    for dt in (2e-3, 1e-3):
        rk4 = Block("A", "rk4", dt=dt, **SCALED)
        rk4.start()
        rk4.advance_to(5600.0)
        assert rk4.output("slip_count") == ours.output("slip_count") == 28
        errors.append(abs(rk4.output("x") - ours.output("x")))
    assert errors[0] / errors[1] == pytest.approx(2.0, rel=0.3)


@pytest.mark.parametrize("settings, horizon", [
    (dict(SCALED, A=0.3, omega=0.8, initial_state=2), 6000.0),  # sub-threshold stick-slip
    (dict(SCALED, A=1.0, omega=0.8, initial_state=2), 60.0),    # bouncing, short horizon
])
def test_splitting_the_horizon_changes_results_only_at_the_tolerance(settings, horizon):
    rng = np.random.default_rng(3)
    stops = np.cumsum(rng.uniform(0.0, horizon / 150, 400))
    stops = list(stops[stops < horizon]) + [horizon]
    one = exact(**settings)
    one.advance_to(horizon)
    many = exact(**settings)
    for t in stops:
        many.advance_to(t)
    a, b = one.outputs(), many.outputs()
    for name in STATE:
        assert b[name] == pytest.approx(a[name], rel=1e-9, abs=1e-11), name


def test_results_do_not_depend_on_dt():
    settings = dict(SCALED, A=0.3, omega=0.8, initial_state=2)
    runs = [sample(exact(dt=dt, **settings), [1234.5, 5800.0], *STATE) for dt in (4e-4, 0.1, 3.7)]
    for run in runs[1:]:
        np.testing.assert_allclose(run, runs[0], rtol=1e-9, atol=1e-11)


def test_state_round_trip_through_json_continues_bit_for_bit():
    block = exact(A=1.0, omega=0.8, initial_state=2, **SCALED)
    block.advance_to(40.0)
    saved = json.loads(json.dumps(block.get_state()))
    block.advance_to(90.0)
    other = Block("A", "event_driven")
    other.set_state(saved)
    other.advance_to(90.0)
    assert other.outputs() == block.outputs()


def test_off_grid_outputs_come_from_the_exact_flow():
    """dt = 5: outputs at 12.3 are those of a run whose grid holds 12.3."""
    settings = dict(SCALED, A=1.0, omega=0.8, initial_state=2)
    coarse = exact(dt=5.0, **settings)
    coarse.advance_to(12.3)
    fine = exact(dt=0.1, **settings)
    fine.advance_to(12.3)
    assert coarse.grid_step == 2
    assert coarse.output("surface_z") == pytest.approx(math.sin(0.8 * 12.3), abs=1e-14)
    for name in STATE:
        assert coarse.output(name) == pytest.approx(fine.output(name), rel=1e-9, abs=1e-11), name


def test_friction_rule_holds_in_stored_states_while_bouncing_and_sticking():
    block = exact(A=0.7, omega=0.8, initial_state=2, **SCALED)  # A_c(0.8) = 0.57: bounces
    times = np.arange(0.05, 400.0, 0.05)
    friction, normal, contact = sample(block, times, "friction_force", "normal_force", "contact")
    loaded = friction != 0.0
    assert np.all(np.abs(friction[loaded]) < 0.5 * normal[loaded])
    assert np.all(friction[contact == 0] == 0.0)
    assert 0.1 < loaded.mean() < 0.9 and (contact == 0).mean() > 0.05  # both regimes visited


def test_every_reset_of_a_loaded_spring_is_counted_like_the_fixed_step_schemes():
    """Without vibration there are no cascades: the count per slip is the number of
    times the spring reached mu_s N, the same as RK4's at a small step."""
    ours = exact(**SCALED)
    rk4 = Block("A", "rk4", dt=5e-4, **SCALED)
    rk4.start()
    for block in (ours, rk4):
        block.advance_to(11000.0)  # two slips
    assert ours.output("slip_count") == rk4.output("slip_count") > 40


@pytest.mark.parametrize("model", "BC")
def test_refused_for_the_corrugated_models(model):
    with pytest.raises(ModelError, match="only for model A"):
        Block(model, "event_driven")
    block = Block(model)
    with pytest.raises(ModelError, match="only for model A"):
        block.set_integrator(2)
    assert block.integrator == "symplectic_euler"


def test_no_step_limit_applies():
    block = Block("A", "event_driven", k_n=1e8, dt=1.0)  # far beyond any explicit scheme's limit
    block.start()
    block.advance_to(10.0)
    assert block.output("penetration") == pytest.approx(1e-8, rel=1e-9)


@pytest.mark.parametrize("settings", [
    dict(SCALED, A=0.3, omega=0.8, initial_state=2),   # stick-slip
    dict(SCALED, A=1.5, omega=0.8, initial_state=2),   # bouncing
    dict(SCALED, A=0.7, omega=0.8, initial_state=0),   # impact start, bouncing and sticking
])
def test_energy_balance_closes_to_rounding(settings):
    """Exact flows and exact quadratures: the residual is rounding; skipping whole periods
    of a locked bounce adds at most the periodicity tolerance (1e-10 relative)."""
    for skip, bound in ((False, 1e-11), (True, 1e-10)):
        block = exact(energy_balance=True, **settings)
        n = int(round(3000.0 / block.parameters["dt"]))
        assert event_driven.advance_exact(block.settings.kind, block.y, block.cnt, block.drv, block.prm, n, True,
                                          event_driven.EVENT_TOL, skip) == 0
        block.time = 3000.0
        block._observed = None
        out = block.outputs()
        assert out["energy_dissipated"] > 1.0
        assert abs(out["energy_residual"]) < bound * out["energy_dissipated"], f"skip = {skip}"


def test_external_plate_acceleration_is_integrated_exactly():
    """Constant upward acceleration a: the block settles at penetration m (g + a) / k_n
    with no lag (the first-order scheme lags by gamma_n a dt / k_n)."""
    block = exact(k_d=0.0, V_d=0.0)
    block.set_plate_input(0.0, 0.0, 0.5)
    block.advance_to(600.0)
    assert block.output("surface_z") == pytest.approx(0.5 * 0.5 * 600.0**2, rel=1e-12)
    assert block.output("penetration") == pytest.approx(1.5, abs=1e-9)


def test_skipping_periods_of_a_locked_bounce_matches_integrating_them():
    settings = dict(A=1.5 * float(detachment_amplitude(0.7)), omega=0.7, initial_state=2)
    results = []
    for skip in (True, False):
        block = Block("A", "event_driven", energy_balance=True, **settings)
        block.start()
        n = int(2e5 / block.parameters["dt"])
        assert event_driven.advance_exact(block.settings.kind, block.y, block.cnt, block.drv, block.prm, n, True,
                                          event_driven.EVENT_TOL, skip) == 0
        block.time = 2e5
        block._observed = None
        results.append(block.outputs())
    skipped, integrated = results
    for name in ("x", "z", "vx", "phi_integral", "work_input"):
        assert skipped[name] == pytest.approx(integrated[name], rel=1e-8, abs=1e-10), name
    assert skipped["slip_count"] == integrated["slip_count"]


def test_a_horizon_of_1e9_is_reached_directly():
    block = exact(A=2.0, omega=0.5, initial_state=2)
    block.advance_to(1e9)
    assert block.grid_step == round(1e9 / 4e-4)
    out = block.outputs()
    assert all(math.isfinite(out[name]) for name in STATE)
    assert out["slip_count"] > 1000  # twenty stick-slip cycles at the paper's drive


def test_retuning_omega_during_a_run_keeps_the_plate_continuous():
    block = exact(A=0.2, omega=0.5, initial_state=2, **SCALED)
    block.advance_to(10.0)
    before = block.output("surface_z")
    block.set_parameter("omega", 1.3)
    assert block.output("surface_z") == pytest.approx(before, abs=1e-12)
    block.advance_to(10.0 + 2 * math.pi / 1.3)  # one period of the new drive later
    assert block.output("surface_z") == pytest.approx(before, abs=1e-9)


def test_a_non_finite_state_is_reported_and_the_last_good_state_kept():
    block = exact(k_d=10.0, V_d=1e308)
    before = block.outputs()
    with pytest.raises(ModelError, match="non-finite"):
        block.advance_to(10.0)
    assert block.time == 0.0 and block.outputs() == before


def test_block_fmu_runs_the_exact_scheme_like_the_core(fmu_path):
    """integrator = 2 through fmpy: the FMU bundles the scheme and gives the core's numbers."""
    from fmpy import simulate_fmu

    settings = dict(SCALED, A=1.0, omega=0.8, initial_state=2)
    result = simulate_fmu(fmu_path("A"), stop_time=50.0, output_interval=0.5,
                          start_values={**settings, "integrator": 2, "dt": 0.01})
    block = exact(dt=0.01, **settings)
    (x, z) = sample(block, result["time"][1:], "x", "z")
    np.testing.assert_allclose(result["x"][1:], x, rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(result["z"][1:], z, rtol=1e-12, atol=1e-13)
