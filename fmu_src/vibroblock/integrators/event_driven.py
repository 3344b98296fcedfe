"""``event_driven`` (id 2, model A only): exact integration between located events.

Between events model A is linear with sinusoidal and polynomial forcing, and its
vertical and horizontal motions decouple:

* vertical, in contact: y = z - Z_p obeys m y'' + gamma_n y' + k_n y = -m (g + a_ext)
  + m A omega^2 sin(theta); in flight z is ballistic;
* horizontal: m xi'' + gamma_t xi' + k xi = f0 + f1 u (xi = x - x_s, u = t - t_s), with
  k = k_d + k_t while the friction spring is loaded (F = F_s + xi) and k = k_d otherwise.

Each piece is integrated in closed form: the homogeneous part through the exact 2x2
propagator e^(lam u) [C(u) I + S(u) (M - lam I)] (cos/sin, cosh/sinh or 1/u depending on
the sign of lam^2 - k/m, written so that no case divides by a vanishing number), plus
the particular solutions (constant, linear, harmonic).  Every quantity an event
depends on is then a *signal* of one form:

    g(u) = p0 + p1 u + p2 u^2 + Re(H e^(i omega u)) + mode_1(u) + mode_2(u)

(a mode is a homogeneous solution of one of the two oscillators).  Events are the first
zeros of such signals:

==============  =============================  ==================================
event           signal                         active
==============  =============================  ==================================
contact         z - Z_p                        in flight
detachment      delta = Z_p - z                in contact
Coulomb reset   mu_s N -/+ k_t F               in contact, spring loaded
spring re-arms  N (from below)                 in contact, N <= 0 (F held at 0)
==============  =============================  ==================================

The first zero is found without sampling: bounds on the signal exclude whole
intervals (the polynomial against the harmonic amplitude plus the modes' envelopes,
which crosses a stick phase of 5e7 time units in a few jumps; and a second-derivative
bound that steps safely towards a zero), so no zero is ever stepped over; the event
is returned within EVENT_TOL (time) after the true zero, on the far side.

The integrals the contract needs -- phi = int (vx - V_d)^2 dt, the work of the drive,
the plate and gravity, the dashpots' dissipation -- are integrals of products of two
signals, done in closed form with complex exponentials (int_0^u v^k e^(s v) dv), or,
where a mode's exponential split is ill-conditioned (near critical damping or a very
short segment), by Gauss-Legendre quadrature on the robust propagator.

A cascade of Coulomb resets accumulating at a zero of N (the dashpot pulls the block
out: each reset re-arms a spring that the falling bound releases again sooner) is cut
when the friction impulse the rest of the cascade could still give is below
CASCADE_TOL_FACTOR * EVENT_TOL (velocity); the spring is then held at zero until N
rises again.  Every resolved reset of a loaded spring counts in cnt[C_SLIPS].

The step dt plays no role in accuracy: it only sets the grid on which the state is
stored (the contract's t_n = t0 + n dt); any n, even 1e12, costs the same few events.

Whole periods are skipped where the motion has become periodic: with a harmonic drive
only (no external input), the state at a touchdown (plate phase, vertical velocity
relative to the plate, drive-spring stretch x - V_d t, vx; F = 0 there) determines the
future.  When it repeats within PERIODIC_TOL over two consecutive periods of q drive
cycles (bouncing locked to the plate), the remaining whole periods are added at once:
t += N 2 pi q / omega, x += N V_d T, and phi, work, dissipation and slips grow by N times
their increase over one period.  A stick phase needs no skipping: the closed form
crosses it in one segment whatever its length.

Costs (contract rule 6): every located event counts in cnt[C_EVENTS], every skipped plate
period in cnt[C_JUMPED] (the counters ``adaptive`` keeps too, which hands model A over to
this scheme).
"""
import cmath
import math

import numpy as np
from .. import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from .fixed_step import record_observation
from .plate import grid_phase, phase_after
from ..layout import (C_EVENTS, C_JUMPED, C_PHASE_STEP, C_SLIPS, C_STEP, D_AMP, D_DT, D_EXT_A, D_EXT_T, D_EXT_V,
                      D_EXT_Z, D_OMEGA, D_T0, P_G, P_GN, P_GT, P_KD, P_KN, P_KT, P_M, P_MUS, P_VD, Y_DISSIPATED,
                      Y_E_NORMAL, Y_F, Y_PHI, Y_PHI_C, Y_VX, Y_VZ, Y_WORK, Y_X, Y_Z, N_OBS)

# Events are located to this time (tau_0) past their true zero, or to 8 ulp of the time
# since the segment began, whichever is larger.
EVENT_TOL = 1e-12
# A cascade of resets is cut when its remaining friction impulse (per unit mass) is below
# this many times the time tolerance, in delta_0 / tau_0.
CASCADE_TOL_FACTOR = 1.0
# A mode's exponential split is used for integrals only where the two exponents differ by
# at least this much over the part of the segment where the mode has not decayed.
CONDITIONING = 0.25
# e-foldings after which a decaying mode is negligible (e^-40 ~ 4e-18).
DECAY_WINDOW = 40.0
# Safe steps allowed per event search; beyond, the search reports failure (-1).
MAX_ROOT_STEPS = 1 << 24
# Zero-length segments allowed in a row before the scheme forces progress (grazing).
MAX_IMMEDIATE = 16
# Periodic orbits: touchdowns remembered, and the relative agreement of the state at
# touchdown (plate phase, relative vertical velocity, drive-spring stretch, vx) over two
# consecutive periods that counts as periodic.
TOUCHDOWNS = 16
PERIODIC_TOL = 1e-10
# Touchdown record layout.
T_PHASE, T_YDOT, T_STRETCH, T_VX, T_TIME, T_PHI, T_WORK, T_DISS, T_ENORM, T_SLIPS = range(10)

# Signal layout: polynomial, harmonic, two modes (initial value, rate, lam, k/m).
S_P0, S_P1, S_P2, S_HRE, S_HIM, S_OMEGA = 0, 1, 2, 3, 4, 5
S_M1, S_M2 = 6, 10
SIG_LEN = 14
# Rows of the signal workspace.
R_DELTA, R_N, R_YDOT, R_VP, R_CONTACT, R_BOUND, R_SPRING, R_NEG_N, R_SCRATCH = range(9)
N_ROWS = 9

# Horizontal regimes: flight, spring loaded, spring held at 0 while N <= 0, and the tail of
# a reset cascade (spring held at 0 while N > 0 falls to its zero).
FREE, ENGAGED, HELD, CASCADE = 0, 1, 2, 3
# Events.
EV_NONE, EV_CONTACT, EV_DETACH, EV_RESET_PLUS, EV_RESET_MINUS, EV_N_RISES, EV_N_ZERO = range(7)

INF = math.inf
E_CONST = math.e

# 8-point Gauss-Legendre rule on [-1, 1].
GL_X = np.array([-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                 0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363])
GL_W = np.array([0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                 0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763])
# Gauss-Legendre panels allowed per integral (reached only near critical damping).
MAX_PANELS = 1 << 20


# ---------------------------------------------------------------------------- modes
@njit(cache=True)
def mode_cs(lam, kap, u):
    """(e^(lam u) C(u), e^(lam u) S(u)) of the propagator of f'' - 2 lam f' + kap f = 0,
    with C = cosh(mu u), S = sinh(mu u)/mu, mu^2 = lam^2 - kap (cos/sin if negative)."""
    d = lam * lam - kap
    if d < 0.0:
        w = math.sqrt(-d)
        e = math.exp(lam * u)
        return e * math.cos(w * u), e * math.sin(w * u) / w
    if d > 0.0:
        mu = math.sqrt(d)
        xm = mu * u
        if xm < 0.5:
            e = math.exp(lam * u)
            return e * math.cosh(xm), e * math.sinh(xm) / mu
        # lam + mu = kap / (lam - mu) without cancellation (slow mode of an overdamped pair)
        slow = kap / (lam - mu)
        ep = math.exp(slow * u)
        em = math.exp((lam - mu) * u)
        return 0.5 * (ep + em), ep * (-math.expm1(-2.0 * xm)) / (2.0 * mu)
    e = math.exp(lam * u)
    return e, e * u


@njit(cache=True)
def mode_value(f0, f1, lam, kap, u):
    """Value and rate at u of the mode with value f0 and rate f1 at 0."""
    ec, es = mode_cs(lam, kap, u)
    f2 = 2.0 * lam * f1 - kap * f0
    return ec * f0 + es * (f1 - lam * f0), ec * f1 + es * (f2 - lam * f1)


@njit(cache=True)
def mode_envelope(v0, v1, lam, kap):
    """Upper bound of |f(w)| over w >= 0 for the mode with value v0 and rate v1 at w = 0."""
    if v0 == 0.0 and v1 == 0.0:
        return 0.0
    d = lam * lam - kap
    q = abs(v1 - lam * v0)
    if d < 0.0:
        w = math.sqrt(-d)
        bound = math.sqrt(v0 * v0 + (q / w) ** 2)
        if lam < 0.0:
            bound = min(bound, abs(v0) + q / (E_CONST * -lam))
        return bound
    if d > 0.0:
        mu = math.sqrt(d)
        slow_rate = kap / (mu - lam) if mu - lam > 0.0 else 0.0
        reach = 1.0 / (2.0 * mu)
        if slow_rate > 0.0:
            reach = min(reach, 1.0 / (E_CONST * slow_rate))
        return abs(v0) + q * reach
    if lam < 0.0:
        return abs(v0) + q / (E_CONST * -lam)
    return abs(v0) if q == 0.0 else INF


# ---------------------------------------------------------------------------- signals
@njit(cache=True)
def set_signal(s, p0, p1, p2, h, omega):
    s[S_P0], s[S_P1], s[S_P2] = p0, p1, p2
    s[S_HRE], s[S_HIM], s[S_OMEGA] = h.real, h.imag, omega
    s[S_M1:SIG_LEN] = 0.0


@njit(cache=True)
def set_mode(s, slot, f0, f1, lam, kap):
    s[slot], s[slot + 1], s[slot + 2], s[slot + 3] = f0, f1, lam, kap


@njit(cache=True)
def signal_value(s, u):
    val = s[S_P0] + u * (s[S_P1] + u * s[S_P2])
    if s[S_HRE] != 0.0 or s[S_HIM] != 0.0:
        ph = s[S_OMEGA] * u
        val += s[S_HRE] * math.cos(ph) - s[S_HIM] * math.sin(ph)
    for slot in (S_M1, S_M2):
        if s[slot] != 0.0 or s[slot + 1] != 0.0:
            val += mode_value(s[slot], s[slot + 1], s[slot + 2], s[slot + 3], u)[0]
    return val


@njit(cache=True)
def signal_state(s, u):
    """Value, first and second derivative at u; the polynomial part and its slope; the
    level the non-polynomial parts can reach from u on (harmonic amplitude + mode
    envelopes); and a bound of |g''| from u on."""
    poly = s[S_P0] + u * (s[S_P1] + u * s[S_P2])
    poly1 = s[S_P1] + 2.0 * u * s[S_P2]
    g, g1, g2 = poly, poly1, 2.0 * s[S_P2]
    level = 0.0
    curvature = 2.0 * abs(s[S_P2])
    if s[S_HRE] != 0.0 or s[S_HIM] != 0.0:
        om = s[S_OMEGA]
        c, sn = math.cos(om * u), math.sin(om * u)
        re = s[S_HRE] * c - s[S_HIM] * sn
        im = s[S_HRE] * sn + s[S_HIM] * c
        g += re
        g1 -= om * im
        g2 -= om * om * re
        amp = math.hypot(s[S_HRE], s[S_HIM])
        level += amp
        curvature += amp * om * om
    for slot in (S_M1, S_M2):
        f0, f1 = s[slot], s[slot + 1]
        if f0 == 0.0 and f1 == 0.0:
            continue
        lam, kap = s[slot + 2], s[slot + 3]
        m0, m1 = mode_value(f0, f1, lam, kap, u)
        m2 = 2.0 * lam * m1 - kap * m0
        m3 = 2.0 * lam * m2 - kap * m1
        g += m0
        g1 += m1
        g2 += m2
        level += mode_envelope(m0, m1, lam, kap)
        curvature += mode_envelope(m2, m3, lam, kap)
    return g, g1, g2, poly, poly1, level, curvature


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
        # Envelope exclusion: the polynomial stays above what the rest can reach.
        reach = 0.0
        if poly - level > 0.0:
            reach = first_positive_root(poly - level, poly1, s[S_P2])
        # Curvature exclusion: g(u + w) >= g + g1 w - curvature w^2 / 2.
        local = first_positive_root(g, g1, -0.5 * curvature)
        step = max(reach, local)
        resolution = max(tol, 8.0 * 2.220446049250313e-16 * abs(u))
        probing = step < resolution
        if probing:
            step = resolution
        if u + step > u_hi:
            if not probing:
                return INF
            u_new = u_hi
        else:
            u_new = u + step
        if u_new <= u:  # no representable progress left
            return u_new
        g, g1, g2, poly, poly1, level, curvature = signal_state(s, u_new)
        if g <= 0.0:
            return u_new
        if u_new >= u_hi:
            return INF
        u = u_new
    return math.nan


@njit(cache=True)
def _step_from(g, g1, poly, poly1, p2, level, curvature):
    """Length of the interval after u over which bounds keep the signal positive."""
    reach = 0.0
    if poly - level > 0.0:
        reach = first_positive_root(poly - level, poly1, p2)
    return max(reach, first_positive_root(g, g1, -0.5 * curvature))


@njit(cache=True)
def first_zero_pair(a, b, u_lo, u_hi, tol):
    """First zero of a - b or a + b on [u_lo, u_hi] (as first_zero), evaluating a and b
    once per step; returns (u, sign), sign +1 for a - b, -1 for a + b, 0 if none."""
    u = u_lo
    ga, ga1, ga2, pa, pa1, la, ca = signal_state(a, u)
    gb, gb1, gb2, pb, pb1, lb, cb = signal_state(b, u)
    for sign in (1.0, -1.0):
        g, g1, g2 = ga - sign * gb, ga1 - sign * gb1, ga2 - sign * gb2
        if g <= 0.0 and not (g1 > 0.0 or (g1 == 0.0 and g2 > 0.0)):
            return u_lo, sign
    skip = 0.0
    for sign in (1.0, -1.0):
        g, g1, g2 = ga - sign * gb, ga1 - sign * gb1, ga2 - sign * gb2
        if g <= 0.0:  # rising from a rounding sliver below zero
            skip = max(skip, max(-2.0 * g / g1, tol) if g1 > 0.0 else max(math.sqrt(-4.0 * g / g2), tol))
    if skip > 0.0:
        u = u_lo + skip
        if u > u_hi:
            return INF, 0.0
        ga, ga1, ga2, pa, pa1, la, ca = signal_state(a, u)
        gb, gb1, gb2, pb, pb1, lb, cb = signal_state(b, u)
        if ga - gb <= 0.0:
            return u_lo, 1.0
        if ga + gb <= 0.0:
            return u_lo, -1.0
    level, curvature = la + lb, ca + cb
    for _ in range(MAX_ROOT_STEPS):
        step = min(_step_from(ga - gb, ga1 - gb1, pa - pb, pa1 - pb1, a[S_P2] - b[S_P2], level, curvature),
                   _step_from(ga + gb, ga1 + gb1, pa + pb, pa1 + pb1, a[S_P2] + b[S_P2], level, curvature))
        resolution = max(tol, 8.0 * 2.220446049250313e-16 * abs(u))
        probing = step < resolution
        if probing:
            step = resolution
        if u + step > u_hi:
            if not probing:
                return INF, 0.0
            u_new = u_hi
        else:
            u_new = u + step
        if u_new <= u:
            return u_new, 1.0 if ga - gb <= ga + gb else -1.0
        ga, ga1, ga2, pa, pa1, la, ca = signal_state(a, u_new)
        gb, gb1, gb2, pb, pb1, lb, cb = signal_state(b, u_new)
        if ga - gb <= 0.0:
            return u_new, 1.0
        if ga + gb <= 0.0:
            return u_new, -1.0
        if u_new >= u_hi:
            return INF, 0.0
        level, curvature = la + lb, ca + cb
        u = u_new
    return math.nan, 0.0


# ---------------------------------------------------------------------------- integrals
@njit(cache=True)
def cexpm1(z):
    a, b = z.real, z.imag
    sb = math.sin(0.5 * b)
    return complex(math.expm1(a) * math.cos(b) - 2.0 * sb * sb, math.exp(a) * math.sin(b))


@njit(cache=True)
def j_moment(k, z):
    """int_0^1 v^k e^(z v) dv for k = 0, 1, 2 (complex z, Re z <= 0 in use)."""
    if abs(z) < 0.5:
        term = complex(1.0, 0.0)
        total = term / (k + 1)
        for j in range(1, 19):
            term = term * z / j
            total += term / (k + j + 1)
            if abs(term.real) + abs(term.imag) < 1e-17:  # |total| > 0.2: below rounding
                break
        return total
    j0 = cexpm1(z) / z
    if k == 0:
        return j0
    ez = cmath.exp(z)
    j1 = (ez - j0) / z
    if k == 1:
        return j1
    return (ez - 2.0 * j1) / z


@njit(cache=True)
def exp_moment(k, s, u):
    """int_0^u v^k e^(s v) dv."""
    return u ** (k + 1) * j_moment(k, s * u)


@njit(cache=True)
def mode_split(f0, f1, lam, kap):
    """The mode as c1 e^(s1 u) + c2 e^(s2 u) (requires lam^2 != kap)."""
    d = lam * lam - kap
    q = f1 - lam * f0
    if d < 0.0:
        w = math.sqrt(-d)
        a = complex(0.5 * f0, -0.5 * q / w)
        return a, complex(lam, w), a.conjugate(), complex(lam, -w)
    mu = math.sqrt(d)
    slow = kap / (lam - mu)
    return (complex(0.5 * (f0 + q / mu), 0.0), complex(slow, 0.0),
            complex(0.5 * (f0 - q / mu), 0.0), complex(lam - mu, 0.0))


@njit(cache=True)
def mode_scales(lam, kap, u):
    """|mu|, the part of [0, u] where the mode has not decayed, and its fastest rate."""
    d = lam * lam - kap
    mu = math.sqrt(abs(d))
    if d > 0.0:
        decay = kap / (mu - lam) if mu - lam > 0.0 else 0.0
    else:
        decay = -lam
    window = u if decay <= 0.0 else min(u, DECAY_WINDOW / decay)
    return mu, window, abs(lam) + mu


@njit(cache=True)
def _part_value(s, part, v):
    """Value at v of one part of a signal: 0 polynomial, 1 harmonic, 2/3 mode 1/2."""
    if part == 0:
        return s[S_P0] + v * (s[S_P1] + v * s[S_P2])
    if part == 1:
        ph = s[S_OMEGA] * v
        return s[S_HRE] * math.cos(ph) - s[S_HIM] * math.sin(ph)
    slot = S_M1 if part == 2 else S_M2
    return mode_value(s[slot], s[slot + 1], s[slot + 2], s[slot + 3], v)[0]


@njit(cache=True)
def _quadrature(a, slot, b, part, window, rate):
    """Gauss-Legendre integral over [0, window] of mode `slot` of a times part of b."""
    if window <= 0.0:
        return 0.0
    panels = int(min(max(1.0, math.ceil(rate * window)), MAX_PANELS))
    h = window / panels
    total = 0.0
    for p in range(panels):
        mid = (p + 0.5) * h
        for j in range(8):
            v = mid + 0.5 * h * GL_X[j]
            m = mode_value(a[slot], a[slot + 1], a[slot + 2], a[slot + 3], v)[0]
            total += GL_W[j] * m * _part_value(b, part, v)
    return 0.5 * h * total


@njit(cache=True)
def _mode_product(a, slot, b, u, with_modes):
    """int_0^u (mode `slot` of a) * (b's polynomial, harmonic and, if asked, modes)."""
    f0, f1, lam, kap = a[slot], a[slot + 1], a[slot + 2], a[slot + 3]
    if f0 == 0.0 and f1 == 0.0:
        return 0.0
    mu, window, rate = mode_scales(lam, kap, u)
    split_ok = mu * window >= CONDITIONING
    total = 0.0
    has_poly = b[S_P0] != 0.0 or b[S_P1] != 0.0 or b[S_P2] != 0.0
    has_harm = b[S_HRE] != 0.0 or b[S_HIM] != 0.0
    om = b[S_OMEGA]
    if split_ok:
        c1, s1, c2, s2 = mode_split(f0, f1, lam, kap)
        acc = complex(0.0, 0.0)
        for c, r in ((c1, s1), (c2, s2)):
            if has_poly:
                for k in range(3):
                    if b[S_P0 + k] != 0.0:
                        acc += c * b[S_P0 + k] * exp_moment(k, r, u)
            if has_harm:
                hb = complex(b[S_HRE], b[S_HIM])
                acc += 0.5 * c * (hb * exp_moment(0, r + complex(0.0, om), u)
                                  + hb.conjugate() * exp_moment(0, r - complex(0.0, om), u))
        total += acc.real
    else:
        if has_poly:
            total += _quadrature(a, slot, b, 0, window, rate)
        if has_harm:
            total += _quadrature(a, slot, b, 1, window, rate + om)
    if with_modes:
        for other in (S_M1, S_M2):
            g0, g1 = b[other], b[other + 1]
            if g0 == 0.0 and g1 == 0.0:
                continue
            lam2, kap2 = b[other + 2], b[other + 3]
            mu2, window2, rate2 = mode_scales(lam2, kap2, u)
            if split_ok and mu2 * window2 >= CONDITIONING:
                c1, s1, c2, s2 = mode_split(f0, f1, lam, kap)
                d1, r1, d2, r2 = mode_split(g0, g1, lam2, kap2)
                acc = (c1 * (d1 * exp_moment(0, s1 + r1, u) + d2 * exp_moment(0, s1 + r2, u))
                       + c2 * (d1 * exp_moment(0, s2 + r1, u) + d2 * exp_moment(0, s2 + r2, u)))
                total += acc.real
            else:
                total += _quadrature(a, slot, b, 2 if other == S_M1 else 3, min(window, window2), rate + rate2)
    return total


@njit(cache=True)
def mode_square_integral(f0, f1, lam, kap, u, scratch):
    """int_0^u f(v)^2 dv for the mode with value f0 and rate f1 at 0."""
    if f0 == 0.0 and f1 == 0.0:
        return 0.0
    mu, window, rate = mode_scales(lam, kap, u)
    if mu * window >= CONDITIONING:
        c1, s1, c2, s2 = mode_split(f0, f1, lam, kap)
        if lam * lam - kap < 0.0:  # conjugate pair: 2 Re(c1^2 E(2 s1)) + 2 |c1|^2 E(2 lam)
            return (2.0 * (c1 * c1 * exp_moment(0, 2.0 * s1, u)).real
                    + 2.0 * abs(c1) ** 2 * exp_moment(0, 2.0 * s1.real, u).real)
        return (c1 * c1 * exp_moment(0, 2.0 * s1, u) + 2.0 * c1 * c2 * exp_moment(0, s1 + s2, u)
                + c2 * c2 * exp_moment(0, 2.0 * s2, u)).real
    scratch[:] = 0.0
    set_mode(scratch, S_M1, f0, f1, lam, kap)
    return _quadrature(scratch, S_M1, scratch, 2, window, 2.0 * rate)


@njit(cache=True)
def product_integral(a, b, u):
    """int_0^u a(v) b(v) dv for two signals sharing the harmonic's frequency."""
    pa = (a[S_P0], a[S_P1], a[S_P2])
    pb = (b[S_P0], b[S_P1], b[S_P2])
    total = 0.0
    for i in range(3):
        if pa[i] == 0.0:
            continue
        for j in range(3):
            if pb[j] != 0.0:
                total += pa[i] * pb[j] * u ** (i + j + 1) / (i + j + 1)
    om = a[S_OMEGA] if (a[S_HRE] != 0.0 or a[S_HIM] != 0.0) else b[S_OMEGA]
    wz = complex(0.0, om)
    ha = complex(a[S_HRE], a[S_HIM])
    hb = complex(b[S_HRE], b[S_HIM])
    a_harm = ha.real != 0.0 or ha.imag != 0.0
    b_harm = hb.real != 0.0 or hb.imag != 0.0
    for k in range(3):
        if b_harm and pa[k] != 0.0:
            total += (hb * pa[k] * exp_moment(k, wz, u)).real
        if a_harm and pb[k] != 0.0:
            total += (ha * pb[k] * exp_moment(k, wz, u)).real
    if a_harm and b_harm:
        total += 0.5 * (ha * hb * exp_moment(0, 2.0 * wz, u)).real + 0.5 * (ha * hb.conjugate()).real * u
    total += _mode_product(a, S_M1, b, u, True) + _mode_product(a, S_M2, b, u, True)
    total += _mode_product(b, S_M1, a, u, False) + _mode_product(b, S_M2, a, u, False)
    return total


# ---------------------------------------------------------------------------- the scheme
@njit(cache=True)
def _kahan(total, compensation, value):
    corrected = value - compensation
    new_total = total + corrected
    return new_total, (new_total - total) - corrected


@njit(cache=True)
def _wrap(angle):
    return angle - 2.0 * math.pi * math.floor(angle / (2.0 * math.pi) + 0.5)


@njit(cache=True)
def _same_touchdown(a, b, length):
    """Same state at two touchdowns, relative to the motion's scales: velocities against
    the impact velocity, the stretch against itself plus the plate's excursion."""
    if abs(_wrap(a[T_PHASE] - b[T_PHASE])) > PERIODIC_TOL:
        return False
    speed = max(abs(a[T_YDOT]), abs(b[T_YDOT]))
    if abs(a[T_YDOT] - b[T_YDOT]) > PERIODIC_TOL * speed or abs(a[T_VX] - b[T_VX]) > PERIODIC_TOL * speed:
        return False
    return abs(a[T_STRETCH] - b[T_STRETCH]) <= PERIODIC_TOL * (max(abs(a[T_STRETCH]), abs(b[T_STRETCH])) + length)


@njit(cache=True)
def _touchdown_period(book, count, length):
    """Number of touchdowns p in a period if the last touchdown repeats the one p before,
    which repeats the one 2p before; 0 otherwise."""
    last = (count - 1) % TOUCHDOWNS
    for p in range(1, TOUCHDOWNS // 2 + 1):
        if count < 2 * p + 1:
            break
        one = (count - 1 - p) % TOUCHDOWNS
        two = (count - 1 - 2 * p) % TOUCHDOWNS
        if _same_touchdown(book[last], book[one], length) and _same_touchdown(book[one], book[two], length):
            return p
    return 0


@njit(cache=True)
def _evolve(y, slips, drv, prm, anchor, n_ref, off, n_to, off_to, track_energy, tol, skip_periods, out, costs):
    """Integrate model A from t0 + n_ref dt + off to t0 + n_to dt + off_to.

    Reads the state from y, writes the final state to out (same layout) and returns the
    slip count, or -1 if an event search failed or the state stopped being finite.  Adds
    the events it located to costs[0] and the plate periods it skipped to costs[1].
    """
    m, grav, k_n, k_t = prm[P_M], prm[P_G], prm[P_KN], prm[P_KT]
    gam_n, gam_t, mu_s, k_d, v_d = prm[P_GN], prm[P_GT], prm[P_MUS], prm[P_KD], prm[P_VD]
    t0, dt, amp, om = drv[D_T0], drv[D_DT], drv[D_AMP], drv[D_OMEGA]
    ext_z, ext_v, ext_a = drv[D_EXT_Z], drv[D_EXT_V], drv[D_EXT_A]
    ext_origin = t0 - drv[D_EXT_T]
    half_kt = 0.5 * k_t
    cascade_tol = CASCADE_TOL_FACTOR * tol

    x, z, vx, vz, shear = y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F]
    phi, phi_c = y[Y_PHI], y[Y_PHI_C]
    work, dissipated, e_normal = y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL]

    # Constants of the two oscillators and of the steady harmonic response in contact.
    lam_n, kap_n = -gam_n / (2.0 * m), k_n / m
    lam_t = -gam_t / (2.0 * m)
    response = m * amp * om * om / complex(k_n - m * om * om, gam_n * om)
    y_const = -m * (grav + ext_a) / k_n

    sig = np.zeros((N_ROWS, SIG_LEN))
    delta, normal_sig, ydot, vp = sig[R_DELTA], sig[R_N], sig[R_YDOT], sig[R_VP]
    contact_sig, neg_n, scratch = sig[R_CONTACT], sig[R_NEG_N], sig[R_SCRATCH]
    bound, spring = sig[R_BOUND], sig[R_SPRING]
    detach_known, detach_n, detach_off = False, n_ref, INF
    h_y = h_n = 0j
    y_s = yh0 = yh1 = nh0 = nh1 = 0.0

    # Which side of each switch the stored state is on.
    th = grid_phase(drv, anchor, n_ref) + om * off
    tau_e = ext_origin + n_ref * dt + off
    plate_z = amp * math.sin(th) + ext_z + tau_e * (ext_v + 0.5 * ext_a * tau_e)
    plate_v = amp * om * math.cos(th) + ext_v + ext_a * tau_e
    plate_a = -amp * om * om * math.sin(th) + ext_a
    pen, pen_rate = plate_z - z, plate_v - vz
    if pen > 0.0:
        in_contact = True
    elif pen == 0.0:
        in_contact = pen_rate > 0.0 or (pen_rate == 0.0 and plate_a + grav > 0.0)
    else:
        in_contact = False
    regime = FREE
    if in_contact:
        normal = k_n * pen + gam_n * pen_rate
        normal_rate = k_n * pen_rate + gam_n * (plate_a + grav - normal / m)
        if abs(k_t * shear) >= mu_s * normal and not (normal == 0.0 and normal_rate > 0.0 and shear == 0.0):
            if shear != 0.0:
                slips += 1
                dissipated += half_kt * shear * shear
            shear = 0.0
        if mu_s * normal > 0.0 or (mu_s > 0.0 and normal == 0.0 and normal_rate > 0.0):
            regime = ENGAGED
        else:
            regime = HELD
    elif shear != 0.0:
        dissipated += half_kt * shear * shear
        shear = 0.0

    # Touchdown book for skipping periods (only a purely harmonic drive repeats).
    periodic_drive = skip_periods and om > 0.0 and ext_v == 0.0 and ext_a == 0.0
    book = np.zeros((TOUCHDOWNS, 10))
    touchdowns = 0
    cycle = 2.0 * math.pi / om if om > 0.0 else INF

    just_reset = False
    immediate = 0
    while True:
        u_rem = (n_to - n_ref) * dt + (off_to - off)
        if u_rem <= 0.0:
            break
        th = grid_phase(drv, anchor, n_ref) + om * off
        tau_e = ext_origin + n_ref * dt + off
        e_th = complex(math.cos(th), math.sin(th))
        plate_z = amp * e_th.imag + ext_z + tau_e * (ext_v + 0.5 * ext_a * tau_e)
        plate_v = amp * om * e_th.real + ext_v + ext_a * tau_e
        stretch = v_d * (t0 + n_ref * dt) + v_d * off - x  # drive spring's far end minus x

        # Horizontal oscillator of this regime and its particular solution a + b u.
        loaded = regime == ENGAGED
        k_h = k_d + k_t if loaded else k_d
        f0 = k_d * stretch - (k_t * shear if loaded else 0.0)
        f1 = k_d * v_d
        if k_h > 0.0:
            b_lin = f1 / k_h
            a_lin = (f0 - gam_t * b_lin) / k_h
        else:
            b_lin = a_lin = 0.0
        kap_t = k_h / m
        xi0, xi1 = -a_lin, vx - b_lin
        xi2 = 2.0 * lam_t * xi1 - kap_t * xi0

        # Vertical solution of this regime, and the event signals.
        if in_contact:
            y_s, ydot_s = z - plate_z, vz - plate_v
            h_y = -1j * response * e_th  # y_R(u) = Re(h_y e^(i om u))
            yh0 = y_s - y_const - h_y.real
            yh1 = ydot_s - (1j * om * h_y).real
            yh2 = 2.0 * lam_n * yh1 - kap_n * yh0
            set_signal(delta, -y_const, 0.0, 0.0, -h_y, om)
            set_mode(delta, S_M1, -yh0, -yh1, lam_n, kap_n)
            h_n = -(k_n + 1j * om * gam_n) * h_y
            nh0 = -k_n * yh0 - gam_n * yh1
            nh1 = -k_n * yh1 - gam_n * yh2
            set_signal(normal_sig, -k_n * y_const, 0.0, 0.0, h_n, om)
            set_mode(normal_sig, S_M1, nh0, nh1, lam_n, kap_n)
            set_signal(ydot, 0.0, 0.0, 0.0, 1j * om * h_y, om)
            set_mode(ydot, S_M1, yh1, yh2, lam_n, kap_n)
        else:
            set_signal(contact_sig, z - (ext_z + tau_e * (ext_v + 0.5 * ext_a * tau_e)),
                       vz - (ext_v + ext_a * tau_e), -0.5 * (grav + ext_a), 1j * amp * e_th, om)

        u_ev, event = INF, EV_NONE
        if in_contact:
            # Detachment first: it bounds the other searches (and wins ties, resetting F anyway).
            # The vertical motion ignores the horizontal regime, so it is found once per contact.
            if not detach_known:
                r = first_zero(delta, 0.0, u_rem, tol)
                if math.isnan(r):
                    return -1
                detach_known = True
                detach_n, detach_off = n_ref, off + r  # absolute time (inf: not before the window's end)
                if detach_off < INF:
                    whole = math.floor(detach_off / dt)
                    detach_n += np.int64(whole)
                    detach_off -= whole * dt
            r = (detach_n - n_ref) * dt + (detach_off - off)
            if r < INF:
                u_ev, event = max(r, 0.0), EV_DETACH
            if regime == ENGAGED and just_reset:
                # A reset while N falls: cut the cascade if what it can still do is negligible.
                n_state = signal_state(normal_sig, 0.0)
                if n_state[1] < 0.0:
                    u_zero = first_zero(normal_sig, 0.0, min(u_ev, u_rem), tol)
                    if math.isnan(u_zero):
                        return -1
                    if u_zero < u_ev:
                        accel = (k_d * (abs(stretch) + (abs(v_d) + abs(vx)) * u_zero) + gam_t * abs(vx)) / m
                        v_max = abs(vx) + accel * u_zero
                        if k_t * v_max * u_zero * u_zero / (2.0 * m) <= cascade_tol:
                            regime = CASCADE
                            u_ev, event = u_zero, EV_N_ZERO
                            # the spring no longer loads: redo the horizontal particular solution
                            k_h = k_d
                            f0 = k_d * stretch
                            if k_h > 0.0:
                                b_lin = f1 / k_h
                                a_lin = (f0 - gam_t * b_lin) / k_h
                            else:
                                b_lin = a_lin = 0.0
                            kap_t = k_h / m
                            xi0, xi1 = -a_lin, vx - b_lin
                            xi2 = 2.0 * lam_t * xi1 - kap_t * xi0
            just_reset = False
            if regime == ENGAGED:
                # Coulomb: mu_s N -/+ k_t F, with the bound and the spring evaluated once per step
                set_signal(bound, -mu_s * k_n * y_const, 0.0, 0.0, mu_s * h_n, om)
                set_mode(bound, S_M1, mu_s * nh0, mu_s * nh1, lam_n, kap_n)
                set_signal(spring, k_t * (shear + a_lin), k_t * b_lin, 0.0, 0j, om)
                set_mode(spring, S_M1, k_t * xi0, k_t * xi1, lam_t, kap_t)
                u_hi = min(u_ev, u_rem)
                u_lo = 0.0
                # No reset can come before mu_s N falls to the largest k_t |F| of the interval: when
                # that is small (bouncing), find that point on the cheaper bound alone first.
                spring_max = k_t * (abs(shear) + abs(a_lin) + abs(b_lin) * u_hi
                                    + mode_envelope(xi0, xi1, lam_t, kap_t))
                if spring_max < 0.5 * bound[S_P0]:
                    bound[S_P0] -= spring_max
                    u_lo = first_zero(bound, 0.0, u_hi, tol)
                    bound[S_P0] += spring_max
                    if math.isnan(u_lo):
                        return -1
                if u_lo < INF:
                    r, sign = first_zero_pair(bound, spring, u_lo, u_hi, tol)
                else:
                    r, sign = INF, 0.0
                if math.isnan(r):
                    return -1
                if r < u_ev:
                    u_ev, event = r, EV_RESET_PLUS if sign > 0.0 else EV_RESET_MINUS
            elif regime == HELD:
                for i in range(SIG_LEN):
                    neg_n[i] = -normal_sig[i]
                for slot in (S_M1, S_M2):  # the modes' rates and k/m are not negated
                    neg_n[slot + 2], neg_n[slot + 3] = normal_sig[slot + 2], normal_sig[slot + 3]
                neg_n[S_OMEGA] = normal_sig[S_OMEGA]
                r = first_zero(neg_n, 0.0, min(u_ev, u_rem), tol)
                if math.isnan(r):
                    return -1
                if r < u_ev:
                    u_ev, event = r, EV_N_RISES
            elif regime == CASCADE and event == EV_NONE:
                r = first_zero(normal_sig, 0.0, min(u_ev, u_rem), tol)
                if math.isnan(r):
                    return -1
                if r < u_ev:
                    u_ev, event = r, EV_N_ZERO
        else:
            r = first_zero(contact_sig, 0.0, u_rem, tol)
            if math.isnan(r):
                return -1
            if r < u_ev:
                u_ev, event = r, EV_CONTACT

        if u_ev >= u_rem:
            u, event = u_rem, EV_NONE
        else:
            u = u_ev
        if u <= 0.0:
            immediate += 1
            if immediate > MAX_IMMEDIATE:
                # grazing that keeps switching back and forth: move on by one tolerance
                u = min(tol, u_rem)
                event = EV_NONE
                immediate = 0
        else:
            immediate = 0

        # State at the end of the segment.
        xi, xi_rate = mode_value(xi0, xi1, lam_t, kap_t, u)
        x_new = x + a_lin + b_lin * u + xi
        vx_new = b_lin + xi_rate
        shear_new = shear + a_lin + b_lin * u + xi if regime == ENGAGED else 0.0
        th_end = th + om * u
        tau_end = tau_e + u
        plate_z_end = amp * math.sin(th_end) + ext_z + tau_end * (ext_v + 0.5 * ext_a * tau_end)
        plate_v_end = amp * om * math.cos(th_end) + ext_v + ext_a * tau_end
        if in_contact:
            yh, yh_rate = mode_value(yh0, yh1, lam_n, kap_n, u)
            rot = h_y * complex(math.cos(om * u), math.sin(om * u))
            y_end = y_const + rot.real + yh
            ydot_end = (1j * om * rot).real + yh_rate
            z_new = y_end + plate_z_end
            vz_new = ydot_end + plate_v_end
        else:
            z_new = z + u * (vz - 0.5 * grav * u)
            vz_new = vz - grav * u

        # Quadratures over the segment; vx - V_d = (b - V_d) + xi', and xi integrates xi'.
        drift = b_lin - v_d
        phi_part = (drift * drift * u + 2.0 * drift * (xi - xi0)
                    + mode_square_integral(xi1, xi2, lam_t, kap_t, u, scratch))
        phi, phi_c = _kahan(phi, phi_c, phi_part)
        if track_energy:
            vx_square = phi_part + 2.0 * v_d * (x_new - x) - v_d * v_d * u
            dissipated += gam_t * vx_square
            if k_d != 0.0:
                xi_integral = -(m * (xi_rate - xi1) + gam_t * (xi - xi0)) / k_h
                work += k_d * v_d * (stretch * u + 0.5 * v_d * u * u
                                     - (a_lin * u + 0.5 * b_lin * u * u + xi_integral))
            work -= m * grav * (z_new - z)
            if in_contact:
                dissipated += gam_n * product_integral(ydot, ydot, u)
                set_signal(vp, ext_v + ext_a * tau_e, ext_a, 0.0, amp * om * e_th, om)
                work += product_integral(vp, normal_sig, u)
                e_normal += 0.5 * k_n * (y_end * y_end - y_s * y_s)

        x, z, vx, vz, shear = x_new, z_new, vx_new, vz_new, shear_new
        if not math.isfinite(x + z + vx + vz + shear + phi):
            return -1
        if u == u_rem:
            n_ref, off = n_to, off_to
        else:
            off += u
            if off >= dt:
                whole = math.floor(off / dt)
                n_ref += np.int64(whole)
                off -= whole * dt

        # Switches.
        if event != EV_NONE:
            costs[0] += 1
        if event == EV_DETACH:
            in_contact = False
            dissipated += half_kt * shear * shear
            shear = 0.0
            regime = FREE
        elif event == EV_N_ZERO:
            regime = HELD
        elif event == EV_N_RISES:
            regime = ENGAGED
            shear = 0.0
        elif event != EV_NONE:  # contact or Coulomb reset
            if event == EV_CONTACT:
                in_contact = True
                detach_known = False
            elif shear != 0.0:
                slips += 1
                dissipated += half_kt * shear * shear
            shear = 0.0
            # the spring re-arms if the bound is positive, or zero and rising
            plate_a_end = -amp * om * om * math.sin(th_end) + ext_a
            pen, pen_rate = plate_z_end - z, plate_v_end - vz
            normal = k_n * max(pen, 0.0) + gam_n * pen_rate
            normal_rate = k_n * pen_rate + gam_n * (plate_a_end + grav - normal / m)
            if mu_s * normal > 0.0 or (mu_s > 0.0 and normal == 0.0 and normal_rate > 0.0):
                regime = ENGAGED
                just_reset = event != EV_CONTACT
            else:
                regime = HELD
            if event == EV_CONTACT and periodic_drive:
                # Touchdown: if the motion has locked onto a period, add whole periods at once.
                rec = book[touchdowns % TOUCHDOWNS]
                t_now = t0 + n_ref * dt + off
                rec[T_PHASE] = _wrap(th_end)
                rec[T_YDOT] = vz - plate_v_end
                rec[T_STRETCH] = v_d * (t0 + n_ref * dt) + v_d * off - x
                rec[T_VX] = vx
                rec[T_TIME], rec[T_PHI], rec[T_WORK] = t_now, phi, work
                rec[T_DISS], rec[T_ENORM], rec[T_SLIPS] = dissipated, e_normal, slips
                touchdowns += 1
                p = _touchdown_period(book, touchdowns, abs(amp) + m * grav / k_n)
                if p > 0:
                    before = book[(touchdowns - 1 - p) % TOUCHDOWNS]
                    period = round((t_now - before[T_TIME]) / cycle) * cycle
                    u_left = (n_to - n_ref) * dt + (off_to - off)
                    skips = math.floor(u_left / period) - 1.0 if period > 0.0 else -1.0
                    if skips >= 1.0:
                        x += skips * v_d * period
                        phi += skips * (phi - before[T_PHI])
                        work += skips * (work - before[T_WORK])
                        dissipated += skips * (dissipated - before[T_DISS])
                        e_normal += skips * (e_normal - before[T_ENORM])
                        slips += np.int64(skips) * np.int64(slips - before[T_SLIPS])
                        off += skips * period
                        costs[1] += np.int64(skips) * np.int64(round(period / cycle))
                        whole = math.floor(off / dt)
                        n_ref += np.int64(whole)
                        off -= whole * dt
                        touchdowns = 0

    out[Y_X], out[Y_Z], out[Y_VX], out[Y_VZ], out[Y_F] = x, z, vx, vz, shear
    out[Y_PHI], out[Y_PHI_C] = phi, phi_c
    out[Y_WORK], out[Y_DISSIPATED], out[Y_E_NORMAL] = work, dissipated, e_normal
    return slips


@njit(cache=True)
def advance(kind, method, flags, y, cnt, drv, prm, n_steps, track_energy):
    """Advance model A by n_steps grid steps exactly (see the module doc): the end time
    t0 + (n + n_steps) dt is reached directly, whatever n_steps is.  Returns 0, or -1
    (the arrays untouched) if the state stopped being finite."""
    return advance_exact(y, cnt, drv, prm, n_steps, track_energy, EVENT_TOL, True)


@njit(cache=True)
def advance_exact(y, cnt, drv, prm, n_steps, track_energy, tol, skip_periods):
    """``advance`` with its event tolerance and period skipping chosen (for tests)."""
    n = cnt[C_STEP]
    out = y.copy()
    costs = np.zeros(2, np.int64)
    slips = _evolve(y, cnt[C_SLIPS], drv, prm, cnt[C_PHASE_STEP], n, 0.0, n + n_steps, 0.0, track_energy, tol,
                    skip_periods, out, costs)
    if slips < 0:
        return -1
    y[:] = out
    cnt[C_STEP] = n + n_steps
    cnt[C_SLIPS] = slips
    cnt[C_EVENTS] += costs[0]
    cnt[C_JUMPED] += costs[1]
    return 0


@njit(cache=True)
def observe(kind, method, flags, y, cnt, drv, prm, h, track_energy, obs):
    """Fill ``obs`` with the state at t_n + h (0 <= h < dt) by the exact flow, without
    touching the stored state (the layout of ``fixed_step.observe``)."""
    n = cnt[C_STEP]
    out = y.copy()
    slips = cnt[C_SLIPS]
    if h > 0.0:
        slips = _evolve(y, slips, drv, prm, cnt[C_PHASE_STEP], n, 0.0, n, h, track_energy, EVENT_TOL, False, out,
                        np.zeros(2, np.int64))
        if slips < 0:
            out[:] = math.nan
            slips = cnt[C_SLIPS]
    dt, om = drv[D_DT], drv[D_OMEGA]
    t = drv[D_T0] + n * dt + h
    th = phase_after(drv, cnt, n, h)
    tau_e = t - drv[D_EXT_T]
    plate_z = drv[D_AMP] * math.sin(th) + drv[D_EXT_Z] + tau_e * (drv[D_EXT_V] + 0.5 * drv[D_EXT_A] * tau_e)
    plate_v = drv[D_AMP] * om * math.cos(th) + drv[D_EXT_V] + drv[D_EXT_A] * tau_e
    pen = plate_z - out[Y_Z]
    normal = prm[P_KN] * pen - prm[P_GN] * (out[Y_VZ] - plate_v) if pen > 0.0 else 0.0
    record_observation(obs, out[Y_X], out[Y_Z], out[Y_VX], out[Y_VZ], out[Y_F], pen, normal, 1.0, out[Y_PHI], slips,
                       t, out[Y_WORK], out[Y_DISSIPATED], out[Y_E_NORMAL], pen > 0.0,
                       -prm[P_KT] * out[Y_F] if pen > 0.0 else 0.0)
    return N_OBS
