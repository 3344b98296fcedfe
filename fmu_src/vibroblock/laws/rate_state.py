"""Dieterich-Ruina rate-and-state friction at the contact's interface, shared by the
``rate_state_aging`` and ``rate_state_slip`` friction laws (they differ in how the
state theta evolves).

The contact keeps the Cundall-Strack spring k_t: it is the contact's tangential
compliance, in series with an interface that slips at the rate V where

    k_t |F| = mu(V, theta) N_b,
    mu(V, theta) = a asinh( V / (2 V_0) exp(Psi / a) ),   Psi = mu_0 + b ln(V_0 theta / D_c),

the regularized form of mu_0 + a ln(V/V_0) + b ln(V_0 theta/D_c) (Rice and Ben-Zion,
PNAS 93, 3811, 1996; Lapusta et al., JGR 105, 23765, 2000; QDYN uses it): the two agree
to a relative exp(-2 Psi / a) once V >> V_0 exp(-Psi / a), and the regularized one stays
finite at V = 0 and odd in V.  Inverted, the interface slips at

    V(F) = 2 V_0 exp(-Psi / a) sinh(k_t |F| / (a N_b))

so the friction force is the spring's, and the spring relaxes by the interface's slip:
dF/dt = u_t - sign(F) V(F).  The integrator grows F by u_t over the step; this rule
then takes the relaxation over the step h by backward Euler,

    F_1 = F_0 - h sign(F_1) V(F_1),

which has one root between 0 and F_0 (V grows with |F|) and is stable however stiff
the law is at small V (exp(Psi/a) ~ 1e26 at the defaults); it is solved in logarithms
(``relaxed``), where V cannot overflow.  Then theta evolves over h at the slip rate V(F_1), exactly for a rate
held over the step (the law module's ``evolve``).  First order in h overall.

An error-controlled integrator (``adaptive``) takes the same law in continuous time
instead (``interface_with``): F and ln theta are state components with
dF/dt = u_t - sign(F) V(F) and theta's law, so its tolerance, not a first-order rule,
sets the error.  It integrates ln theta, not theta: theta relaxes to D_c / V at the rate
V / D_c, thousands per tau_0 in a fast slip, and a stiff-stable step's stages may
overshoot a positive quantity below zero, where ln theta has no such edge (and its
error weight is theta's relative error, which is what mu sees).

In the limit k_t -> infinity the block itself slips at V: the classical
spring-slider.  With a finite k_t the loading stiffness Ruina's stability threshold
k_c = (b - a) N / D_c compares with is the drive spring in series with the contact's,
k_d k_t / (k_d + k_t).

Detached (delta <= 0) or without a normal force (N_b <= 0): F = 0, and theta is kept
(no contact to age or to slide).  No reset ever happens (``coulomb_resets`` stays 0);
the energy the interface's slip takes from the spring, k_t (F_0^2 - F_1^2) / 2, counts
as dissipated.
"""
import math

from numba import njit

from ..layout import P_KT, slot
from ..parameters import FINITE, NON_NEGATIVE, POSITIVE, Parameter

PARAMETERS = (
    Parameter("rs_a", 0.01, "1", "rate-and-state direct effect a (friction_law = 3, 4)", POSITIVE),
    Parameter("rs_b", 0.015, "1", "rate-and-state evolution effect b (friction_law = 3, 4)", NON_NEGATIVE),
    Parameter("rs_D_c", 1.0, "delta_0", "rate-and-state characteristic slip distance D_c (friction_law = 3, 4)",
              POSITIVE),
    Parameter("rs_V_0", 2e-5, "delta_0/tau_0", "rate-and-state reference slip rate V_0 (friction_law = 3, 4)",
              POSITIVE),
    Parameter("rs_mu_0", 0.5, "1", "rate-and-state friction coefficient mu_0 at steady sliding at V_0 "
              "(friction_law = 3, 4)", FINITE),
    Parameter("rs_theta_0", 5e4, "tau_0", "rate-and-state state theta at the start (friction_law = 3, 4; "
              "D_c / V_0 at the defaults: steady state at V_0)", POSITIVE),
)
P_A, P_B, P_DC, P_V0, P_MU0 = (slot(name) for name in ("rs_a", "rs_b", "rs_D_c", "rs_V_0", "rs_mu_0"))
# The interface slips at every stress: an error-controlled integrator carries F and theta.
INTERFACE_SLIPS = True
REFUSED_BY = {
    "event_driven": "its closed-form regimes assume the paper's spring with reset; use a fixed-step scheme",
}
# Newton's iterations before the rule stops improving (it converges in a few).
MAX_ITERATIONS = 60
LN2 = math.log(2.0)
# The slip rate theta evolves at is capped here (delta_0/tau_0): as N_b -> 0 the
# interface's rate overflows, and theta, which relaxes to D_c / V, must stay positive.
RATE_CAP = 1e100
LOG_RATE_CAP = math.log(RATE_CAP)


def initial_state(parameters: dict) -> float:
    return parameters["rs_theta_0"]


@njit(inline="always")
def state_term(theta, prm):
    """Psi = mu_0 + b ln(V_0 theta / D_c)."""
    return prm[P_MU0] + prm[P_B] * math.log(prm[P_V0] * theta / prm[P_DC])


@njit
def log_slip_rate(r, log_scale):
    """ln V and d(ln V)/dr at r = k_t |F| / (a N_b) > 0, V = 2 V_0 exp(-Psi/a) sinh(r),
    ``log_scale`` = ln V_0 - Psi/a; in logarithms (V overflows long before its logarithm
    does); below r = 1e-3 by the series ln sinh r = ln r + r^2/6, coth r = 1/r + r/3
    (exp(-2r) rounds to 1 near r = 0)."""
    if r < 1e-3:
        return log_scale + LN2 + math.log(r) + r * r / 6.0, 1.0 / r + r / 3.0
    tail = math.exp(-2.0 * r)
    return log_scale + r + math.log1p(-tail), (1.0 + tail) / (1.0 - tail)


@njit
def relaxed(shear, theta, normal, h, prm):
    """|F_1| solving |F_1| + h V(|F_1|) = |F_0| (backward Euler of the interface's slip),
    and V(|F_1|); ``shear`` = F_0.

    Solved in r = k_t |F| / (a N_b) as ln(h V(r)) = ln(r_0 - r) (scaled by a N_b / k_t),
    whose left side is near linear in r where V is large, by Newton's method kept inside
    the bracket (0, r_0) the two sides' monotony gives; where h V(r_0) is below rounding
    of |F_0| the spring keeps F_0."""
    target = abs(shear)
    scale = prm[P_KT] / (prm[P_A] * normal)  # r per unit of |F|
    r0 = scale * target
    if r0 == 0.0:
        return target, 0.0
    log_scale = math.log(prm[P_V0]) - state_term(theta, prm) / prm[P_A]  # ln V_0 - Psi/a: theta is held
    log_v0 = log_slip_rate(r0, log_scale)[0]
    if h <= 0.0:
        return target, math.exp(log_v0)
    log_h = math.log(h * scale)  # h V in units of r
    if log_h + log_v0 < math.log(2.2e-16 * r0):
        return target, math.exp(log_v0)
    low, high = 0.0, r0
    if log_h + log_v0 < math.log(0.5 * r0):  # first guess: one step of the small slip
        r = r0 - math.exp(log_h + log_v0)
    else:  # where ln V ~ ln V_0 - Psi/a + r meets ln(r_0 / h)
        r = math.log(r0) - log_h - log_scale
        if not 0.0 < r < r0:  # below r ~ 1 V is linear, 2 V_0 exp(-Psi/a) r
            r = r0 / (1.0 + math.exp(log_h + LN2 + log_scale))
        if not 0.0 < r < r0:
            r = 0.5 * r0
    for _ in range(MAX_ITERATIONS):
        gap = r0 - r
        if gap <= 0.0:  # below the rounding of r_0: the root is lower
            high = r
            r = 0.5 * (low + high)
            continue
        log_v, slope = log_slip_rate(r, log_scale)
        residual = log_h + log_v - math.log(gap)
        if residual > 0.0:
            high = r
        else:
            low = r
        step = residual / (slope + 1.0 / gap)
        if abs(step) <= 4e-16 * r:  # converged (a Newton step below rounding)
            r -= step
            break
        r_next = r - step
        if not low < r_next < high:
            r_next = 0.5 * (low + high)
        if high - low <= 4e-16 * high:
            break
        r = r_next
    return r / scale, math.exp(log_slip_rate(r, log_scale)[0])


@njit(inline="always")
def interface_slip(shear, theta, penetration, bound_normal, h, prm):
    """The relaxed F and the slip rate over the step (capped at ``RATE_CAP``), or (0, -1)
    without contact or normal force (theta then kept)."""
    if penetration <= 0.0 or bound_normal <= 0.0:
        return 0.0, -1.0
    magnitude, rate = relaxed(shear, theta, bound_normal, h, prm)
    return math.copysign(magnitude, shear), min(rate, RATE_CAP)


@njit(inline="always")
def relative_expm1(x):
    """-expm1(-x) / x, 1 at x = 0: the weight of a constant source over a decay."""
    return -math.expm1(-x) / x if x > 1e-300 else 1.0


def rule_with(evolve):
    """The friction rule (``laws``: friction) of a rate-and-state law whose theta evolves
    over a step by the compiled ``evolve(theta, V, h, prm)``: the interface's slip over
    the step, then theta's evolution at its rate.  The rule returns (F, theta, False):
    rate-and-state friction has no reset.

    Compiled once and called: inlined, its Newton solve went into every kernel that
    dispatches on the friction law, whichever law runs, and cost seconds of compile time
    in each; called, it costs a call per step where rate-and-state friction runs."""
    @njit
    def rule(shear, theta, penetration, bound_normal, slip_rate, h, prm):
        shear, rate = interface_slip(shear, theta, penetration, bound_normal, h, prm)
        if rate < 0.0:  # no contact: theta kept
            return shear, theta, False
        return shear, evolve(theta, rate, h, prm), False
    return rule


@njit(inline="always")
def integrated(theta):
    """The variable an error-controlled integrator carries for theta: ln theta."""
    return math.log(theta)


@njit(inline="always")
def stored(log_theta):
    """theta from the integrated variable."""
    return math.exp(log_theta)


@njit(inline="always")
def slip_rate(shear, theta, bound_normal, prm):
    """The interface's slip rate V(F) >= 0 at the spring's displacement F (capped at
    ``RATE_CAP``, as N_b -> 0 it overflows); 0 at F = 0.  Without a normal force the
    interface cannot hold any F: the cap."""
    if shear == 0.0:
        return 0.0
    if not bound_normal > 0.0:
        return RATE_CAP
    r = prm[P_KT] * abs(shear) / (prm[P_A] * bound_normal)
    log_scale = math.log(prm[P_V0]) - state_term(theta, prm) / prm[P_A]
    return math.exp(min(log_slip_rate(r, log_scale)[0], LOG_RATE_CAP))


def interface_with(log_state_rate):
    """The law in continuous time on ln theta, given d(ln theta)/dt =
    ``log_state_rate(ln theta, V, prm)``: (the interface's slip rate along F,
    d(ln theta)/dt).  Called, not inlined, as the rule is."""
    @njit
    def interface(shear, log_theta, bound_normal, prm):
        rate = slip_rate(shear, math.exp(log_theta), bound_normal, prm)
        return math.copysign(rate, shear), log_state_rate(log_theta, rate, prm)
    return interface
