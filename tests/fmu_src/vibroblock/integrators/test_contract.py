"""Every registered integrator keeps the contract written in ``vibroblock.integrators``.

The checks run over the registry itself, so an integrator added there is checked here
without a line of this file changing."""
import math
from fractions import Fraction

import numpy as np
import pytest

from vibroblock import Block
from vibroblock import layout as L
from vibroblock.integrators import BY_ID, INTEGRATOR_RECORDS, REDUCED_SCENE
from vibroblock.models import VARIANTS
from vibroblock.interface import COST_OUTPUTS

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
VIBRATED = {"A": 0.6, "omega": 1.3, "initial_state": 2}
BOUNCING = {"A": 2.5, "omega": 0.9}  # lifts off, lands, resets the spring


def cases():
    """(integrator record, model, Block keywords) for every registered integrator."""
    for record in INTEGRATOR_RECORDS.values():
        model = next(m for m in sorted(VARIANTS) if record.supports(m))
        yield pytest.param(record, model, {"integrator": record.name}, id=record.name)
    # On model A adaptive hands the run over to exact flows: its own steps keep the contract too.
    yield pytest.param(INTEGRATOR_RECORDS["adaptive"], "A", {"integrator": "adaptive", "exact_flows": False},
                       id="adaptive-own-steps")
    # The reduced-scene scheme is chosen by the scene options.
    yield pytest.param(REDUCED_SCENE, "A", {"coulomb_friction": True}, id=REDUCED_SCENE.name)


def make(model, keywords, **more):
    dt = 1e-2 if keywords.get("integrator") in ("event_driven", "implicit_contact", "adaptive") else 4e-3
    return Block(model, **{"dt": dt, **SCALED, **keywords, **more})


def test_registry_ids_and_names_are_unique_and_public_ids_are_stable():
    assert len({r.id for r in BY_ID.values()}) == len(BY_ID)
    assert {r.name: r.id for r in INTEGRATOR_RECORDS.values()} == {
        "symplectic_euler": 0, "rk4": 1, "event_driven": 2, "implicit_contact": 3, "adaptive": 4}  # FMU values never change


@pytest.mark.parametrize("record, model, keywords", list(cases()))
def test_rule_1_state_lives_on_the_grid(record, model, keywords):
    block = make(model, keywords, **BOUNCING)
    block.start(t0=2.5)
    block.advance_to(2.5 + 37.0123)
    dt = block.parameters["dt"]
    assert block.grid_step == math.floor(37.0123 / dt + 1e-6)
    assert block.time == 2.5 + 37.0123
    assert block.counters["steps"] == block.grid_step


@pytest.mark.parametrize("record, model, keywords", list(cases()))
def test_rule_2_stored_state_obeys_the_friction_rule(record, model, keywords):
    block = make(model, keywords, **BOUNCING)
    block.start()
    p = block.parameters
    seen_contact = seen_flight = 0
    for k in range(1, 400):
        block.advance_to(k * 0.25)
        if block.time != block.drv[L.D_T0] + block.grid_step * p["dt"]:
            continue
        out = block.outputs()
        if out["penetration"] <= 0.0:
            seen_flight += 1
            assert block.y[L.Y_F] == 0.0
        else:
            seen_contact += 1
            assert block.y[L.Y_F] == 0.0 or abs(p["k_t"] * block.y[L.Y_F]) < p["mu_s"] * out["normal_force"]
    assert seen_contact and seen_flight


@pytest.mark.parametrize("record, model, keywords", list(cases()))
def test_rule_3_any_split_of_a_run_gives_the_same_result(record, model, keywords):
    tight = {"rtol": 1e-10, "atol": 1e-12} if record.name == "adaptive" else {}

    def run(stops):
        block = make(model, keywords, **VIBRATED, **tight)
        block.start()
        for t in stops:
            block.advance_to(t)
        return block.outputs(), block.y.copy()

    rng = np.random.default_rng(7)
    ragged = [t for t in np.cumsum(rng.uniform(0.0, 0.9, 200)) if t < 60.0] + [60.0]
    (one, y_one), (many, y_many) = run([60.0]), run(ragged)
    if record.splits_bitwise:
        assert one == many and y_one.tobytes() == y_many.tobytes()
    else:
        # Its steps depend on where a call stops, so two splits differ by the global error:
        # for adaptive (rtol 1e-10 here) up to ~1e2 rtol across the run's landings and resets.
        bound = 1e2 * tight.get("rtol", 1e-11)
        for name, value in one.items():
            if name not in COST_OUTPUTS:  # the cost, unlike the result, depends on the split
                assert many[name] == pytest.approx(value, rel=bound, abs=bound), name


@pytest.mark.parametrize("t0", [2.0**31, 2.0**40])
@pytest.mark.parametrize("record, model, keywords", list(cases()))
def test_rule_3_the_plate_is_exact_at_any_time(record, model, keywords, t0):
    """Started at t0 ~ 2e9 or 1e12, the surface at each grid point is A sin(omega t) to
    ~1e-15: omega t summed in doubles would be ~1e-7 (2e9) to ~1e-4 rad (1e12) off.  The
    times t0 + n dt are exact doubles here (dt a power of 2), so the comparison is sharp."""
    drive = {key: VIBRATED[key] for key in ("A", "omega")}
    block = make(model, keywords, dt=2.0**-8, x_start=SCALED["V_d"] * t0, **drive)
    block.start(t0)
    turn = 2 * Fraction("3.14159265358979323846264338327950288419716939937510582097494459")
    for k in range(1, 41):
        t = t0 + 0.25 * k
        block.advance_to(t)
        phase = Fraction(drive["omega"]) * Fraction(t)
        phase -= turn * math.floor(phase / turn)
        assert block.output("surface_z") == pytest.approx(drive["A"] * math.sin(float(phase)), abs=1e-14), t


@pytest.mark.parametrize("record, model, keywords", list(cases()))
def test_rule_4_a_failed_advance_leaves_the_arrays_untouched(record, model, keywords):
    block = make(model, keywords, **VIBRATED)
    block.start()
    block.advance_to(5.0)
    block.y[L.Y_VX] = math.nan  # a state no integrator can continue
    before = [a.copy() for a in (block.y, block.cnt, block.drv, block.prm)]
    status = record.run_advance(block.settings.variant.kind, block.settings.scene_flags(), block.y, block.cnt,
                                block.drv, block.prm, 1000, False)
    assert status < 0
    assert record.message(status, t=5.0, t_end=9.0, dt=0.01)
    for old, new in zip(before, (block.y, block.cnt, block.drv, block.prm)):
        assert old.tobytes() == new.tobytes()


@pytest.mark.parametrize("record, model, keywords", list(cases()))
def test_rule_5_the_energy_balance_measures_the_error(record, model, keywords):
    """Stored - start - work + dissipated is the scheme's error: small against the energy
    that flowed, and it shrinks when dt does (exact schemes: at rounding already)."""
    residuals = []
    for dt_scale in (1.0, 0.5):
        block = make(model, keywords, energy_balance=True, **VIBRATED)
        block.set_parameter("dt", block.parameters["dt"] * dt_scale)
        block.start()
        block.advance_to(40.0)
        out = block.outputs()
        assert out["energy_dissipated"] > 0.0 and out["work_input"] != 0.0
        residuals.append(abs(out["energy_residual"]) / (abs(out["work_input"]) + out["energy_dissipated"]))
    assert residuals[0] < 1e-2
    assert residuals[1] <= residuals[0] or residuals[1] < 1e-12


@pytest.mark.parametrize("record, model, keywords", list(cases()))
def test_rule_6_counters_count(record, model, keywords):
    block = make(model, keywords, **BOUNCING)
    block.start()
    block.advance_to(200.0)
    counters = block.counters
    assert counters["steps"] == block.grid_step > 0
    assert counters["resets"] == block.output("slip_count")
    assert counters["events"] >= 0 and counters["rejected"] >= 0
    if record.scheme is None:  # it locates its switches: the landings, detachments and resets are counted
        assert counters["events"] > counters["resets"] > 0
