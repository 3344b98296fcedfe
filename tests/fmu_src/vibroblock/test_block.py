"""Block's contract: time grid, communication-step independence, state, validation."""
import json
import math

import numpy as np
import pytest

from vibroblock import Block, ModelError, parameters_for

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}


def final_outputs(block_factory, stops):
    block = block_factory()
    block.start()
    for t in stops:
        block.advance_to(t)
    return block.outputs(), block.get_state()


@pytest.mark.parametrize("model", "ABC")
@pytest.mark.parametrize("integrator", ["symplectic_euler", "rk4"])
def test_results_do_not_depend_on_how_the_horizon_is_split(model, integrator):
    def factory():
        return Block(model, integrator, A=0.6, omega=1.3, initial_state=2, **SCALED)

    rng = np.random.default_rng(1)
    ragged = np.cumsum(rng.uniform(0.0, 0.9, 400))
    ragged = ragged[ragged < 150.0]
    one, state_one = final_outputs(factory, [150.0])
    many, state_many = final_outputs(factory, list(ragged) + [150.0])
    assert one == many  # bit for bit
    assert state_one["y"] == state_many["y"] and state_one["cnt"] == state_many["cnt"]


def test_time_is_counted_in_steps_not_accumulated():
    block = Block("A", dt=0.1)
    block.start(t0=5.0)
    block.advance_to(5.0 + 1e6 * 0.1)
    assert block.grid_step == 1_000_000
    assert block.time == 5.0 + 1e6 * 0.1


def test_outputs_between_grid_points_are_at_the_requested_time():
    """A communication point off the grid is reached by a scratch step: the plate's
    height output is exactly the drive at that time."""
    block = Block("A", A=0.3, omega=0.7, dt=0.01, initial_state=2)
    block.start()
    block.advance_to(1.2345)
    assert block.output("surface_z") == pytest.approx(0.3 * math.sin(0.7 * 1.2345), abs=1e-14)


def test_state_round_trip_through_json_reproduces_the_run():
    block = Block("B", A=0.5, omega=0.9, initial_state=2, **SCALED)
    block.start()
    block.advance_to(40.0)
    saved = json.loads(json.dumps(block.get_state()))
    block.advance_to(90.0)
    reference = block.outputs()

    other = Block("B")
    other.set_state(saved)
    other.advance_to(90.0)
    assert other.outputs() == reference


def test_changing_omega_keeps_the_plate_phase_continuous():
    block = Block("A", A=0.2, omega=0.5, initial_state=2)
    block.start()
    block.advance_to(10.0)
    before = block.output("surface_z")
    block.set_parameter("omega", 1.3)
    assert block.output("surface_z") == pytest.approx(before, abs=1e-12)
    assert not math.isclose(0.2 * math.sin(1.3 * 10.0), before, abs_tol=1e-3)  # the naive jump


def test_external_plate_input_is_held_at_constant_acceleration():
    """A plate accelerating upwards at a < g: the block rides it, pressed in by m (g + a)."""
    accel = 0.5
    block = Block("A", k_d=0.0, V_d=0.0)
    block.start()
    block.set_plate_input(0.0, 0.0, accel)
    block.advance_to(600.0)
    plate = 0.5 * accel * 600.0**2
    assert block.output("surface_z") == pytest.approx(plate, rel=1e-12)
    # The first-order scheme lags the plate by O(dt): a dashpot offset gamma_n a dt / k_n.
    assert block.output("penetration") == pytest.approx(1.0 + accel, abs=1e-4)


@pytest.mark.parametrize("name, value", [
    ("m", 0.0), ("m", -1.0), ("m", math.nan), ("k_n", -1.0), ("k_t", math.inf), ("gamma_n", -0.1),
    ("gamma_t", -1e-9), ("mu_s", -0.5), ("k_d", -1.0), ("V_d", math.nan), ("dt", 0.0), ("dt", -4e-4),
    ("omega", -1.0), ("A", math.inf), ("x_start", math.nan),
])
def test_inadmissible_parameters_are_refused_and_the_old_value_kept(name, value):
    block = Block("A")
    old = block.parameters[name]
    with pytest.raises(ModelError, match=name):
        block.set_parameter(name, value)
    assert block.parameters[name] == old


def test_model_specific_parameters_are_checked_per_model():
    with pytest.raises(ModelError, match="P_l"):
        Block("C", P_l=-1.0)
    with pytest.raises(ModelError, match="no parameter 'A_x'"):
        Block("A", A_x=1.0)
    assert {p.name for p in parameters_for("C")} >= {"A_x", "omega_x", "P_l"}


def test_too_large_dt_is_refused_with_the_limit():
    block = Block("A", k_n=1e8, dt=4e-4)
    with pytest.raises(ModelError, match=r"use dt <= 0.0001"):
        block.start()


def test_only_the_drive_is_tunable_during_a_run():
    block = Block("A")
    block.start()
    with pytest.raises(ModelError, match="fixed once the run has started"):
        block.set_parameter("m", 2.0)
    block.set_parameter("A", 0.1)
    assert block.parameters["A"] == 0.1


def test_a_drive_retuned_during_a_run_is_checked_and_a_refused_value_leaves_the_run_as_it_was():
    """event_driven refuses an undamped contact driven at its resonance omega = sqrt(k_n/m)
    at start; retuning omega onto it during the run is refused the same way, with the
    previous omega kept, and the run goes on exactly as one never asked to retune."""
    def run(retune: bool):
        block = Block("A", "event_driven", initial_state=0, gamma_n=0.0, A=2.0, omega=0.9)
        block.start()
        block.advance_to(10.0)
        if retune:
            with pytest.raises(ModelError, match=r"undamped contact .* resonance"):
                block.set_parameter("omega", 1.0)
            assert block.parameters["omega"] == 0.9
        block.advance_to(40.0)
        return block.outputs()

    retuned = run(retune=True)
    assert all(math.isfinite(float(value)) for value in retuned.values())
    assert retuned == run(retune=False)


def test_a_non_finite_state_is_reported_and_the_last_good_state_kept():
    block = Block("A", k_d=10.0, V_d=1e308)
    block.start()
    before = block.outputs()
    with pytest.raises(ModelError, match="non-finite"):
        block.advance_to(10.0)
    assert block.time == 0.0 and block.outputs() == before


@pytest.mark.parametrize("t_end", [0.0, -1.0, math.nan, math.inf])
def test_advancing_to_a_bad_time_is_refused(t_end):
    block = Block("A")
    block.start()
    with pytest.raises(ModelError, match="end time"):
        block.advance_to(t_end)


def test_a_cost_count_beyond_an_fmi2integer_is_held_at_its_largest_value():
    from vibroblock import layout as L
    block = Block("C", "adaptive", rtol=1e-6, atol=1e-8, dt=1e-2, A=0.2, omega=0.8, initial_state=2)
    block.start()
    block.advance_to(1.0)
    accepted = block.counters["accepted"]
    assert block.output("accepted_steps") == accepted > 0
    block.cnt[L.C_ACCEPTED] = 2**40  # ~1e12 steps: a long enough run gets there
    block.advance_to(2.0)
    assert block.counters["accepted"] > 2**40
    assert block.output("accepted_steps") == 2**31 - 1
