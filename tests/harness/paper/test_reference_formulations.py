"""The reference's two formulations of models B and C, its two Coulomb bounds and its two
flight rules (docs/physics.md), checked against closed-form facts rather than stored outputs."""
import math

import numpy as np
import pytest

from harness.paper import analytic, reference

SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
GENTLE = {"A_x": 1.0, "omega_x": 0.5}  # slopes up to 0.5 (27 degrees): no self-locking for mu_s = 0.5
COMBINATIONS = [(f, c, fl) for f in reference.FORMULATIONS for c in reference.COULOMB_NORMALS
                for fl in reference.FLIGHTS if not (f == "tangent_frame" and fl == "free")]


def options(combination):
    return dict(zip(("formulation", "coulomb_normal", "flight"), combination))


def test_options_are_taken_by_name_or_code_and_nonsense_is_refused():
    times = np.linspace(4.0, 20.0, 5)
    settings = dict(SCALED, **GENTLE, A=1.5, omega=0.8)
    by_name = reference.simulate("C", settings, 20.0, times, formulation="tangent_frame",
                                 coulomb_normal="applied_load", x_start=1.0)
    by_code = reference.simulate("C", settings, 20.0, times, formulation=1, coulomb_normal=1, flight=0, x_start=1.0)
    np.testing.assert_array_equal(by_name["x"], by_code["x"])
    assert by_code.formulation == "tangent_frame" and by_code.coulomb_normal == "applied_load"
    with pytest.raises(ValueError, match="fixed-axes formulation only"):
        reference.simulate("B", settings, 1.0, formulation="tangent_frame", flight="free")
    with pytest.raises(ValueError, match="formulation"):
        reference.simulate("B", settings, 1.0, formulation="rotating")
    with pytest.raises(ValueError, match="coulomb_normal"):
        reference.simulate("B", settings, 1.0, coulomb_normal=2)


@pytest.mark.parametrize("combination", COMBINATIONS, ids="-".join)
def test_every_formulation_reduces_to_model_a_on_a_flat_plate(combination):
    """A_x = 0 (and P_l = m g in C): B, C and A itself, in any reading, are the fixed-axes
    model A with the same Coulomb bound, through contacts, detachments and resets."""
    opts = options(combination)
    common = dict(SCALED, A=1.0, omega=0.8)
    times = np.linspace(5.0, 40.0, 8)
    a = reference.simulate("A", common, 40.0, times, initial=2, coulomb_normal=opts["coulomb_normal"])
    kinds = {kind for _, kind in a.event_log}
    assert {"contact", "detach"} <= kinds
    runs = [reference.simulate("A", common, 40.0, times, initial=2, **opts),
            reference.simulate("B", dict(common, A_x=0.0), 40.0, times, initial=2, **opts),
            reference.simulate("C", dict(common, A_x=0.0, P_l=1.0), 40.0, times, initial=2, **opts)]
    for run in runs:
        assert [k for _, k in run.event_log] == [k for _, k in a.event_log]
        for name in ("x", "z", "vx", "vz", "F", "phi", "work", "dissipated"):
            np.testing.assert_allclose(run[name], a[name], atol=1e-9, err_msg=name)


@pytest.mark.parametrize("formulation", reference.FORMULATIONS)
@pytest.mark.parametrize("model, extra", [("B", {}), ("C", {"P_l": 1.3})])
def test_rest_on_a_flank_balances_the_applied_load_and_the_drive(formulation, model, extra):
    """At rest on a 20-degree flank with the drive spring stretched: penetration
    delta = N_a / k_n, N_a = W_n - k_d (x - V_d t) sin a (the drive's normal component
    included), and the tangential spring holds the tangential applied force."""
    settings = dict(**GENTLE, k_d=5e-2, V_d=0.0, k_t=10.0, gamma_t=0.5, gamma_n=0.5, mu_s=1.0, **extra)
    x_start = math.acos(math.tan(math.radians(20.0)) / 0.5) / 0.5  # uphill flank, stretch x - V_d t = x > 0
    run = reference.simulate(model, settings, 300.0, [300.0], formulation=formulation, x_start=x_start,
                             contact_law="linear_along_normal")  # (the statics derived for it)
    assert run.events == 0
    p, x = run.parameters, run.final("x")
    n_a = analytic.applied_normal(model, p, x, 300.0)
    assert n_a != pytest.approx(analytic.applied_normal(model, dict(p, k_d=0.0), x), rel=1e-3)  # the drive term shows
    assert run.final("delta") == pytest.approx(n_a / p["k_n"], abs=1e-10)
    assert p["k_t"] * run.final("F") == pytest.approx(analytic.applied_tangential(model, p, x, 300.0), abs=1e-10)
    assert abs(run.final("vx")) < 1e-10 and abs(run.final("vz")) < 1e-10
    if formulation == "tangent_frame":
        assert run.final("zeta") == pytest.approx(-n_a / p["k_n"], abs=1e-10)


def _model_b_without_friction(formulation, **extra):
    settings = dict(**GENTLE, k_d=5e-2, V_d=2e-2, gamma_t=0.3, gamma_n=0.5, k_t=0.0, **extra)
    p = {**reference.DEFAULTS["B"], **settings}
    roots, stable = analytic.model_b_equilibria(p, 0.0)
    x_start = roots[stable][np.argmin(np.abs(roots[stable]))]
    times = np.arange(5.0, 2000.1, 5.0)
    run = reference.simulate("B", settings, 2000.0, times, formulation=formulation, x_start=x_start,
                             contact_law="linear_along_normal",
                             initial=2 if "A" in extra else 0)
    return p, x_start, times, run


@pytest.mark.parametrize("formulation", reference.FORMULATIONS)
def test_model_b_without_friction_sticks_at_the_stable_roots_of_eq9(formulation):
    """k_t = 0: the block sits at a stable root of cos(omega_x x*) = K (x* - V_d t), drifts at
    Eq. (10)'s V_stick, and slips only when its root meets the unstable one (the fold,
    sin(omega_x x_f) = k_d / (m g A_x omega_x^2))."""
    p, x_start, times, run = _model_b_without_friction(formulation)
    x, vx = run["x"], run["vx"]
    wavelength = 2.0 * math.pi / p["omega_x"]
    assert run.final("x") - x_start > 2.5 * wavelength  # several slips
    fast = np.abs(vx) > p["V_d"]
    # settled: 100 tau_0 after the last slip, 50 before the next (a slip starts slowly at the fold)
    settled = np.array([t >= 100.0 and not fast[(times > t - 100.0) & (times <= t + 50.0)].any() for t in times])
    assert settled.mean() > 0.6
    checked = 0
    for t, xk, vk in zip(times[settled], x[settled], vx[settled]):
        roots, stable = analytic.model_b_equilibria(p, t)
        k = np.argmin(np.abs(roots - xk))
        assert stable[k], f"t = {t}: next to an unstable root"
        root = roots[k]
        curvature = p["k_d"] - p["m"] * p["g"] * p["A_x"] * p["omega_x"] ** 2 * math.sin(p["omega_x"] * root)
        cos2 = analytic.tilt(root, p["A_x"], p["omega_x"])[0] ** 2
        lag = p["gamma_t"] * vk / (cos2 * curvature)  # the dashpot's force shifts the balance
        assert abs(xk - root) < 2.0 * lag + 1e-4, f"t = {t}"
        if formulation == "tangent_frame":
            assert abs(xk - (root - lag)) < 0.1 * lag + 1e-5, f"t = {t}"
        if curvature > 0.15:  # deep in the well
            checked += 1
            assert vk == pytest.approx(analytic.drift_velocity(p, root), rel=0.05)
    assert checked > 100
    # the first stick ends at its fold, not before
    fold_phase = math.asin(p["k_d"] / (p["m"] * p["g"] * p["A_x"] * p["omega_x"] ** 2))
    x_fold = (2.0 * math.pi * math.floor((p["omega_x"] * x_start + math.pi) / (2.0 * math.pi)) + fold_phase) / p["omega_x"]
    t_fold = (x_fold + p["m"] * p["g"] * p["A_x"] * p["omega_x"] * math.cos(p["omega_x"] * x_fold) / p["k_d"]) / p["V_d"]
    assert x[times < t_fold].max() < x_fold
    assert np.interp(t_fold + 60.0, times, x) > x_fold + 0.5 * wavelength


def test_tangent_frame_model_b_horizontal_motion_ignores_the_vibration():
    """Claim C5 holds by construction in the tangent frame: with k_t = 0 the tangential
    equation does not contain zeta, so a vibration that makes the block bounce leaves x(t)
    as it was without vibration."""
    _, _, _, calm = _model_b_without_friction("tangent_frame")
    _, _, _, shaken = _model_b_without_friction("tangent_frame", A=2.0, omega=1.3)
    assert not shaken["contact"].all() and shaken.events > 100
    np.testing.assert_allclose(shaken["x"], calm["x"], atol=1e-8)


@pytest.mark.parametrize("formulation", reference.FORMULATIONS)
def test_model_c_without_friction_never_sticks(formulation):
    """k_t = 0: model C's tangential balance -k_d (x - V_d t) cos a = 0 has no steady root
    away from the drive, so the block follows it (dx/dt near V_d), where model B sticks."""
    settings = dict(**GENTLE, k_d=5e-2, V_d=2e-2, gamma_t=0.3, k_t=0.0)
    times = np.arange(5.0, 1500.1, 5.0)
    c = reference.simulate("C", settings, 1500.0, times, formulation=formulation, contact_law="linear_along_normal")
    b = reference.simulate("B", settings, 1500.0, times, formulation=formulation, contact_law="linear_along_normal")
    late = times > 100.0
    assert np.all(np.abs(c["vx"][late] / settings["V_d"] - 1.0) < 0.05)
    assert np.mean(b["vx"][late] < 0.5 * settings["V_d"]) > 0.5


@pytest.mark.parametrize("coulomb_normal", reference.COULOMB_NORMALS)
@pytest.mark.parametrize("omega", [0.3, 1.0, 3.0])
def test_tangent_frame_model_c_detaches_at_a_c_with_g_replaced_by_p_l(omega, coulomb_normal):
    """On a 60-degree flank, drive off: the normal motion is model A's oscillator with P_l in
    place of m g, so on its steady orbit the block stays embedded at 0.97 A_c and
    detaches at 1.03 A_c, A_c = (P_l / m omega^2) |k_n - m omega^2 + i gamma_n omega| / k_n."""
    x_start = math.acos(math.tan(math.radians(60.0)) / 20.0) / 2e-2  # the paper's corrugation
    onset = float(analytic.detachment_amplitude(omega, load=1.5))
    for factor, detaches in ((0.97, False), (1.03, True)):
        settings = dict(P_l=1.5, k_d=0.0, V_d=0.0, A=factor * onset, omega=omega)
        run = reference.simulate("C", settings, 3 * 2 * math.pi / omega, formulation="tangent_frame",
                                 coulomb_normal=coulomb_normal, initial=2, x_start=x_start,
                                 solver=reference.Solver.reference())
        assert ("detach" in {kind for _, kind in run.event_log}) == detaches, factor
        assert run.final("x") == x_start  # nothing acts along the tangent


@pytest.mark.parametrize("combination", COMBINATIONS, ids="-".join)
@pytest.mark.parametrize("model", ["B", "C"])
def test_energy_balance_closes(model, combination):
    """Bouncing on a corrugated plate with resets: stored energy change = work - dissipated,
    with the stored energy and the work of docs/physics.md for each formulation."""
    settings = dict(SCALED, **GENTLE, A=1.5, omega=0.8)
    run = reference.simulate(model, settings, 80.0, np.linspace(8.0, 80.0, 10), x_start=1.0, **options(combination))
    assert {"contact", "detach"} <= {kind for _, kind in run.event_log}
    assert run.final("dissipated") > 5.0
    assert np.max(np.abs(run.energy_residual())) < 1e-9


def test_tangent_frame_normal_spring_energy_is_half_k_n_delta_squared():
    settings = dict(SCALED, **GENTLE, A=1.5, omega=0.8)
    run = reference.simulate("B", settings, 80.0, np.linspace(0.5, 80.0, 160), x_start=1.0, formulation="tangent_frame")
    touching = run["contact"]
    assert 0.2 < touching.mean() < 0.9
    np.testing.assert_allclose(run["e_normal"][touching], 0.5 * run["delta"][touching] ** 2, atol=1e-10)


@pytest.mark.parametrize("formulation", reference.FORMULATIONS)
def test_applied_load_bound_keeps_the_stick_time_of_claim_c1_under_vibration(formulation):
    """Model A, vibration below friction loss (A = 0.3 < A_N(0.8) = 0.57): with the applied
    load as the bound the first slip comes at the unvibrated time (claim C1's
    mu_s m g / (k_t V_S)), claim C2 true by construction; with the contact force the bound
    dips to mu_s m g (1 - A / A_N) every period and the slip comes within a period of
    C1's time scaled by that factor."""
    settings = dict(k_d=5e-2, V_d=5e-2, gamma_t=5e-2)
    stick = reference.stick_slip_cycle(settings)["stick_time"]

    def first_reset(amplitude, bound):
        run = reference.simulate("A", dict(settings, A=amplitude, omega=0.8), 300.0, [300.0], initial=2,
                                 formulation=formulation, coulomb_normal=bound, solver=reference.Solver.reference())
        assert "detach" not in {kind for _, kind in run.event_log}
        return next(t for t, kind in run.event_log if kind == "reset")

    calm = first_reset(0.0, "contact_force")
    assert calm == pytest.approx(stick, rel=2e-3)
    assert first_reset(0.3, "applied_load") == pytest.approx(calm, abs=1e-6)
    earliest = stick * (1.0 - 0.3 / float(analytic.friction_loss_amplitude(0.8)))
    assert earliest - 1.0 < first_reset(0.3, "contact_force") < earliest + 2.0 * math.pi / 0.8 + 1.0


def test_free_flight_follows_the_drive_where_surface_flight_is_trapped_under_a_crest():
    """Model C in fixed axes, dropped from high above a crest (no damping): with the load
    along the normal taken under the flying block (flight = 'surface') the horizontal
    component P_l sin a traps the block under the crest; in free flight it is the drive's
    undamped oscillator x = V_d t + x0 cos(W t) - (V_d / W) sin(W t), W^2 = k_d / m, and
    falls as z0 - P_l t^2 / (2 m)."""
    settings = dict(**GENTLE, k_d=1e-2, V_d=1e-2, gamma_t=0.0)
    x0 = 0.5 * math.pi / GENTLE["omega_x"]
    times = np.linspace(100.0, 1900.0, 19)
    free = reference.simulate("C", settings, 1900.0, times, initial=1, flight="free", x_start=x0, z_start=2e6)
    trapped = reference.simulate("C", settings, 1900.0, times, initial=1, flight="surface", x_start=x0, z_start=2e6)
    assert free.events == trapped.events == 0
    w = math.sqrt(settings["k_d"])
    exact = settings["V_d"] * times + x0 * np.cos(w * times) - settings["V_d"] / w * np.sin(w * times)
    np.testing.assert_allclose(free["x"], exact, atol=1e-8)
    np.testing.assert_allclose(free["z"], 2e6 - 0.5 * times ** 2, rtol=1e-12)
    assert np.max(np.abs(trapped["x"] - x0)) < 0.5 * math.pi / GENTLE["omega_x"]
    assert np.max(np.abs(free["x"] - x0)) > 2.0 * math.pi / GENTLE["omega_x"]


def test_free_flight_falls_straight_where_the_surface_dashpot_pushes_the_block_sideways():
    """Drive off, dropped over a 20-degree flank: in free flight only the load acts, so x
    stays put; with flight = 'surface' the dashpot -gamma_t u_t t, u_t containing
    v_z sin a, turns the fall into a sideways push."""
    settings = dict(**GENTLE, k_d=0.0, V_d=0.0, gamma_t=5e-3)
    x0 = math.acos(math.tan(math.radians(20.0)) / 0.5) / 0.5
    times = np.linspace(10.0, 100.0, 10)
    runs = {flight: reference.simulate("B", settings, 100.0, times, initial=1, flight=flight, x_start=x0, z_start=1e4)
            for flight in reference.FLIGHTS}
    assert runs["free"].events == runs["surface"].events == 0
    np.testing.assert_array_equal(runs["free"]["x"], x0)
    np.testing.assert_allclose(runs["free"]["z"], 1e4 - 0.5 * times ** 2, rtol=1e-13)
    assert np.max(np.abs(runs["surface"]["x"] - x0)) > 1.0


def test_tangent_frame_point_outputs_are_consistent_and_invert_the_start():
    """z = h(x) + zeta / cos a and its rates: vx, vz are the time derivatives of x, z along a
    run (a landing on the corrugation, resets), and a start given as a point comes back unchanged."""
    settings = dict(SCALED, **GENTLE, A=0.4, omega=0.8, V_d=0.3)
    start = dict(x_start=1.0, z_start=1.0, vx_start=0.3, vz_start=-0.1)  # above the surface: lands
    times = np.linspace(0.0, 6.0, 6001)
    run = reference.simulate("B", settings, 6.0, times, initial=1, formulation="tangent_frame", **start)
    assert [run[name][0] for name in ("x", "z", "vx", "vz")] == pytest.approx(list(start.values()), abs=1e-14)
    smooth = slice(5, -5)
    # (central differences err by ~dt * jump in acceleration at contacts and detachments)
    np.testing.assert_allclose(np.gradient(run["x"], times)[smooth], run["vx"][smooth], atol=1e-3)
    np.testing.assert_allclose(np.gradient(run["z"], times)[smooth], run["vz"][smooth], atol=1e-3)
    assert "contact" in {kind for _, kind in run.event_log}
    assert np.max(np.abs(run["vx"] - run["u"])) > 1e-2  # the map is not the identity here
