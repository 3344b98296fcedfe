"""Rate-and-state friction (friction_law = 3 aging, 4 slip): the closed forms, an
independent solve_ivp reference, Ruina's critical stiffness, and the refusals."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from vibroblock import Block, layout as L
from vibroblock.block import ModelError
from vibroblock.laws import LAWS, law_parameters

LAWS_RS = ("rate_state_aging", "rate_state_slip")
A_, B_, DC, V0, MU0 = 0.01, 0.015, 0.1, 1e-3, 0.5


def law_module(name):
    return next(law for law in LAWS["friction"].values() if law.name == name).module


def prm_array(k_t, **overrides):
    values = {p.name: p.default for p in law_parameters()}
    values.update(rs_a=A_, rs_b=B_, rs_D_c=DC, rs_V_0=V0, rs_mu_0=MU0, **overrides)
    prm = np.zeros(L.N_PRM)
    for name, value in values.items():
        prm[L.slot(name)] = value
    prm[L.P_KT] = k_t
    return prm


# ------------------------------------------------------ an independent reference (numpy)
def reference_slip_rate(mu, theta, a=A_, b=B_):
    """V from mu = a asinh(V / (2 V_0) exp(Psi / a)), Psi = mu_0 + b ln(V_0 theta / D_c)."""
    psi = MU0 + b * np.log(V0 * theta / DC)
    return 2.0 * V0 * np.exp(-psi / a) * np.sinh(mu / a)


def reference_state_rate(law, v, theta):
    if law == "rate_state_aging":
        return 1.0 - v * theta / DC
    return -(v * theta / DC) * np.log(v * theta / DC)


def steady_mu(v, a=A_, b=B_):
    """The regularized law at steady state theta = D_c / V (mu_0 + (a - b) ln(V / V_0) to
    a relative exp(-2 Psi / a))."""
    psi = MU0 + b * np.log(V0 / v)
    return a * np.arcsinh(v / (2.0 * V0) * np.exp(psi / a))


@pytest.mark.parametrize("normal", [1e3, 1.0, 1e-3, 1e-30, 1e-200])
@pytest.mark.parametrize("shear", [1e-300, 1e-20, 1e-9, 0.5, 1.785, 1.9, 10.0, 1e3])
def test_the_interface_s_slip_solves_backward_euler_from_creep_to_overflow(shear, normal):
    """F_1 + h V(F_1) = F_0 however small F (exp(-2 r) rounds to 1) or N_b (V overflows
    by hundreds of decades): checked where it is representable, as ln(h V(F_1)) =
    ln(F_0 - F_1) with V written out here (ln sinh r summed as numpy's logaddexp)."""
    k_t, h, theta = 0.28, 1e-2, 5e4
    module = law_module("rate_state_aging")
    prm = prm_array(k_t)
    f1, theta1, reset = module.rule(shear, theta, 1.0, normal, 0.0, h, prm)
    assert 0.0 <= f1 <= shear and math.isfinite(theta1) and theta1 > 0.0 and not reset
    psi = MU0 + B_ * math.log(V0 * theta / DC)
    creep = h * k_t / (A_ * normal) * 2.0 * V0 * math.exp(-psi / A_)  # h dV/dF at F = 0
    if shear / (1.0 + creep) < 1e-300:  # relaxed below the doubles' range (N_b ~ 0)
        assert f1 < 1e-300
        return
    r = k_t * f1 / (A_ * normal)
    log_sinh = np.logaddexp(r, -r) - math.log(2.0) + math.log(-math.expm1(-2.0 * r)) - math.log1p(math.exp(-2.0 * r))
    log_hv = math.log(h) + math.log(2.0 * V0) - psi / A_ + log_sinh
    if shear - f1 > 1e-12 * shear:  # the slip is resolved: the two sides agree, to F's rounding
        assert log_hv == pytest.approx(math.log(shear - f1), abs=1e-10 + 4.4e-16 * shear / (shear - f1))
    else:  # the slip is below F's rounding
        assert math.exp(log_hv) <= 1e-12 * shear


@pytest.mark.parametrize("integrator", ["symplectic_euler", "adaptive"])
@pytest.mark.parametrize("law", LAWS_RS)
def test_steady_sliding_obeys_mu_ss_of_the_printed_law(law, integrator):
    """A velocity-strengthening block (a > b) driven at V_d slides steadily; the spring then
    holds mu_ss N = (mu_0 + (a - b) ln(V_d / V_0)) N, the drive's stretch adds the dashpot."""
    a, b, v_d, k_d, gamma_t = 0.015, 0.01, 1e-2, 1e-2, 5e-3
    block = Block("A", integrator, 0, False, dt=1e-2, friction_law=law, k_d=k_d, V_d=v_d,
                  gamma_t=gamma_t, A=0.0, rs_a=a, rs_b=b, rs_D_c=DC, rs_V_0=V0, rs_mu_0=MU0, rs_theta_0=DC / V0)
    block.start()
    block.advance_to(30000.0)
    out = block.outputs()
    mu_ss = MU0 + (a - b) * math.log(v_d / V0)
    assert out["vx"] == pytest.approx(v_d, rel=1e-6)
    assert abs(out["friction_force"]) / out["normal_force"] == pytest.approx(mu_ss, rel=1e-9)
    assert v_d * 30000.0 - out["x"] == pytest.approx((mu_ss + gamma_t * v_d) / k_d, rel=1e-6)


def law_run(law, k_t, h, v1, v2, t_end):
    """The rule driven as the velocity-step experiment: the spring's end (the block,
    stiff machine k_t) moves at v1 until t = 0, at v2 after; mu(t) = k_t F / N."""
    module = law_module(law)
    prm = prm_array(k_t)
    theta = DC / v1
    shear = steady_mu(v1) / k_t
    times = np.arange(1, int(round(t_end / h)) + 1) * h
    mu = np.empty_like(times)
    for i in range(len(times)):
        shear, theta, reset = module.rule(shear + h * v2, theta, 1.0, 1.0, v2, h, prm)
        assert not reset
        mu[i] = k_t * shear
    return times, mu


def reference_run(law, k_t, v1, v2, times):
    def rates(t, y):
        mu, theta = y
        v = reference_slip_rate(mu, theta)
        return [k_t * (v2 - v), reference_state_rate(law, v, theta)]
    solution = solve_ivp(rates, (0.0, times[-1]), [steady_mu(v1), DC / v1], method="Radau", t_eval=times,
                         rtol=1e-11, atol=1e-14)
    assert solution.success
    return solution.y[0]


@pytest.mark.parametrize("law", LAWS_RS)
def test_a_velocity_step_follows_the_reference_and_the_closed_forms(law):
    """A ten-fold step of the slip rate (stiff machine, k_t D_c / (a N) = 1000): mu jumps by
    ~a ln(V2/V1) (the direct effect), then decays over a slip of a few D_c to
    mu_ss(V2) = mu_ss(V1) + (a - b) ln(V2/V1).  The rule (backward Euler, first order)
    matches a Radau solution of the same equations written independently, and its error
    halves with the step."""
    k_t, v1, v2, t_end = 100.0, 1e-3, 1e-2, 100.0
    errors = []
    for h in (2e-3, 1e-3):
        times, mu = law_run(law, k_t, h, v1, v2, t_end)
        reference = reference_run(law, k_t, v1, v2, times)
        errors.append(np.abs(mu - reference).max())
    assert errors[1] < 0.01 * A_ * math.log(v2 / v1)  # 1 % of the direct effect, in the elastic rise
    assert 1.7 < errors[0] / errors[1] < 2.3  # first order
    peak = mu.max() - steady_mu(v1)
    assert peak == pytest.approx(A_ * math.log(v2 / v1), rel=0.05)
    assert mu[-1] - steady_mu(v2) == pytest.approx(0.0, abs=1e-3 * A_)  # after a slip of 10 D_c
    assert steady_mu(v2) - steady_mu(v1) == pytest.approx((A_ - B_) * math.log(v2 / v1), rel=1e-9)
    slip_at_peak = v2 * times[np.argmax(mu)]
    assert slip_at_peak < DC  # the peak comes within the first D_c of slip, the decay after it
    after = np.argmax(mu)
    half_way = times[after + np.argmax(mu[after:] - steady_mu(v2) < 0.5 * (mu.max() - steady_mu(v2)))] * v2
    assert 0.1 * DC < half_way < 3.0 * DC


@pytest.mark.parametrize("integrator", ["symplectic_euler", "adaptive"])
@pytest.mark.parametrize("law", LAWS_RS)
@pytest.mark.parametrize("ratio, unstable", [(0.5, True), (0.8, True), (1.25, False), (2.0, False)])
def test_ruina_s_critical_stiffness_separates_stick_slip_from_steady_sliding(law, ratio, unstable, integrator):
    """Quasi-static driving (inertia's correction m V^2 / (a N D_c) = 1e-3): below
    k_c = (b - a) N / D_c the block stick-slips, above it the slip rate settles to V_d.
    The loading stiffness is the drive spring in series with the contact's, k_d k_t / (k_d + k_t)."""
    k_t, v_d = 0.28, 1e-3
    k_c = (B_ - A_) * 1.0 / DC
    k_d = 1.0 / (1.0 / (ratio * k_c) - 1.0 / k_t)
    block = Block("A", integrator, 0, False, dt=1e-2, friction_law=law, k_t=k_t, k_d=k_d, V_d=v_d,
                  gamma_t=0.0, A=0.0, rs_a=A_, rs_b=B_, rs_D_c=DC, rs_V_0=v_d, rs_mu_0=MU0, rs_theta_0=DC / v_d)
    block.start()
    block.advance_to(34000.0)
    late = []
    for t in np.arange(34002.0, 40000.0, 2.0):
        block.advance_to(t)
        late.append(block.output("vx") / v_d)
    if unstable:
        assert max(late) > 10.0 and min(late) < 0.1
    else:
        assert max(late) - min(late) < 1e-4


@pytest.mark.parametrize("law", LAWS_RS)
def test_event_driven_refuses_rate_and_state_saying_why_and_adaptive_keeps_its_own_steps(law):
    """event_driven's closed forms assume the spring with reset.  adaptive on model A hands
    its runs to those exact flows (option exact_flows), but not a run of this law: it takes
    error-controlled steps (accepted steps counted, where the exact flows count none)."""
    block = Block("A", "event_driven", 0, False, friction_law=law)
    with pytest.raises(ModelError, match="spring with reset"):
        block.start()
    block = Block("A", "adaptive", 0, False, dt=1e-2, friction_law=law, k_d=1e-2, V_d=1e-2, A=0.0)
    block.start()
    block.advance_to(10.0)
    assert block.settings.kernel().name == "adaptive" and block.output("accepted_steps") > 0


# ------------------------------------------- adaptive: the law in continuous time
def reference_block_run(law, p, times):
    """Model A on a still plate with rate-and-state friction, written out here from
    docs/physics.md Sec. 2 and Sec. 5 (state x, z, vx, vz, F, theta; the block stays in
    contact), solved by scipy's DOP853 at tight tolerance from rest at its static
    penetration."""
    def rates(t, y):
        x, z, vx, vz, shear, theta = y
        normal = p["k_n"] * (-z) - p["gamma_n"] * vz
        psi = p["rs_mu_0"] + p["rs_b"] * math.log(p["rs_V_0"] * theta / p["rs_D_c"])
        v = 2.0 * p["rs_V_0"] * math.exp(-psi / p["rs_a"]) * math.sinh(p["k_t"] * abs(shear) / (p["rs_a"] * normal))
        if law == "rate_state_aging":
            theta_rate = 1.0 - v * theta / p["rs_D_c"]
        else:
            theta_rate = -(v * theta / p["rs_D_c"]) * math.log(v * theta / p["rs_D_c"]) if v > 0.0 else 0.0
        ax = (-p["k_d"] * (x - p["V_d"] * t) - p["gamma_t"] * vx - p["k_t"] * shear) / p["m"]
        az = (normal - p["m"] * p["g"]) / p["m"]
        return [vx, vz, ax, az, vx - math.copysign(v, shear), theta_rate]
    z0 = -p["m"] * p["g"] / p["k_n"]
    solution = solve_ivp(rates, (0.0, times[-1]), [0.0, z0, 0.0, 0.0, 0.0, p["rs_theta_0"]], method="DOP853",
                         t_eval=times, rtol=1e-12, atol=1e-14)
    assert solution.success
    return solution.y


@pytest.mark.parametrize("law", LAWS_RS)
def test_adaptive_follows_an_independent_solution_through_stick_slip(law):
    """Below Ruina's k_c, driven at ten times V_0 from theta at steady state at V_0, the
    block creeps, then slips (at ~40 V_d, backwards after it); adaptive, which
    integrates F and theta with the motion under its error control, matches a DOP853
    solution of the equations written out independently through the first slip, to a
    few times its tolerance, and its error falls with the tolerance (the
    fixed-step rule is first order in dt, this is not)."""
    k_t = 0.28
    k_d = 1.0 / (1.0 / (0.5 * (B_ - A_) / DC) - 1.0 / k_t)
    v_d = 10.0 * V0
    p = dict(m=1.0, g=1.0, k_n=1.0, gamma_n=0.07, k_t=k_t, gamma_t=5e-3, k_d=k_d, V_d=v_d, rs_a=A_, rs_b=B_,
             rs_D_c=DC, rs_V_0=V0, rs_mu_0=MU0, rs_theta_0=DC / V0)
    times = np.linspace(10.0, 2400.0, 240)
    x_ref, z_ref, vx_ref, _, f_ref, theta_ref = reference_block_run(law, p, times)
    assert vx_ref.max() > 10.0 * v_d and vx_ref.min() < 0.0  # the window holds a slip
    errors = []
    for rtol in (1e-6, 1e-9):
        block = Block("A", "adaptive", 0, False, dt=1e-2, friction_law=law, A=0.0, rtol=rtol, atol=rtol * 1e-2,
                      **{k: v for k, v in p.items() if k not in ("m", "g", "k_n", "gamma_n")})
        block.start()
        error = 0.0
        for t, x, vx, shear, theta in zip(times, x_ref, vx_ref, f_ref, theta_ref):
            block.advance_to(t)
            out = block.outputs()
            error = max(error, abs(out["x"] - x) / (abs(x) + 1e-3), abs(out["vx"] - vx) / vx_ref.max(),
                        abs(-out["friction_force"] / k_t - shear) / abs(f_ref).max(),
                        abs(block.y[L.Y_FRICTION_STATE] - theta) / theta)
        errors.append(error)
    assert errors[0] < 2e-5 and errors[1] < 2e-8  # a few times rtol (errors relative to each variable's scale)
    assert errors[1] < 0.01 * errors[0]


@pytest.mark.parametrize("law", LAWS_RS)
@pytest.mark.parametrize("model", ["B", "C"])
def test_adaptive_on_a_vibrated_corrugated_plate_is_the_limit_of_the_fixed_step_rule(law, model):
    """On a vibrated corrugated plate (no closed form), rk4's first-order rule converges to
    adaptive's run: its error against adaptive at rtol 1e-10 halves with dt.  Model B
    starts in a trough of its corrugation (slope 0) and creeps up the flank."""
    d_c = 1.0  # the interface stays well posed: k_t >> (b - a) N_b / D_c
    settings = dict(dt=1e-2, friction_law=law, k_d=1e-2, V_d=1e-2, A=0.2, omega=0.5, rs_a=A_, rs_b=B_, rs_D_c=d_c,
                    rs_V_0=V0, rs_mu_0=MU0, rs_theta_0=d_c / V0, x_start=-25.0 * math.pi if model == "B" else 0.0)
    exact = Block(model, "adaptive", 0, False, rtol=1e-10, atol=1e-12, **settings)
    exact.start()
    exact.advance_to(200.0)
    errors = []
    for dt in (2e-2, 1e-2):
        block = Block(model, "rk4", 0, False, **dict(settings, dt=dt))
        block.start()
        block.advance_to(200.0)
        errors.append(abs(block.output("x") - exact.output("x")))
    assert 1.6 < errors[0] / errors[1] < 2.5
    assert errors[1] < 5e-3 * abs(exact.output("x") - settings["x_start"])


def test_adaptive_stops_cleanly_where_the_interface_s_slip_runs_away():
    """Model B started on a flank of slope 20 slides down and slams into the next one
    (N_b ~ 20): with D_c = 0.1, k_t = 0.28 < (b - a) N_b / D_c ~ 1, the massless
    interface's slip grows without bound in finite time (docs/physics.md Sec. 5).
    adaptive stops with the message naming the condition and keeps the state before the
    call; nothing is NaN."""
    block = Block("B", "adaptive", 0, False, dt=1e-2, friction_law="rate_state_aging", k_d=1e-2, V_d=1e-2, A=0.0,
                  rs_a=A_, rs_b=B_, rs_D_c=DC, rs_V_0=V0, rs_mu_0=MU0, rs_theta_0=DC / V0)
    block.start()
    block.advance_to(40.0)
    kept = block.y.copy()
    with pytest.raises(ModelError, match=r"runs away in finite time, k_t < \(b - a\) N_b / D_c"):
        block.advance_to(60.0)
    assert block.time == 40.0 and np.array_equal(block.y, kept) and np.all(np.isfinite(kept))


@pytest.mark.parametrize("name, value", [("rs_a", -0.01), ("rs_a", 0.0), ("rs_b", -0.1), ("rs_D_c", 0.0),
                                         ("rs_V_0", -1.0), ("rs_theta_0", 0.0), ("rs_mu_0", math.nan)])
def test_bad_law_parameters_are_refused(name, value):
    with pytest.raises(ModelError, match=name):
        Block("A", "symplectic_euler", 0, False, friction_law="rate_state_aging", **{name: value})


@pytest.mark.parametrize("law", LAWS_RS)
@pytest.mark.parametrize("integrator", ["symplectic_euler", "rk4", "implicit_contact", "adaptive"])
def test_the_energy_the_interface_s_slip_takes_is_booked_as_dissipated(law, integrator):
    """Stick-slip (k = k_c / 2) through the first slips: the interface's slip is the only
    dissipation (no dashpots), k_t (F_0^2 - F_1^2) / 2 per step; the balance closes to
    rounding with the schemes whose own energy error is that small, to first order with
    symplectic Euler."""
    k_t = 0.28
    k_d = 1.0 / (1.0 / (0.5 * (B_ - A_) / DC) - 1.0 / k_t)
    block = Block("A", integrator, 0, True, dt=1e-2, friction_law=law, k_t=k_t, k_d=k_d, V_d=V0, gamma_t=0.0,
                  gamma_n=0.07, A=0.0, rs_a=A_, rs_b=B_, rs_D_c=DC, rs_V_0=V0, rs_mu_0=MU0, rs_theta_0=DC / V0)
    block.start()
    block.advance_to(60000.0)
    out = block.outputs()
    assert out["energy_dissipated"] > 1.0
    tolerance = {"symplectic_euler": 1e-2, "adaptive": 1e-6}.get(integrator, 1e-10)  # adaptive: its rtol
    assert abs(out["energy_residual"]) < tolerance * out["energy_dissipated"]


@pytest.mark.parametrize("integrator", ["rk4", "adaptive"])
def test_theta_is_state_restored_with_the_run(integrator):
    block = Block("A", integrator, 0, False, dt=1e-2, friction_law="rate_state_slip", k_d=1e-2, V_d=1e-2, A=0.0,
                  rs_D_c=DC, rs_V_0=V0, rs_theta_0=DC / V0)
    block.start()
    block.advance_to(800.0)
    saved = block.get_state()
    block.advance_to(1500.0)
    first = block.outputs()
    block.set_state(saved)
    block.advance_to(1500.0)
    assert block.outputs() == first


@pytest.mark.parametrize("integrator", ["rk4", "adaptive"])
def test_mu_s_plays_no_part_under_rate_and_state(integrator):
    """The interface's coefficient is mu(V, theta): a run with mu_s = 0 (no Coulomb bound)
    is the run with the default mu_s, bit for bit, in both the fixed-step rule and
    adaptive's regimes (which turn on N_b's sign, not on mu_s N_b)."""
    runs = []
    for mu_s in (0.5, 0.0):
        block = Block("C", integrator, 0, False, dt=1e-2, friction_law="rate_state_aging", k_d=1e-2, V_d=1e-2,
                      A=0.2, omega=0.5, mu_s=mu_s, rs_D_c=1.0, rs_V_0=V0, rs_theta_0=1.0 / V0)
        block.start()
        block.advance_to(100.0)
        runs.append(block.y.copy())
    assert abs(runs[0][L.Y_F]) > 0.0 and runs[0].tobytes() == runs[1].tobytes()
