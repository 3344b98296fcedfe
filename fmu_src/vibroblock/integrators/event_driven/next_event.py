"""Next event of ``event_driven``: the first zero of the active event signals.

The first zero is found without sampling: bounds on the signal exclude whole intervals
(the polynomial against the harmonic amplitude plus the modes' envelopes, which crosses
a stick phase of 5e7 time units in a few jumps; and a second-derivative bound that steps
safely towards a zero), so no zero is ever stepped over; the event is returned within
the tolerance (time) after the true zero, on the far side.  ``next_event`` asks the
searches the regime makes active (the module doc of ``event_driven``) and returns the
earliest.
"""
import math

import numpy as np
from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ...laws import friction_spring_force
from ...layout import P_GT, P_KD, P_KN, P_M, P_MUS, P_VD
from .regimes import CASCADE, ENGAGED, EV_DETACH, EV_N_RISES, EV_N_ZERO, EV_NONE, EV_RESET_MINUS, EV_RESET_PLUS, HELD
from .signals import (INF, R_BOUND, R_DELTA, R_N, R_NEG_N, R_SPRING, S_HIM, S_HRE, S_M1, S_M2, S_OMEGA, S_P0, S_P2,
                      SIG_LEN, mode_envelope, set_mode, set_signal, signal_state)

# Safe steps allowed per event search; beyond, the search reports failure (nan).
MAX_ROOT_STEPS = 1 << 24
# A cascade of resets is cut when its remaining friction impulse (per unit mass) is below
# this many times the time tolerance, in delta_0 / tau_0.
CASCADE_TOL_FACTOR = 1.0


@njit(cache=True)
def first_positive_root(a0, a1, a2):
    """Smallest w > 0 with a0 + a1 w + a2 w^2 = 0, for a0 > 0 (inf if none)."""
    if a2 == 0.0:
        return a0 / -a1 if a1 < 0.0 else INF
    disc = a1 * a1 - 4.0 * a2 * a0
    if disc < 0.0:
        return INF
    q = -0.5 * (a1 + math.copysign(math.sqrt(disc), a1))
    best = INF
    if q != 0.0:
        r1, r2 = q / a2, a0 / q
        if r1 > 0.0:
            best = r1
        if 0.0 < r2 < best:
            best = r2
    return best


@njit(cache=True)
def _step_from(g, g1, poly, poly1, p2, level, curvature):
    """Length of the interval after u over which bounds keep the signal positive: the
    polynomial stays above what the rest can reach (envelope exclusion), and
    g(u + w) >= g + g1 w - curvature w^2 / 2 (curvature exclusion)."""
    reach = 0.0
    if poly - level > 0.0:
        reach = first_positive_root(poly - level, poly1, p2)
    return max(reach, first_positive_root(g, g1, -0.5 * curvature))


@njit(inline="always")
def _next_probe(u, step, u_hi, tol):
    """Where a search goes from u after a safe step: at least the resolution (the
    tolerance, or 8 ulp of u) on, and at most to u_hi; inf where the safe step itself
    passes u_hi (no zero before it)."""
    resolution = max(tol, 8.0 * 2.220446049250313e-16 * abs(u))
    if step < resolution:
        return u_hi if u + resolution > u_hi else u + resolution
    return INF if u + step > u_hi else u + step


@njit(cache=True)
def first_zero(s, u_lo, u_hi, tol):
    """First u in [u_lo, u_hi] where the signal is <= 0, located within tol after the
    true zero; inf if there is none; nan if the search did not converge.

    A signal that starts at or below zero but rising is taken as having just crossed
    (the sliver below zero is rounding); one that starts there falling gives u_lo.
    """
    u = u_lo
    g, g1, g2, poly, poly1, level, curvature = signal_state(s, u)
    if g <= 0.0:
        if not (g1 > 0.0 or (g1 == 0.0 and g2 > 0.0)):
            return u_lo
        skip = max(-2.0 * g / g1, tol) if g1 > 0.0 else max(math.sqrt(-4.0 * g / g2), tol)
        u = u_lo + skip
        if u > u_hi:
            return INF
        g, g1, g2, poly, poly1, level, curvature = signal_state(s, u)
        if g <= 0.0:
            return u_lo
    for _ in range(MAX_ROOT_STEPS):
        u_new = _next_probe(u, _step_from(g, g1, poly, poly1, s[S_P2], level, curvature), u_hi, tol)
        if u_new == INF:
            return INF
        if u_new <= u:  # no representable progress left
            return u_new
        g, g1, g2, poly, poly1, level, curvature = signal_state(s, u_new)
        if g <= 0.0:
            return u_new
        if u_new >= u_hi:
            return INF
        u = u_new
    return math.nan




@njit(inline="always")
def _pair_state(a, b, u):
    """``signal_state`` of a and of b at u, and which of a - b (+1) and a + b (-1) is at or
    below zero there (0: neither)."""
    sa, sb = signal_state(a, u), signal_state(b, u)
    below = 1.0 if sa[0] - sb[0] <= 0.0 else (-1.0 if sa[0] + sb[0] <= 0.0 else 0.0)
    return sa, sb, below


@njit(cache=True)
def first_zero_pair(a, b, u_lo, u_hi, tol):
    """First zero of a - b or a + b on [u_lo, u_hi] (as first_zero), evaluating a and b
    once per step; returns (u, sign), sign +1 for a - b, -1 for a + b, 0 if none."""
    u = u_lo
    sa, sb, _ = _pair_state(a, b, u)
    for sign in (1.0, -1.0):
        g, g1, g2 = sa[0] - sign * sb[0], sa[1] - sign * sb[1], sa[2] - sign * sb[2]
        if g <= 0.0 and not (g1 > 0.0 or (g1 == 0.0 and g2 > 0.0)):
            return u_lo, sign
    skip = 0.0
    for sign in (1.0, -1.0):
        g, g1, g2 = sa[0] - sign * sb[0], sa[1] - sign * sb[1], sa[2] - sign * sb[2]
        if g <= 0.0:  # rising from a rounding sliver below zero
            skip = max(skip, max(-2.0 * g / g1, tol) if g1 > 0.0 else max(math.sqrt(-4.0 * g / g2), tol))
    if skip > 0.0:
        u = u_lo + skip
        if u > u_hi:
            return INF, 0.0
        sa, sb, below = _pair_state(a, b, u)
        if below != 0.0:
            return u_lo, below
    for _ in range(MAX_ROOT_STEPS):
        # (g, g', g'', polynomial, its slope, level, curvature bound) of each signal
        level, curvature = sa[5] + sb[5], sa[6] + sb[6]
        step = min(_step_from(sa[0] - sb[0], sa[1] - sb[1], sa[3] - sb[3], sa[4] - sb[4], a[S_P2] - b[S_P2], level,
                              curvature),
                   _step_from(sa[0] + sb[0], sa[1] + sb[1], sa[3] + sb[3], sa[4] + sb[4], a[S_P2] + b[S_P2], level,
                              curvature))
        u_new = _next_probe(u, step, u_hi, tol)
        if u_new == INF:
            return INF, 0.0
        if u_new <= u:
            return u_new, 1.0 if sa[0] - sb[0] <= sa[0] + sb[0] else -1.0
        sa, sb, below = _pair_state(a, b, u_new)
        if below != 0.0:
            return u_new, below
        if u_new >= u_hi:
            return INF, 0.0
        u = u_new
    return math.nan, 0.0


# ---------------------------------------------------------------------------- the events
@njit(inline="always")
def _cascade_end(kind, prm, sig, u_ev, u_rem, tol, drive):
    """After a reset while N falls: the zero of N if the rest of the cascade can no longer
    give a friction impulse above the tolerance (the cascade is then cut there), else inf;
    nan if the search failed.  ``drive`` is (stretch, vx, shear) at the segment start."""
    stretch, vx, _ = drive
    normal_sig = sig[R_N]
    if not signal_state(normal_sig, 0.0)[1] < 0.0:
        return INF
    u_zero = first_zero(normal_sig, 0.0, min(u_ev, u_rem), tol)
    if math.isnan(u_zero) or not u_zero < u_ev:
        return u_zero if math.isnan(u_zero) else INF
    m, k_d, gam_t = prm[P_M], prm[P_KD], prm[P_GT]
    accel = (k_d * (abs(stretch) + (abs(prm[P_VD]) + abs(vx)) * u_zero) + gam_t * abs(vx)) / m
    v_max = abs(vx) + accel * u_zero
    # the spring force the cascade's remaining travel could still build, as an impulse
    if friction_spring_force(kind, v_max, prm) * u_zero * u_zero / (2.0 * m) <= CASCADE_TOL_FACTOR * tol:
        return u_zero
    return INF


@njit(inline="always")
def _coulomb_reset(kind, prm, sig, u_hi, tol, shear, flow, y_const):
    """First time mu_s N - k_t F or mu_s N + k_t F reaches zero before u_hi (inf if none, nan
    if the search failed), and the event it is.  The bound is the contact force's
    (``laws.bound_contact_force``), the spring the friction law's force of F's flow."""
    _, a_lin, b_lin, lam_t, kap_t, xi0, xi1, _ = flow
    normal_sig, bound, spring = sig[R_N], sig[R_BOUND], sig[R_SPRING]
    mu_s, om = prm[P_MUS], normal_sig[S_OMEGA]
    # mu_s N, part by part (its constant as mu_s k_n y_const, as the contact flow has it)
    set_signal(bound, -mu_s * prm[P_KN] * y_const, 0.0, 0.0, mu_s * complex(normal_sig[S_HRE], normal_sig[S_HIM]), om)
    set_mode(bound, S_M1, mu_s * normal_sig[S_M1], mu_s * normal_sig[S_M1 + 1], normal_sig[S_M1 + 2],
             normal_sig[S_M1 + 3])
    set_signal(spring, friction_spring_force(kind, shear + a_lin, prm), friction_spring_force(kind, b_lin, prm), 0.0,
               0j, om)
    set_mode(spring, S_M1, friction_spring_force(kind, xi0, prm), friction_spring_force(kind, xi1, prm), lam_t, kap_t)
    u_lo = 0.0
    # No reset can come before mu_s N falls to the largest k_t |F| of the interval: when
    # that is small (bouncing), find that point on the cheaper bound alone first.
    spring_max = friction_spring_force(kind, abs(shear) + abs(a_lin) + abs(b_lin) * u_hi
                                       + mode_envelope(xi0, xi1, lam_t, kap_t), prm)
    if spring_max < 0.5 * bound[S_P0]:
        bound[S_P0] -= spring_max
        u_lo = first_zero(bound, 0.0, u_hi, tol)
        bound[S_P0] += spring_max
        if math.isnan(u_lo):
            return u_lo, EV_NONE
    if not u_lo < INF:
        return INF, EV_NONE
    r, sign = first_zero_pair(bound, spring, u_lo, u_hi, tol)
    return r, EV_RESET_PLUS if sign > 0.0 else EV_RESET_MINUS


@njit(inline="always")
def _n_rises(sig, u_hi, tol):
    """First time N rises to zero (the spring held at 0 re-arms), inf if not before u_hi."""
    normal_sig, neg_n = sig[R_N], sig[R_NEG_N]
    for i in range(SIG_LEN):
        neg_n[i] = -normal_sig[i]
    for slot in (S_M1, S_M2):  # a mode's lam and k/m are not negated
        neg_n[slot + 2], neg_n[slot + 3] = normal_sig[slot + 2], normal_sig[slot + 3]
    neg_n[S_OMEGA] = normal_sig[S_OMEGA]
    return first_zero(neg_n, 0.0, u_hi, tol)


@njit(inline="always")
def next_event(kind, prm, sig, regime, just_reset, u_detach, u_rem, tol, drive, flow, y_const):
    """The first event in contact within u_rem: (u, event, regime), u = nan if a search
    failed.  ``u_detach`` is the time to the detachment (inf: not in the window); it bounds
    the other searches and wins ties (it resets F anyway).  After a reset while N falls,
    the cascade may be cut (the regime returned is then CASCADE)."""
    u_ev, event = INF, EV_NONE
    if u_detach < INF:
        u_ev, event = max(u_detach, 0.0), EV_DETACH
    if regime == ENGAGED and just_reset:
        u_zero = _cascade_end(kind, prm, sig, u_ev, u_rem, tol, drive)
        if math.isnan(u_zero):
            return u_zero, EV_NONE, regime
        if u_zero < INF:
            regime = CASCADE
            u_ev, event = u_zero, EV_N_ZERO
    if regime == ENGAGED:
        r, found = _coulomb_reset(kind, prm, sig, min(u_ev, u_rem), tol, drive[2], flow, y_const)
    elif regime == HELD:
        r, found = _n_rises(sig, min(u_ev, u_rem), tol), EV_N_RISES
    elif regime == CASCADE and event == EV_NONE:
        r, found = first_zero(sig[R_N], 0.0, min(u_ev, u_rem), tol), EV_N_ZERO
    else:
        r, found = INF, EV_NONE
    if math.isnan(r):
        return r, EV_NONE, regime
    if r < u_ev:
        u_ev, event = r, found
    return u_ev, event, regime


@njit(inline="always")
def detachment(sig, n_ref, off, dt, u_rem, tol):
    """The detachment's absolute time (grid index, offset; offset inf: not before the
    window's end), or offset nan if the search failed.  The vertical motion ignores the
    horizontal regime, so it is found once per contact."""
    r = first_zero(sig[R_DELTA], 0.0, u_rem, tol)
    detach_n, detach_off = n_ref, off + r
    if detach_off < INF:
        whole = math.floor(detach_off / dt)
        detach_n += np.int64(whole)
        detach_off -= whole * dt
    return detach_n, detach_off
