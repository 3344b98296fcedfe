"""The readings of models B and C (``vibroblock.readings``, docs/physics.md): formulation,
Coulomb bound and flight, checked against facts -- the reduction to model A, statics,
Eq. (9)'s stick positions, the detachment onset, the energy balance, save/restore -- and
against the independent reference (``harness.paper.reference``)."""
import math

import numpy as np
import pytest

from harness.paper import analytic, reference
from vibroblock import Block, ModelError

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
GENTLE = {"A_x": 1.0, "omega_x": 0.5}  # slopes up to 0.5: no self-locking for mu_s = 0.5
READINGS = ("formulation", "coulomb_normal", "flight")
COMBINATIONS = [(f, c, fl) for f in (0, 1) for c in (0, 1) for fl in (0, 1) if not (f and fl)]
POINT = ("x", "z", "vx", "vz")


def options(combination):
    return dict(zip(READINGS, combination))


def ids(combination):
    f, c, fl = combination
    return f"{reference.FORMULATIONS[f]}-{reference.COULOMB_NORMALS[c]}-{reference.FLIGHTS[fl]}"


def run(model, times, integrator="rk4", names=POINT, **settings):
    block = Block(model, integrator, **settings)
    block.start()
    rows = []
    for t in times:
        block.advance_to(t)
        out = block.outputs()
        rows.append([out[n] for n in names])
    return np.array(rows, dtype=float), block


# ---------------------------------------------------------------- reduction to model A
@pytest.mark.parametrize("combination", COMBINATIONS, ids=ids)
@pytest.mark.parametrize("integrator", ["symplectic_euler", "rk4", "implicit_contact", "adaptive"])
def test_every_reading_reduces_exactly_to_model_a_on_a_flat_plate(integrator, combination):
    """A_x = 0 (and P_l = m g in C): B and C in any reading are model A with the same
    Coulomb bound, bit for bit, through contacts, detachments and resets (adaptive: the
    same error-controlled steps and located events, model A's own in every reading: on A its
    own steps, exact_flows off)."""
    opts = options(combination)
    if integrator == "implicit_contact" and (opts["formulation"] or opts["flight"]):
        pytest.skip("refused: test_implicit_contact_refuses_the_tangent_frame_and_free_flight")
    common = dict(SCALED, A=1.0, omega=0.8, initial_state=2, energy_balance=True, dt=1e-3)
    names = POINT + ("penetration", "normal_force", "friction_force", "slip_count", "phi_integral",
                     "work_input", "energy_dissipated", "surface_z")
    times = np.linspace(5.0, 40.0, 8)
    own_steps = {"exact_flows": False} if integrator == "adaptive" else {}
    a, block_a = run("A", times, integrator, names, **common, coulomb_normal=opts["coulomb_normal"], **own_steps)
    assert not a[:, 4].min() > 0.0  # flights
    assert block_a.counters["resets"] > 0 or opts["coulomb_normal"] == 1  # (the applied load holds the stick)
    for model, extra in (("B", {}), ("C", {"P_l": 1.0})):
        other, _ = run(model, times, integrator, names, **common, A_x=0.0, **extra, **opts)
        np.testing.assert_array_equal(other, a, err_msg=f"{model} {opts}")


def test_implicit_contact_refuses_the_tangent_frame_and_free_flight():
    for reading, why in (("formulation", "tangent_frame"), ("flight", "free")):
        block = Block("B", "implicit_contact", **{reading: 1})
        with pytest.raises(ModelError, match=f"implicit_contact integrator .*{why}.*symplectic_euler or rk4"):
            block.start()


def test_event_driven_refuses_the_applied_load_bound():
    with pytest.raises(ModelError, match="event_driven integrator .*applied_load"):
        Block("A", "event_driven", coulomb_normal=1).start()


def test_bad_readings_are_refused_with_what_is_allowed():
    with pytest.raises(ModelError, match=r"formulation = 2 is not admissible.*0 \(fixed_axes\), 1 \(tangent_frame\)"):
        Block("B", formulation=2)
    with pytest.raises(ModelError, match="formulation = 1 .* models B, C, not model A"):
        Block("A", formulation=1)
    with pytest.raises(ModelError, match="not admissible"):
        Block("C", flight=True)
    with pytest.raises(ModelError, match="tangent frame has no position in the plane"):
        Block("C", formulation="tangent_frame", flight="free").start()
    with pytest.raises(ModelError, match="scene reductions"):
        Block("B", rigid_contact=True, coulomb_normal=1).start()
    assert Block("C", formulation="tangent_frame", coulomb_normal="applied_load").readings == {
        "formulation": 1, "coulomb_normal": 1, "flight": 0, "contact_law": 0, "friction_law": 0, "plate_motion": 0}


# ---------------------------------------------------------------- statics
# The statics of docs/physics.md Sec. 8 are derived for the contact force along the normal;
# the conservative contact's curvature term shifts a rest point on a curved flank by
# C / (its stiffness along the surface), tested in laws/test_contact_linear.py.
ALONG_NORMAL = {"contact_law": "linear_along_normal"}
@pytest.mark.parametrize("coulomb_normal", [0, 1])
@pytest.mark.parametrize("formulation", [0, 1])
@pytest.mark.parametrize("model, extra", [("B", {}), ("C", {"P_l": 1.3})])
def test_rest_on_a_flank_balances_the_applied_load_and_the_drive(model, extra, formulation, coulomb_normal):
    """At rest on a 20-degree flank, drive spring stretched: delta = N_a / k_n with
    N_a = W_n - k_d (x - V_d t) sin a, and the tangential spring holds (load + drive) . t."""
    settings = dict(**GENTLE, k_d=5e-2, V_d=0.0, k_t=10.0, gamma_t=0.5, gamma_n=0.5, mu_s=1.0, dt=1e-2, **extra)
    x_start = math.acos(math.tan(math.radians(20.0)) / 0.5) / 0.5
    out, block = run(model, [300.0], "rk4", POINT + ("penetration", "friction_force"), x_start=x_start,
                     formulation=formulation, coulomb_normal=coulomb_normal, **settings, **ALONG_NORMAL)
    p = {**reference.DEFAULTS[model], **settings}
    x, z, vx, vz, penetration, friction = out[-1]
    n_a = analytic.applied_normal(model, p, x, 300.0)
    assert block.counters["resets"] == 0
    assert penetration == pytest.approx(n_a / p["k_n"], abs=1e-10)
    assert -friction == pytest.approx(analytic.applied_tangential(model, p, x, 300.0), abs=1e-10)
    assert abs(vx) < 1e-10 and abs(vz) < 1e-10
    cos_a, _ = analytic.tilt(x, GENTLE["A_x"], GENTLE["omega_x"])
    assert z == pytest.approx(GENTLE["A_x"] * math.sin(GENTLE["omega_x"] * x) - n_a / (p["k_n"] * cos_a), abs=1e-10)


@pytest.mark.parametrize("formulation", [0, 1])
def test_model_b_without_friction_sticks_at_the_stable_roots_of_eq9(formulation):
    """k_t = 0: the block rests at a stable root of cos(omega_x x*) = K (x* - V_d t), lagging
    it by the dashpot's share gamma_t x' / (cos^2 a U''), pressed in by delta* = m g / (k_n cos a)."""
    settings = dict(**GENTLE, k_d=5e-2, V_d=2e-2, gamma_t=0.3, gamma_n=0.5, k_t=0.0, dt=2e-2)
    p = {**reference.DEFAULTS["B"], **settings}
    roots, stable = analytic.model_b_equilibria(p, 0.0)
    x_start = roots[stable][np.argmin(np.abs(roots[stable]))]
    times = np.arange(5.0, 1200.1, 5.0)
    out, _ = run("B", times, "rk4", ("x", "vx", "penetration"), x_start=x_start, formulation=formulation, **settings,
                 **ALONG_NORMAL)
    x, vx, penetration = out.T
    assert x[-1] - x_start > 1.5 * 2.0 * math.pi / p["omega_x"]  # slipped over several crests
    fast = np.abs(vx) > p["V_d"]
    settled = np.array([t >= 100.0 and not fast[(times > t - 100.0) & (times <= t + 50.0)].any() for t in times])
    assert settled.mean() > 0.5
    deep = 0
    for t, xk, vk, pen in zip(times[settled], x[settled], vx[settled], penetration[settled]):
        roots, stable = analytic.model_b_equilibria(p, t)
        k = np.argmin(np.abs(roots - xk))
        assert stable[k], f"t = {t}: next to an unstable root"
        u2 = p["k_d"] - p["m"] * p["g"] * p["A_x"] * p["omega_x"] ** 2 * math.sin(p["omega_x"] * roots[k])
        cos_a = analytic.tilt(roots[k], p["A_x"], p["omega_x"])[0]
        lag = p["gamma_t"] * vk / (cos_a ** 2 * u2)
        assert abs(xk - roots[k]) < 2.0 * abs(lag) + 1e-4, f"t = {t}"
        if formulation == 1:
            assert abs(xk - (roots[k] - lag)) < 0.1 * abs(lag) + 1e-5, f"t = {t}"
        if u2 > 0.15:
            deep += 1
            assert pen == pytest.approx(p["m"] * p["g"] / (p["k_n"] * cos_a), rel=1e-3)
    assert deep > 50


@pytest.mark.parametrize("formulation", [0, 1])
def test_model_c_without_friction_never_sticks(formulation):
    settings = dict(**GENTLE, k_d=5e-2, V_d=2e-2, gamma_t=0.3, k_t=0.0, dt=2e-2)
    times = np.arange(5.0, 1000.1, 5.0)
    c, _ = run("C", times, "rk4", ("vx",), formulation=formulation, **settings, **ALONG_NORMAL)
    b, _ = run("B", times, "rk4", ("vx",), formulation=formulation, **settings, **ALONG_NORMAL)
    late = times > 100.0
    assert np.all(np.abs(c[late, 0] / settings["V_d"] - 1.0) < 0.05)
    assert np.mean(b[late, 0] < 0.5 * settings["V_d"]) > 0.5


# ---------------------------------------------------------------- detachment onset
@pytest.mark.parametrize("omega", [0.3, 1.0, 3.0])
def test_tangent_frame_model_c_detaches_at_a_c_with_g_replaced_by_p_l(omega):
    """On a 60-degree flank of the paper's corrugation, drive off: embedded at 0.97 A_c,
    detached at 1.03 A_c, A_c = (P_l / m omega^2) |k_n - m omega^2 + i gamma_n omega| / k_n."""
    x_start = math.acos(math.tan(math.radians(60.0)) / 20.0) / 2e-2
    onset = float(analytic.detachment_amplitude(omega, load=1.5))
    period = 2.0 * math.pi / omega
    times = np.linspace(period / 400.0, 3.0 * period, 1200)
    for factor, detaches in ((0.97, False), (1.03, True)):
        out, _ = run("C", times, "rk4", ("x", "contact", "penetration"), P_l=1.5, k_d=0.0, V_d=0.0,
                     A=factor * onset, omega=omega, initial_state=2, x_start=x_start, formulation=1,
                     dt=period / 4000.0)
        assert (not out[:, 1].all()) == detaches, factor
        if not detaches:
            assert out[:, 2].min() > 0.0
        assert np.max(np.abs(out[:, 0] - x_start)) < 1e-9  # nothing acts along the tangent


# ---------------------------------------------------------------- energy balance
@pytest.mark.parametrize("combination", COMBINATIONS, ids=ids)
@pytest.mark.parametrize("model", ["B", "C"])
def test_energy_balance_closes(model, combination):
    """Bouncing on the corrugation with resets: the residual of docs/physics.md's balance is
    the integration error -- first order for symplectic Euler (quartering dt quarters it),
    round-off plus the events' share for rk4, and implicit_contact's where it runs."""
    opts = options(combination)
    settings = dict(SCALED, **GENTLE, A=1.5, omega=0.8, x_start=1.0, energy_balance=True, initial_state=2, **opts)
    times = np.linspace(8.0, 40.0, 5)
    names = ("energy_residual", "energy_dissipated", "contact")
    rk4, _ = run(model, times, "rk4", names, dt=1e-3, **settings)
    assert rk4[-1, 1] > 1.0 and not rk4[:, 2].all()
    assert np.max(np.abs(rk4[:, 0])) < 5e-6  # (measured 2.1e-6: B, fixed axes, the contact-force bound)
    coarse, _ = run(model, times, "symplectic_euler", names, dt=1e-3, **settings)
    fine, _ = run(model, times, "symplectic_euler", names, dt=2.5e-4, **settings)
    assert np.max(np.abs(coarse[:, 0])) < 0.1
    assert np.max(np.abs(fine[:, 0])) < 0.4 * np.max(np.abs(coarse[:, 0]))
    if not (opts["formulation"] or opts["flight"]):
        implicit, _ = run(model, times, "implicit_contact", names, dt=1e-3, **settings)
        assert np.max(np.abs(implicit[:, 0])) < 1e-3


# ---------------------------------------------------------------- state
@pytest.mark.parametrize("combination", [(1, 1, 0), (0, 1, 1)], ids=ids)
def test_saved_state_continues_bit_for_bit(combination):
    settings = dict(SCALED, **GENTLE, A=1.5, omega=0.8, x_start=1.0, initial_state=2, dt=1e-3, energy_balance=True,
                    **options(combination))
    block = Block("C", "rk4", **settings)
    block.start()
    block.advance_to(10.0)
    state = block.get_state()
    block.advance_to(20.0)
    expected = block.outputs()
    again = Block("C", "rk4", **SCALED)
    again.set_state(state)
    assert again.readings == {**options(combination), "contact_law": 0, "friction_law": 0, "plate_motion": 0}
    again.advance_to(20.0)
    assert again.outputs() == expected


# ---------------------------------------------------------------- the reference
@pytest.mark.parametrize("combination", COMBINATIONS, ids=ids)
@pytest.mark.parametrize("model", ["B", "C"])
def test_the_core_agrees_with_the_reference(model, combination):
    """Short scaled runs: embedded (C, no events: to 1e-8 with rk4) and bouncing with resets
    (events at step ends: to the first-order error of dt = 1e-3)."""
    opts = options(combination)
    times = np.linspace(2.0, 20.0, 10)
    cases = [(dict(A=1.5, omega=0.8), 3e-2)]
    if model == "C":
        cases.append((dict(A=0.3, omega=0.8), 1e-8))
    for extra, tolerance in cases:
        p = dict(SCALED, **GENTLE, **extra)
        ref = reference.simulate(model, p, 20.0, times, solver=reference.Solver.reference(1e-11), initial=2,
                                 x_start=1.0, **opts)
        expected = np.stack([ref[name] for name in POINT], axis=1)
        core, _ = run(model, times, "rk4", POINT, initial_state=2, dt=1e-3, x_start=1.0, **p, **opts)
        assert np.max(np.abs(core - expected)) < tolerance, extra
