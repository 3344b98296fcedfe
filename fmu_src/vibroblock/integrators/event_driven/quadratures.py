"""Segment quadratures of ``event_driven``: the integrals the contract needs over one
segment of exact flow.

phi = int (vx - V_d)^2 dt, the work of the drive, the plate and gravity, and the dashpots'
dissipation are integrals of products of two signals (``signals``), done in closed form
with complex exponentials (int_0^u v^k e^(s v) dv), or, where a mode's exponential split
is ill-conditioned (near critical damping or a very short segment), by Gauss-Legendre
quadrature on the robust propagator.
"""
import cmath
import math

import numpy as np
from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ...dynamics import plate_motion
from ..fixed_step import kahan_add
from ...laws import contact_dissipation
from ...layout import (D_AMP, D_EXT_A, D_EXT_V, D_EXT_Z, D_OMEGA, P_G, P_GT, P_KD, P_M, P_VD, Y_DISSIPATED, Y_PHI,
                       Y_PHI_C, Y_WORK, Y_X, Y_Z)
from .signals import (R_N, R_SCRATCH, R_VP, R_YDOT, S_HIM, S_HRE, S_M1, S_M2, S_OMEGA, S_P0, S_P1, S_P2, mode_value,
                      set_mode, set_signal)

# A mode's exponential split is used for integrals only where the two exponents differ by
# at least this much over the part of the segment where the mode has not decayed.
CONDITIONING = 0.25
# e-foldings after which a decaying mode is negligible (e^-40 ~ 4e-18).
DECAY_WINDOW = 40.0
# 8-point Gauss-Legendre rule on [-1, 1].
GL_X = np.array([-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                 0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363])
GL_W = np.array([0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                 0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763])
# Gauss-Legendre panels allowed per integral (reached only near critical damping).
MAX_PANELS = 1 << 20


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


@njit(inline="always")
def segment_quadratures(kind, s, sig, prm, drv, flow, end, segment, in_contact, track_energy):
    """Add one segment's increments to the quadratures in ``s`` (phi and, with the energy
    balance, the work and the dissipation), ``s`` still holding the segment's start.

    ``flow`` is the horizontal flow (``regimes.horizontal_flow``), ``end`` = (xi, xi', x, z)
    at the segment's end, ``segment`` = (u, stretch, tau_e, e^(i theta)) at its start.
    vx - V_d = (b - V_d) + xi', and xi integrates xi'."""
    k_h, a_lin, b_lin, lam_t, kap_t, xi0, xi1, xi2 = flow
    xi, xi_rate, x_new, z_new = end
    u, stretch, tau_e, e_th = segment
    m, gam_t, k_d, v_d = prm[P_M], prm[P_GT], prm[P_KD], prm[P_VD]
    drift = b_lin - v_d
    phi_part = (drift * drift * u + 2.0 * drift * (xi - xi0)
                + mode_square_integral(xi1, xi2, lam_t, kap_t, u, sig[R_SCRATCH]))
    s[Y_PHI], s[Y_PHI_C] = kahan_add(s[Y_PHI], s[Y_PHI_C], phi_part)  # phi runs over up to 1e12 grid steps
    if not track_energy:
        return
    vx_square = phi_part + 2.0 * v_d * (x_new - s[Y_X]) - v_d * v_d * u
    s[Y_DISSIPATED] += gam_t * vx_square
    if k_d != 0.0:
        xi_integral = -(m * (xi_rate - xi1) + gam_t * (xi - xi0)) / k_h
        s[Y_WORK] += k_d * v_d * (stretch * u + 0.5 * v_d * u * u - (a_lin * u + 0.5 * b_lin * u * u + xi_integral))
    s[Y_WORK] -= m * prm[P_G] * (z_new - s[Y_Z])
    if in_contact:
        # the dashpot's power is its rate per unit u_n^2 times u_n^2 (the linear law's)
        s[Y_DISSIPATED] += contact_dissipation(kind, 1.0, 1.0, prm) * product_integral(sig[R_YDOT], sig[R_YDOT], u)
        # the plate's velocity: the external input's part, plus the harmonic drive's
        amp, om = drv[D_AMP], drv[D_OMEGA]
        ext_v = plate_motion(0.0, om, 0.0, 0.0, drv[D_EXT_Z], drv[D_EXT_V], drv[D_EXT_A], tau_e)[1]
        set_signal(sig[R_VP], ext_v, drv[D_EXT_A], 0.0, amp * om * e_th, om)
        s[Y_WORK] += product_integral(sig[R_VP], sig[R_N], u)
