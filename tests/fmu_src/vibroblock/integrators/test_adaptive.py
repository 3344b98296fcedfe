"""The adaptive integrator's error-controlled steps against the independent reference,
event_driven, the physics of a long stick, and its own tolerances (on model A with its
option exact_flows off: ``stepped``); and, last, its hand-over to event_driven's exact
flows on model A."""
import math
from collections import Counter

import numpy as np
import pytest

from vibroblock import Block
from vibroblock.block import ModelError
from vibroblock.interface import COST_OUTPUTS

from harness.paper import reference
from harness.paper.reference import Solver


def stepped(model, **keywords):
    """A Block of ``model`` on adaptive's own steps (model A's exact flows switched off)."""
    return Block(model, "adaptive", **({"exact_flows": False} if model == "A" else {}), **keywords)


SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
VALLEY_X = (-0.5 * math.pi + 0.005) / 0.02  # slope 0.1 of the paper's corrugation, near a valley
# Tight enough for 1e-7 on every scenario: DOP853's error estimate lets the global error
# of the B stick-slip run (590 located resets) grow to ~1e3 rtol (1.3e-7 at rtol 1e-10).
TIGHT = {"rtol": 1e-11, "atol": 1e-13}
# name -> (parameters, horizon, initial_state, x_start offset).  Short horizons: the
# bouncing runs stay non-chaotic; the drive spring starts stretched by 40 so that the
# embedded block slips (Coulomb resets) within the horizon.
SCENARIOS = {
    "stick-slip": (dict(SCALED), 300.0, 0, -40.0),
    "sub-threshold": (dict(SCALED, A=0.2, omega=0.8), 200.0, 2, 0.0),
    "bouncing": (dict(SCALED, A=1.0, omega=0.8), 30.0, 2, 0.0),
}


def run(model, parameters, horizon, initial, x_start, **keywords):
    block = stepped(model, dt=1e-2, energy_balance=True, initial_state=initial, x_start=x_start,
                    **parameters, **keywords)
    block.start()
    block.advance_to(horizon)
    return block


def error(out, ref):
    """Largest of the errors of x (relative to max(|x|, 1)), z, vx, vz (delta_0, delta_0/tau_0) and phi
    (relative)."""
    return max(abs(out["x"] - ref.final("x")) / max(1.0, abs(ref.final("x"))), abs(out["z"] - ref.final("z")),
               abs(out["vx"] - ref.final("vx")), abs(out["vz"] - ref.final("vz")),
               abs(out["phi_integral"] / ref.final("phi") - 1.0))


def scenario(model, name):
    parameters, horizon, initial, offset = SCENARIOS[name]
    x_start = offset + (0.0 if model == "A" else VALLEY_X)
    return parameters, horizon, initial, x_start


@pytest.mark.parametrize("model", "ABC")
@pytest.mark.parametrize("name", list(SCENARIOS))
def test_agrees_with_the_independent_reference(model, name):
    parameters, horizon, initial, x_start = scenario(model, name)
    ref = reference.simulate(model, parameters, horizon, solver=Solver.reference(1e-12), initial=initial,
                             x_start=x_start)
    block = run(model, parameters, horizon, initial, x_start, **TIGHT)
    out = block.outputs()
    assert error(out, ref) < 1e-7
    assert out["slip_count"] == ref.slips  # every Coulomb reset, cascades included
    assert out["contact"] == bool(ref["contact"][-1])
    if name != "sub-threshold" or model != "A":
        assert ref.slips > 0  # the scenario exercises the resets
    energy = out["work_input"] ** 2 + out["energy_dissipated"] ** 2
    assert abs(out["energy_residual"]) < 1e-8 * max(1.0, math.sqrt(energy))
    counters = block.counters
    assert counters["accepted"] > 0 and counters["jacobians"] >= 1  # the start's, which chooses the method
    assert counters["events"] >= counters["resets"]


def test_the_explicit_pair_steps_motion_that_is_not_stiff_and_rodas4_motion_that_is():
    """Contact and friction springs with k/m ~ 1, stepped at rtol 1e-8, are far inside the
    explicit pair's stability bound: after the start's linearisation no step needs a
    Jacobian.  A contact with k_n/m = 1e6 puts the first step beyond the bound: RODAS4
    takes every step, each with its Jacobian.  Both agree with the reference."""
    parameters, horizon, initial, x_start = scenario("C", "stick-slip")
    ref = reference.simulate("C", parameters, horizon, solver=Solver.reference(1e-12), initial=initial,
                             x_start=x_start)
    block = run("C", parameters, horizon, initial, x_start, rtol=1e-8, atol=1e-10)
    counters = block.counters
    assert counters["jacobians"] == 1 and counters["accepted"] > 100
    assert error(block.outputs(), ref) < 1e-6

    stiff = dict(SCALED, k_n=1e6, gamma_n=2e2)
    ref = reference.simulate("A", stiff, 50.0, solver=Solver.reference(1e-12), initial=0, x_start=-40.0)
    block = run("A", stiff, 50.0, 0, -40.0, rtol=1e-8, atol=1e-10)
    counters = block.counters
    assert counters["jacobians"] >= counters["accepted"] > 0
    assert error(block.outputs(), ref) < 1e-6


def test_the_explicit_tableau_has_the_orders_it_is_used_for():
    """The DOP853 tableau the kernel reads from scipy (a private module, pinned) steps an
    ODE with a closed-form solution with local errors of order 9, and its two estimators
    have orders 6 and 4: halving the step divides them by ~2^9, 2^6 and 2^4.  Should a
    scipy release change the tableau, this fails before any result moves."""
    from vibroblock.integrators.adaptive import (EXPLICIT_A, EXPLICIT_B, EXPLICIT_C, EXPLICIT_E3, EXPLICIT_E5,
                                                 EXPLICIT_STAGES)

    def rate(t, y):  # u' = cos(t) u, w' = w^2: u = u0 exp(sin t - sin t0), w = 1 / (1/w0 - (t - t0))
        return np.array([math.cos(t) * y[0], y[1] * y[1]])

    def step(t0, y0, h):
        k = np.zeros((EXPLICIT_STAGES + 1, 2))
        k[0] = rate(t0, y0)
        for s in range(1, EXPLICIT_STAGES):
            k[s] = rate(t0 + EXPLICIT_C[s] * h, y0 + h * (EXPLICIT_A[s, :s] @ k[:s]))
        y1 = y0 + h * (EXPLICIT_B @ k[:EXPLICIT_STAGES])
        k[EXPLICIT_STAGES] = rate(t0 + h, y1)
        return y1, h * (EXPLICIT_E5 @ k), h * (EXPLICIT_E3 @ k)

    assert np.allclose(EXPLICIT_C, EXPLICIT_A.sum(axis=1), rtol=0.0, atol=1e-14)
    t0, y0 = 0.3, np.array([1.2, 0.8])
    steps = (0.2, 0.1, 0.05, 0.025)
    errors, fifth, third = [], [], []
    for h in steps:
        y1, e5, e3 = step(t0, y0, h)
        exact = np.array([y0[0] * math.exp(math.sin(t0 + h) - math.sin(t0)), 1.0 / (1.0 / y0[1] - h)])
        errors.append(np.max(np.abs(y1 - exact)))
        fifth.append(np.max(np.abs(e5)))
        third.append(np.max(np.abs(e3)))
    # The eighth-order step reaches the rounding below h ~ 0.05 (4e-14 at h = 0.1), so its
    # order shows on the first halving only, approached from above (9.8 there).
    assert 8.5 < math.log2(errors[0] / errors[1]) < 10.5 and errors[1] > 100 * np.finfo(float).eps
    for values, order in ((fifth[1:], 6), (third[1:], 4)):
        slopes = np.log2(np.array(values[:-1]) / np.array(values[1:]))
        assert np.all(np.abs(slopes - order) < 0.3), (order, slopes)


@pytest.mark.parametrize("model, formulation", [("A", 0), ("B", 0), ("C", 0), ("C", 1)])
def test_a_flight_above_the_plates_reach_steps_past_the_cap_and_lands_where_the_reference_does(model, formulation):
    """Launched from a crest by a plate at A omega^2 = 12.8 g, the block flies 11-20 plate
    periods, most of them above the plate's highest point: steps past the cap (1/16 of a
    period) there, then the landing, located against the plate's motion, and the state
    after it as the reference's."""
    parameters = dict(SCALED, A=20.0, omega=0.8)
    readings = {} if model == "A" else {"formulation": formulation}
    x_start = 0.0 if model == "A" else math.pi / 0.04  # a crest of the paper's corrugation
    ref = reference.simulate(model, parameters, 250.0, solver=Solver.reference(1e-12), initial=2, x_start=x_start,
                             **readings)
    switches = [(t, kind) for t, kind in ref.event_log if kind in ("contact", "detach")]
    (launch, first), (landing, second) = switches[:2]
    assert (first, second) == ("detach", "contact")
    cap = 2.0 * math.pi / parameters["omega"] / 16.0
    assert landing - launch > 160.0 * cap  # > 10 periods: > 160 steps at the cap
    # Steps in the flight where the error control allows long ones (rtol 1e-6)...
    block = stepped(model, dt=1e-2, initial_state=2, x_start=x_start, rtol=1e-6, atol=1e-8, **parameters,
                    **readings)
    block.start()
    block.advance_to(launch + 1.0)
    before = block.counters["accepted"] + block.counters["rejected"]
    block.advance_to(landing - 1.0)
    assert not block.outputs()["contact"]
    in_flight = block.counters["accepted"] + block.counters["rejected"] - before
    assert in_flight < 0.5 * (landing - 2.0 - launch) / cap
    # ... and the landing at the tight tolerance: the state 2 tau_0 after it (violent,
    # |vz| up to ~1e3) to 1e-9 of each component's size.
    after = landing + 2.0
    ref_after = reference.simulate(model, parameters, after, solver=Solver.reference(1e-12), initial=2,
                                   x_start=x_start, **readings)
    block = stepped(model, dt=1e-2, initial_state=2, x_start=x_start, **TIGHT, **parameters, **readings)
    block.start()
    block.advance_to(after)
    out = block.outputs()
    for name in ("x", "z", "vx", "vz"):
        assert abs(out[name] - ref_after.final(name)) < 1e-9 * max(1.0, abs(ref_after.final(name))), name
    assert abs(out["phi_integral"] / ref_after.final("phi") - 1.0) < 1e-9
    assert out["contact"] == bool(ref_after["contact"][-1])
    assert out["slip_count"] == ref_after.slips


@pytest.mark.parametrize("name", ["stick-slip", "sub-threshold", "bouncing"])
def test_model_a_agrees_with_event_driven_to_1e_8(name):
    parameters, horizon, initial, x_start = scenario("A", name)
    exact = Block("A", "event_driven", dt=1e-2, energy_balance=True, initial_state=initial, x_start=x_start,
                  **parameters)
    exact.start()
    exact.advance_to(horizon)
    ref = exact.outputs()
    out = run("A", parameters, horizon, initial, x_start, **TIGHT).outputs()
    for key in ("x", "z", "vx", "vz", "penetration"):
        assert abs(out[key] - ref[key]) < 1e-8 * max(1.0, abs(ref[key])), key
    assert abs(out["phi_integral"] - ref["phi_integral"]) < 1e-8 * ref["phi_integral"]


@pytest.mark.parametrize("model", "BC")
def test_error_falls_with_rtol(model):
    parameters, horizon, initial, x_start = scenario(model, "sub-threshold")
    ref = reference.simulate(model, parameters, horizon, solver=Solver.reference(1e-12), initial=initial,
                             x_start=x_start)
    errors, costs = [], []
    for rtol in (1e-6, 1e-8, 1e-10):  # B's resets let DOP853's global error reach ~1e2 rtol here
        block = run(model, parameters, horizon, initial, x_start, rtol=rtol, atol=rtol * 1e-2)
        errors.append(error(block.outputs(), ref))
        costs.append(block.counters["accepted"])
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 1e-7
    assert costs[0] < costs[1] < costs[2]


def test_off_grid_outputs_come_from_a_short_integration():
    """An output between grid points equals the one of a run whose grid hits that time."""
    parameters, _, initial, x_start = scenario("B", "bouncing")
    coarse = stepped("B", dt=1.0, initial_state=initial, x_start=x_start, **parameters, **TIGHT)
    fine = stepped("B", dt=0.25, initial_state=initial, x_start=x_start, **parameters, **TIGHT)
    for block in (coarse, fine):
        block.start()
        block.advance_to(12.75)
    a, b = coarse.outputs(), fine.outputs()
    assert coarse.grid_step == 12 and fine.grid_step == 51
    for key in ("x", "z", "vx", "vz", "friction_force", "normal_force"):
        assert a[key] == pytest.approx(b[key], rel=1e-7, abs=1e-8), key
    assert a["contact"] == b["contact"] and a["slip_count"] == b["slip_count"]


@pytest.mark.parametrize("model, keywords", [("A", {}), ("B", {"A_x": 0.0}), ("C", {"A_x": 0.0})])
def test_a_long_stick_at_the_papers_parameters_costs_few_steps(model, keywords):
    """No vibration, the paper's drive (A: k_d = 5e-4, V_d = 2e-5; B, C: 5e-6, 2e-4; flat
    plate for B and C): the block creeps at V_S = V_d k_d / (k_t + k_d) for
    t_stick = mu_s m g / (k_t V_S) = 5e7 (A) or 5e8 (B, C).  An explicit method is held to
    steps of order 1 by the contact's and the spring's periods (6.3 and 11.9): 1e7-1e8
    steps.  The L-stable steps grow once the start's ringing (amplitude ~ V_S / omega) has
    died, so crossing 0.9 t_stick takes a few thousand steps."""
    block = stepped(model, dt=1.0, energy_balance=True, **keywords)
    block.start()
    p = block.parameters
    creep = p["V_d"] * p["k_d"] / (p["k_t"] + p["k_d"])
    stick = p["mu_s"] * p["m"] * 1.0 / (p["k_t"] * creep)
    block.advance_to(0.9 * stick)
    out = block.outputs()
    counters = block.counters
    assert out["slip_count"] == 0 and out["contact"]
    assert out["vx"] == pytest.approx(creep, rel=1e-3)
    # the spring holds 0.9 of the Coulomb bound: k_t F = 0.9 mu_s m g
    assert p["k_t"] * block.y[4] == pytest.approx(0.9 * p["mu_s"], rel=1e-3)
    assert counters["accepted"] + counters["rejected"] < 2e4 < 1e-3 * stick
    drive_energy = 0.5 * p["k_d"] * (p["V_d"] * 0.9 * stick) ** 2
    assert abs(out["energy_residual"]) < 1e-6 * drive_energy


@pytest.mark.parametrize("name, value", [("rtol", 0.0), ("rtol", -1e-6), ("atol", 0.0), ("atol", math.nan)])
def test_non_positive_tolerances_are_refused_when_set(name, value):
    with pytest.raises(ModelError, match=f"{name} = .* must be a finite number > 0"):
        stepped("A", **{name: value})


@pytest.mark.parametrize("name, value, allowed", [("rtol", 0.5, r"\[1e-13, 0.01\]"), ("rtol", 1e-16, r"\[1e-13"),
                                                  ("atol", 10.0, r"\(1e-300, 1\]")])
def test_tolerances_out_of_range_are_refused_at_start(name, value, allowed):
    block = stepped("A", **{name: value})
    with pytest.raises(ModelError, match=f"{name} = .*adaptive.*{allowed}"):
        block.start()
    Block("A", "symplectic_euler", **{name: value}).start()  # the fixed-step schemes ignore them


# ---------------------------------------------------------------- every reading of B and C
READINGS = ("formulation", "coulomb_normal", "flight")
COMBINATIONS = [(f, c, fl) for f in (0, 1) for c in (0, 1) for fl in (0, 1) if not (f and fl)]
# A gentle corrugation (slopes up to 0.5, no self-locking), the drive stiffened to k_d = 5e-2
# and stretched by -9 (a pull of 0.45, near mu_s P_l), vibrated above the onset (A = 1.2 at
# omega = 0.8): within t = 20 the block slips on its friction spring (Coulomb resets), then
# detaches, flies and lands again, in every reading.
READING_SCENE = dict(SCALED, A_x=1.0, omega_x=0.5, k_d=5e-2, A=1.2, omega=0.8)
READING_HORIZON, READING_X_START = 20.0, -9.0
READING_RTOL = 1e-10
# Global error allowed against the reference, from rtol: the local errors are held to
# rtol (atol = rtol / 100, on O(1) components) over ~1.5e3 steps of a run that damps
# (gamma_n, gamma_t), each switch is located to EVENT_TOL = 1e-12 tau_0 (O(1) rates: 1e-12
# per switch) and the reference's own error is ~1e-12, so the global error is a small
# multiple of rtol; 100 rtol allows for the runs' different step sequences.  Measured: 1-4
# rtol at rtol = 1e-6 ... 1e-10.
READING_TOLERANCE = 100 * READING_RTOL


def reading_ids(combination):
    f, c, fl = combination
    return f"{reference.FORMULATIONS[f]}-{reference.COULOMB_NORMALS[c]}-{reference.FLIGHTS[fl]}"


@pytest.mark.parametrize("combination", COMBINATIONS, ids=reading_ids)
@pytest.mark.parametrize("model", "BC")
def test_every_reading_agrees_with_the_independent_reference(model, combination):
    """x, z, vx, vz (the tangent frame's state seen as a point, docs/physics.md Sec. 4) and the
    slip count at ten times through resets, a detachment, a flight and a landing, against the
    reference at 1e-12, to READING_TOLERANCE = 100 rtol."""
    readings = dict(zip(READINGS, combination))
    times = np.linspace(2.0, READING_HORIZON, 10)
    ref = reference.simulate(model, READING_SCENE, READING_HORIZON, times, solver=Solver.reference(1e-12), initial=2,
                             x_start=READING_X_START, **readings)
    switches = Counter(kind for _, kind in ref.event_log)
    assert switches["contact"] > 0 and switches["detach"] > 0 and ref.slips > 0, switches
    block = stepped(model, dt=1e-2, initial_state=2, x_start=READING_X_START, rtol=READING_RTOL,
                    atol=1e-2 * READING_RTOL, **READING_SCENE, **readings)
    block.start()
    core, slips, contact = [], [], []
    for t in times:
        block.advance_to(t)
        out = block.outputs()
        core.append([out[name] for name in ("x", "z", "vx", "vz")])
        slips.append(out["slip_count"])
        contact.append(out["contact"])
    expected = np.stack([ref[name] for name in ("x", "z", "vx", "vz")], axis=1)
    assert np.max(np.abs(np.array(core) - expected)) < READING_TOLERANCE
    assert slips == list(ref["slips"])
    assert contact == list(ref["contact"])
    assert block.counters["events"] >= sum(switches.values())


@pytest.mark.parametrize("coulomb_normal", [0, 1])
@pytest.mark.parametrize("model", "BC")
def test_energy_balance_closes_in_the_tangent_frame(model, coulomb_normal):
    """docs/physics.md Sec. 7's tangent-frame balance (kinetic m (u^2 + w^2)/2, E_n = k_n delta^2/2,
    the work of the normal components of load and drive on zeta) closes to the tolerance
    through resets, flights and landings; the position moving at dx/dt = u would not."""
    block = stepped(model, dt=1e-2, initial_state=2, x_start=READING_X_START, rtol=READING_RTOL,
                    atol=1e-2 * READING_RTOL, energy_balance=True, formulation=1, coulomb_normal=coulomb_normal,
                    **READING_SCENE)
    block.start()
    residuals = []
    for t in np.linspace(2.0, READING_HORIZON, 10):
        block.advance_to(t)
        residuals.append(block.output("energy_residual"))
    out = block.outputs()
    assert out["energy_dissipated"] > 0.1 and out["slip_count"] > 0 and block.counters["events"] >= 4
    assert np.max(np.abs(residuals)) < 1e-8 * max(1.0, out["energy_dissipated"])


CREST_X = 0.5 * math.pi / 0.02  # a crest of the paper's corrugation (slope 0)


def _vibrated_stick(model, max_jump, horizon, omega=0.316, calls=1, x_start=CREST_X, **keywords):
    """Model B or C at the paper's parameters held at a crest (``x_start``) on a plate vibrated
    at a third of the detachment onset (no switch within the horizon), from the steady
    orbit, advanced in ``calls`` equal calls from the time the drive spring is relaxed."""
    from vibroblock import defaults, detachment_amplitude
    p = defaults(model)
    amplitude = float(detachment_amplitude(omega, m=1.0, g=1.0, k_n=1.0, gamma_n=0.07)) / 3.0
    block = stepped(model, initial_state=2, A=amplitude, omega=omega, x_start=x_start, dt=1.0,
                    max_jump=max_jump, **keywords)
    t0 = x_start / p["V_d"]
    block.start(t0)
    for call in range(1, calls + 1):
        block.advance_to(t0 + horizon * call / calls)
    return block


@pytest.mark.parametrize("model", ["C"])
def test_stroboscopic_jumps_agree_with_every_period_resolved(model):
    """The held block's periods taken hundreds at a time agree with every period resolved at a
    tighter tolerance (an independent step sequence), and cost a small fraction of the steps."""
    horizon = 2e4  # ~1000 plate periods
    reference_run = _vibrated_stick(model, 0.0, horizon, formulation=1, rtol=1e-10, atol=1e-12)
    resolved = _vibrated_stick(model, 0.0, horizon, formulation=1)
    jumped = _vibrated_stick(model, 1e12, horizon, formulation=1)
    ref = reference_run.outputs()
    assert reference_run.counters["periods_jumped"] == resolved.counters["periods_jumped"] == 0
    assert jumped.counters["periods_jumped"] > 900
    assert jumped.counters["accepted"] < resolved.counters["accepted"] / 3
    out = jumped.outputs()
    assert out["slip_count"] == ref["slip_count"] == 0 and out["contact"]
    assert abs(out["x"] - ref["x"]) <= 1e-8 * abs(ref["x"]) + 1e-6
    assert abs(out["friction_force"] - ref["friction_force"]) <= 1e-9
    assert abs(out["vx"] - ref["vx"]) <= 1e-9 and abs(out["vz"] - ref["vz"]) <= 1e-8
    assert abs(out["phi_integral"] - ref["phi_integral"]) <= 1e-6 * ref["phi_integral"]


def test_jumps_hold_two_billion_tau_0_after_the_time_origin():
    """The same held stick started at t ~ 2e9 (a crest ~4e5 delta_0 down the corrugation, where
    the drive spring is relaxed then): the plate's phase is reduced at the clock's origin
    (``_clock``), so its rounding is not a ~1e-8 noise between replays of a period that the
    jumps' check would refuse (at 2e9 the sum omega (t + u) rounds to ~1e-7 rad).
    The jumps cross as many periods as near t = 0 and agree with every period resolved."""
    from vibroblock import defaults
    horizon = 2e4
    wavelength = 2.0 * math.pi / 0.02
    crest = CREST_X + wavelength * round(2e9 * defaults("C")["V_d"] / wavelength)
    near, far = (_vibrated_stick("C", 1e12, horizon, formulation=1, x_start=x) for x in (CREST_X, crest))
    resolved = _vibrated_stick("C", 0.0, horizon, formulation=1, x_start=crest)
    assert near.counters["periods_jumped"] > 900
    assert far.counters["periods_jumped"] >= 0.9 * near.counters["periods_jumped"]
    ref, out = resolved.outputs(), far.outputs()
    assert abs(out["x"] - ref["x"]) <= 1e-8 * abs(ref["x"]) + 1e-6
    assert abs(out["friction_force"] - ref["friction_force"]) <= 1e-8
    assert abs(out["phi_integral"] - ref["phi_integral"]) <= 1e-6 * ref["phi_integral"]


def test_one_long_call_jumps_as_cheaply_as_many_short_ones():
    """The held stick over 3e7 tau_0 (1e6 plate periods, the FMU's default tolerances) in one
    call and in thirty: the plate's clock moves its origin to each jump's landing, so the
    phase a replayed period sees does not carry the rounding of omega u at u ~ 3e7 (~1e-9
    rad), a noise that the jumps' check refused late in one long call (with the phase summed
    from the call's start: 9.0e6 steps in one call against 1.3e6 in thirty)."""
    one, thirty = (_vibrated_stick("C", 1e12, 3e7, omega=0.2, calls=calls, formulation=1) for calls in (1, 30))
    assert one.counters["periods_jumped"] > 0.99 * 3e7 / (2 * math.pi / 0.2)
    assert one.counters["accepted"] < 1.5 * thirty.counters["accepted"]
    ref, out = thirty.outputs(), one.outputs()
    assert out["slip_count"] == ref["slip_count"] == 0
    assert abs(out["x"] - ref["x"]) <= 1e-7
    assert abs(out["friction_force"] - ref["friction_force"]) <= 1e-10
    assert abs(out["phi_integral"] - ref["phi_integral"]) <= 1e-7 * ref["phi_integral"]


def test_jumps_tried_and_refused_leave_the_run_as_it_was():
    """Model C at the paper's parameters held at a crest from a stretched drive spring: the
    friction spring rings all along, no jump passes its check, and the tries (replays of
    the plate's period) cost steps but change nothing: the run is bit for bit the one with
    jumps off.  (A try's replays use the stepper's work arrays, so the step after a refused
    try starts from a fresh rate.)"""
    runs = {}
    for max_jump in (0.0, 1e12):
        block = stepped("C", initial_state=2, A=3.0, omega=0.316, x_start=CREST_X, dt=1.0,
                        max_jump=max_jump, formulation=1, rtol=1e-6, atol=1e-8)
        block.start()
        block.advance_to(2e4)
        runs[max_jump] = block
    tried, off = runs[1e12], runs[0.0]
    assert tried.counters["periods_jumped"] == 0
    assert tried.counters["accepted"] > off.counters["accepted"]  # the tries were made
    assert {name: value for name, value in tried.outputs().items() if name not in COST_OUTPUTS} == \
        {name: value for name, value in off.outputs().items() if name not in COST_OUTPUTS}


def test_jumps_stay_long_while_the_slow_variables_drift():
    """Model C held at a crest while the drive's pull grows a hundred times faster than at
    the paper's k_d (1e6 tau_0, 1.6e5 plate periods: the tangential spring's stretch moves
    by 0.1, the block by 0.35 delta_0 along the corrugation).  phi's per-period increment
    leaves the jumps' linear model quadratically in the drift; carried to second order, the
    jumps still span hundreds of periods, and the run agrees with every period resolved."""
    from vibroblock import defaults
    omega = 1.0
    # Ten calls keep the resolved run within the per-call step budget.
    resolved, jumped = (_vibrated_stick("C", max_jump, 1e6, omega=omega, calls=10, k_d=100 * defaults("C")["k_d"],
                                        formulation=1, rtol=1e-6, atol=1e-8) for max_jump in (0.0, 1e12))
    ref, out = resolved.outputs(), jumped.outputs()
    assert jumped.counters["periods_jumped"] > 0.99 * 1e6 / (2 * math.pi / omega)
    # Before the quadratures' second order: 1.5e6 steps (resolved: 2.5e6); now 3.9e5.
    assert jumped.counters["accepted"] < resolved.counters["accepted"] / 5
    assert out["slip_count"] == ref["slip_count"] == 0 and abs(ref["friction_force"]) > 0.09
    assert abs(out["x"] - ref["x"]) <= 1e-5
    assert abs(out["friction_force"] - ref["friction_force"]) <= 1e-7
    assert abs(out["phi_integral"] - ref["phi_integral"]) <= 1e-5 * ref["phi_integral"]
    assert abs(out["energy_dissipated"] - ref["energy_dissipated"]) <= 1e-6 * ref["energy_dissipated"]


def test_stroboscopic_jumps_stop_before_the_slip_they_would_cross():
    """A jump never crosses a switch: the slips that end a vibrated stick of model A come at
    the times every period resolved gives (event_driven as the independent reference).
    Calls of 1000 tau_0 (80 plate periods) leave room for jumps; within each call the slips
    are placed by the state at its end (x to 1e-6: a slip that came a period late or early
    moves x by ~V_d T = 0.1)."""
    parameters = dict(SCALED, A=0.5, omega=0.5)
    runs = {}
    for name, keywords in (("event_driven", {}), ("adaptive", {"exact_flows": False})):  # adaptive at rtol 1e-8
        block = Block("A", name, initial_state=2, dt=1e-2, **parameters, **keywords)
        block.start()
        slips_at, positions = [], []
        last = 0
        for step in range(1, 9):
            block.advance_to(step * 1000.0)
            count = block.output("slip_count")
            positions.append(block.output("x"))
            if count > last:
                slips_at.append(step * 1000.0)
                last = count
        runs[name] = (block, slips_at, np.array(positions))
    jumped = runs["adaptive"][0].counters["periods_jumped"]
    assert jumped > 0
    assert runs["adaptive"][1] == runs["event_driven"][1] and len(runs["event_driven"][1]) >= 2
    assert np.max(np.abs(runs["adaptive"][2] - runs["event_driven"][2])) <= 1e-6 * np.max(np.abs(runs["event_driven"][2]))


# ---------------------------------------------------------------- model A: exact flows
def _results(block):
    return {name: value for name, value in block.outputs().items() if name not in COST_OUTPUTS}


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_on_model_a_adaptive_takes_the_exact_flows(name):
    """By default adaptive runs model A by event_driven's exact flows: the same results bit
    for bit, no steps, no Jacobian, and every located event counted."""
    parameters, horizon, initial, x_start = scenario("A", name)
    runs = {}
    for integrator in ("adaptive", "event_driven"):
        block = Block("A", integrator, dt=1e-2, energy_balance=True, initial_state=initial, x_start=x_start,
                      **parameters)
        block.start()
        block.advance_to(horizon)
        runs[integrator] = block
    assert _results(runs["adaptive"]) == _results(runs["event_driven"])
    counters = runs["adaptive"].counters
    assert counters["accepted"] == counters["rejected"] == counters["jacobians"] == 0
    assert counters["events"] == runs["event_driven"].counters["events"] >= counters["resets"]
    if name != "sub-threshold":
        assert counters["events"] > 0


def test_exact_flows_count_the_events_of_the_independent_reference():
    """The events counted on model A are the reference's: on the stick-slip scenario (no
    cascades) one per Coulomb reset; bouncing, every landing and detachment."""
    for name, kinds in (("stick-slip", ("reset",)), ("bouncing", ("contact", "detach"))):
        parameters, horizon, initial, x_start = scenario("A", name)
        ref = reference.simulate("A", parameters, horizon, solver=Solver.reference(1e-12), initial=initial,
                                 x_start=x_start)
        block = Block("A", "adaptive", dt=1e-2, initial_state=initial, x_start=x_start, **parameters)
        block.start()
        block.advance_to(horizon)
        expected = sum(1 for _, kind in ref.event_log if kind in kinds)
        assert expected > 0
        if name == "stick-slip":
            assert block.counters["events"] == expected == ref.slips
        else:  # the switches of contact, plus the resets and holds event_driven resolves
            assert block.counters["events"] >= expected


@pytest.mark.parametrize("case, parameters, readings", [
    ("the applied-load bound", dict(SCALED), {"coulomb_normal": 1}),
    ("an undamped contact driven at resonance", dict(SCALED, gamma_n=0.0, A=0.05, omega=1.0), {}),
])
def test_where_event_driven_cannot_run_adaptive_takes_its_own_steps(case, parameters, readings):
    """No hand-over where event_driven refuses the reading or the parameters: adaptive's own
    steps run, and agree with the independent reference."""
    with pytest.raises(ModelError):
        Block("A", "event_driven", dt=1e-2, **parameters, **readings).start()
    block = Block("A", "adaptive", dt=1e-2, x_start=-40.0, **parameters, **readings, **TIGHT)
    block.start()
    block.advance_to(100.0)
    assert block.counters["accepted"] > 0
    ref = reference.simulate("A", parameters, 100.0, solver=Solver.reference(1e-12), x_start=-40.0, **readings)
    assert error(block.outputs(), ref) < 1e-7


def test_a_retuned_drive_that_event_driven_cannot_run_hands_back_to_steps():
    """Undamped contact: exact flows while the drive is off resonance; retuned onto it, the
    run goes on by adaptive's steps (event_driven alone refuses the retune) and agrees with
    a run on steps throughout."""
    parameters = dict(SCALED, gamma_n=0.0, A=0.05, omega=0.8)
    blocks = [Block("A", "adaptive", dt=1e-2, **parameters, **TIGHT), stepped("A", dt=1e-2, **parameters, **TIGHT)]
    for block in blocks:
        block.start()
        block.advance_to(50.0)
    assert blocks[0].counters["accepted"] == 0 < blocks[1].counters["accepted"]
    for block in blocks:
        block.set_parameter("omega", 1.0)
        block.advance_to(100.0)
    assert blocks[0].counters["accepted"] > 0
    a, b = blocks[0].outputs(), blocks[1].outputs()
    for key in ("x", "z", "vx", "vz"):
        assert a[key] == pytest.approx(b[key], rel=1e-7, abs=1e-8), key
    exact = Block("A", "event_driven", dt=1e-2, **parameters)
    exact.start()
    with pytest.raises(ModelError, match="resonance"):
        exact.set_parameter("omega", 1.0)


def test_exact_flows_is_an_option_of_model_a_fixed_before_the_start():
    with pytest.raises(ModelError, match="exact_flows is an option of model A only, not of model B"):
        Block("B", "adaptive", exact_flows=False)
    assert Block("C", "adaptive", exact_flows=True).options["exact_flows"]  # the default, without effect
    block = Block("A", "adaptive", exact_flows=False)
    block.start()
    with pytest.raises(ModelError, match="exact_flows is fixed once the run has started"):
        block.set_integrator_option("exact_flows", True)
    restored = Block("A", "adaptive")
    restored.set_state(block.get_state())
    assert restored.options["exact_flows"] is False
