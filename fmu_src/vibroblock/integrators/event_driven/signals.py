"""Signals: every quantity an event of ``event_driven`` depends on, in one closed form.

    g(u) = p0 + p1 u + p2 u^2 + Re(H e^(i omega u)) + mode_1(u) + mode_2(u)

A mode is a homogeneous solution of one of the two oscillators (the contact's, the
horizontal one), f'' - 2 lam f' + kap f = 0, held as its value and rate at u = 0.  A
signal is a row of SIG_LEN numbers; the scheme keeps its signals in the rows R_* of one
workspace array.
"""
import math

from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

# Signal layout: polynomial, harmonic, two modes (initial value, rate, lam, k/m).
S_P0, S_P1, S_P2, S_HRE, S_HIM, S_OMEGA = 0, 1, 2, 3, 4, 5
S_M1, S_M2 = 6, 10
SIG_LEN = 14
# Rows of the signal workspace.
R_DELTA, R_N, R_YDOT, R_VP, R_CONTACT, R_BOUND, R_SPRING, R_NEG_N, R_SCRATCH = range(9)
N_ROWS = 9

INF = math.inf
E_CONST = math.e


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

