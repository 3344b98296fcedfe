"""``implicit_contact`` (id 3), stiff-stable stepping: the linear contact
spring-dashpots are integrated in closed form, everything else is held over the step.

Why
---
With the paper's soft contact (k_n/m = 1) any scheme works at dt = 4e-4.  A stiff contact
(k_n/m = 1e8, so omega_n dt = 4 and an impact lasts less than a step) makes every explicit
scheme blow up, and an implicit Euler step would damp the bounce away without counting it
as dissipation, so the energy balance would not close.  Along the contact normal and
tangent the stiff forces are *linear* in the state, so their flow is known exactly:

    normal, while delta > 0:      m delta'' + gamma_n delta' + k_n delta = g_n
    tangential, while delta > 0:  m F'' + gamma_t F' + k_t F + k_d c^2 s = g_t   (F' = s' = u_t)
    tangential, in flight:        m s'' + gamma_t s'         + k_d c^2 s = g_t
    normal, in flight:            m delta''                              = g_n

where s is the travel along the tangent since the step began, c = cos(alpha), and g_n,
g_t collect the soft forces: the rest of the drive spring, the load, the plate's
acceleration seen from the plate, and the turning of the local frame on a corrugated
plate.

The scheme (one step of length h)
---------------------------------
1. State in the plate's local frame at the block: penetration delta and the velocities
   u_n, u_t relative to the plate (``dynamics.contact``), and F.
2. Soft forces evaluated once, at the midpoint: drive spring at the predicted position
   x + h vx / 2 and time t + h/2 (its pull along the tangent as the block travels is
   part of the exact tangential flow, 4.); load projected on the frame there; the plate's
   mean acceleration over the step, (V_p(t+h) - V_p(t)) / h; on a corrugated plate the
   frame's turning rate Omega = (alpha(x + h vx) - alpha(x)) / h (a central difference
   about the midpoint) gives the centripetal and Coriolis terms and the change of delta
   as the tangent line under the block turns.
3. Normal direction: the exact flow of the linear oscillator above, with the contact
   switches (delta crossing 0 either way) located inside the step: in flight delta is a
   parabola (closed-form root), in contact a damped oscillation (bracketed between its
   extrema, then a safeguarded Newton iteration to machine precision).  A step may hold
   several contact and flight segments.
4. Tangential direction over the same segments: the exact flow of F (in contact) or of
   the free tangential displacement (in flight, where only gamma_t acts).  A detachment
   inside the step releases F (the paper's rule F = 0 once detached).
5. Back to fixed axes: x from the tangential and normal displacements; z and the
   velocities from the new delta and (u_t, u_n), read in the frame the step has turned
   to, alpha(x + h vx) (reading them in the frame at the new x instead costs an O(h^2)
   error per step: the two differ by O(h^2)); the plate's position and velocity are
   exact at t + h.  The caller then applies the friction rule at the new state (the
   contract in ``integrators``).

Order and stability
-------------------
* The only approximation is holding the soft forces at their midpoint values over a
  step: second order (exponential midpoint rule) while the contact state does not change
  and the dynamics are smooth, e.g. the vibrated block embedded below threshold (tested:
  slope 2 of log error against log dt).  Contact switches are located in the step's
  exact flow, so impacts cost no order; Coulomb resets happen at step ends (the contract)
  and are first order, as in every fixed-step scheme here.
* Stable for any k_n, gamma_n, k_t, gamma_t >= 0: the contact flows are exact, so the
  step is never limited by the contact.  The drive spring's pull along the tangent
  (stiffness k_d cos^2 alpha) is part of the exact tangential flow: held explicit, a
  slow force sampled on an under-resolved fast oscillation resonates (multiple-time-
  stepping resonance, seen at dt sqrt(k_t/m) ~ 5 as energy growth), so on a flat plate
  nothing explicit is left and dt is free (tested over 1e9 tau_0 at dt = 40).  On a
  corrugated plate the frame is frozen over a step: the drive's pull across the slope
  and the load's pull along the curved surface stay explicit (``Block`` asks
  dt^2 (k_d + load A_x omega_x^2)/m <= 1), and the surface under the block must not turn
  by more than MAX_TURN_PER_STEP radians in one step (checked at run time: status
  TOO_FAST_FOR_CORRUGATION).
* The energy balance is accumulated from the same exact flows: dashpot dissipation from
  each oscillator's energy identity, the plate's work from the contact impulse and its
  first moment (exact for the plate velocity linear over the step), so the residual is
  the splitting error alone (second order for smooth motion) and not a quadrature error
  of the stiff forces.

Status codes (the driver returns them): -1 non-finite state
(as every integrator), TOO_MANY_SWITCHES (more than MAX_SEGMENTS contact switches in one
step), TOO_FAST_FOR_CORRUGATION (see above).  The arrays are left as they were on entry.
"""
import math

import numpy as np
from .. import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ..dynamics import contact, curvature_force, frame
from ..laws import friction_energy
from ..layout import P_GN, P_GT, P_KD, P_KN, P_KT, P_M, P_VD
from ..models import load, profile

TOO_MANY_SWITCHES = -2
TOO_FAST_FOR_CORRUGATION = -3
# Contact/flight segments allowed in one step.  An impact lasts at least about half a
# contact period, so a step holds about 2 (1 + omega_n dt / pi) segments: 4 at
# k_n/m = 1e8 and dt = 4e-4.  More means a chattering contact the step cannot resolve.
MAX_SEGMENTS = 256
# The search for a release splits the step into pieces shorter than half a contact
# period; a contact so stiff that a step holds more pieces than this is refused.
MAX_PIECES = 4096
# The frame on a corrugated plate is frozen at the step's midpoint: the surface under
# the block may turn by at most this angle (radians) in one step.
MAX_TURN_PER_STEP = 0.25

# Series expansion of the propagator below this (a tau, sqrt(w2) tau); Taylor series of
# cosh/sinh in the discriminant near critical damping below |a^2 - w2| tau^2 = NEAR_CRITICAL.
SERIES_LIMIT = 0.5
NEAR_CRITICAL = 1e-2

# Rows of the table of propagators for a whole step and a half step (``step_propagators``).
NORMAL_CONTACT, SHEAR_CONTACT, SHEAR_FLIGHT = 0, 1, 2
HALF = 3  # offset of the half-step rows


@njit(cache=True)
def oscillator_flow(a, w2, tau):
    """Propagator of y'' + 2 a y' + w2 y = b (constant b) over tau >= 0, for a, w2 >= 0.

    Returns (p, q, r, i1) with y(tau) = p y0 + q v0 + i1 b and v(tau) = -w2 q y0 + r v0 + q b.
    Accurate to a few ulps from tau -> 0 to stiff, heavily over- or undamped arguments:
    a power series for small arguments, a Taylor series in the discriminant near critical
    damping, trigonometric or exponential closed forms otherwise, written without the
    cancellations of the textbook forms (e.g. the slow decay rate w2 / (a + mu)).
    """
    if a * tau < SERIES_LIMIT and w2 * tau * tau < SERIES_LIMIT * SERIES_LIMIT:
        # Terms t_k = c_k tau^k of q's power series; r = q', i1 = integral of q.
        two_a_tau = 2.0 * a * tau
        w2_tau2 = w2 * tau * tau
        previous, term = 0.0, tau
        q, r, i1 = tau, 1.0, 0.5 * tau * tau
        k = 1
        while k < 60:
            following = -(two_a_tau * k * term + w2_tau2 * previous) / ((k + 1) * k)
            k += 1
            previous, term = term, following
            q += term
            r += k * term / tau
            i1 += term * tau / (k + 1)
            if abs(term) <= 1e-18 * abs(q) and abs(previous) <= 1e-18 * abs(q):
                break
        return r + 2.0 * a * q, q, r, i1
    disc = a * a - w2
    if abs(disc) * tau * tau < NEAR_CRITICAL:
        x = disc * tau * tau
        c, s, term_c, term_s = 1.0, 1.0, 1.0, 1.0
        for k in range(1, 8):
            term_c *= x / ((2 * k - 1) * (2 * k))
            term_s *= x / ((2 * k) * (2 * k + 1))
            c += term_c
            s += term_s
        decay = math.exp(-a * tau)
        q = decay * s * tau
        p, r = decay * c + a * q, decay * c - a * q
        return p, q, r, (1.0 - p) / w2
    if disc < 0.0:
        wd = math.sqrt(-disc)
        decay = math.exp(-a * tau)
        q = decay * math.sin(wd * tau) / wd
        ec = decay * math.cos(wd * tau)
        p, r = ec + a * q, ec - a * q
        return p, q, r, (1.0 - p) / w2
    mu = math.sqrt(disc)
    fast_rate = a + mu
    slow_rate = w2 / fast_rate
    slow, fast = math.exp(-slow_rate * tau), math.exp(-fast_rate * tau)
    two_mu = 2.0 * mu
    q = (slow - fast) / two_mu
    p = (fast_rate * slow - slow_rate * fast) / two_mu
    r = (fast_rate * fast - slow_rate * slow) / two_mu
    slow_integral = tau if slow_rate == 0.0 else -math.expm1(-slow_rate * tau) / slow_rate
    return p, q, r, (slow_integral - q) / fast_rate


@njit(inline="always")
def _apply(prop, w2, y0, v0, b):
    p, q, r, i1 = prop
    return p * y0 + q * v0 + i1 * b, -w2 * q * y0 + r * v0 + q * b


@njit(cache=True)
def step_propagators(prm, h):
    """The propagators of a whole step h on a flat plate (the tangential ones include the
    drive spring's stiffness k_d), and of a half step without the drive (the midpoint
    predictor on a corrugated plate)."""
    m = prm[P_M]
    a_n, w2_n = 0.5 * prm[P_GN] / m, prm[P_KN] / m
    a_t, w2_t, w2_d = 0.5 * prm[P_GT] / m, prm[P_KT] / m, prm[P_KD] / m
    table = np.empty((6, 4))
    table[NORMAL_CONTACT, :] = oscillator_flow(a_n, w2_n, h)
    table[SHEAR_CONTACT, :] = oscillator_flow(a_t, w2_t + w2_d, h)
    table[SHEAR_FLIGHT, :] = oscillator_flow(a_t, w2_d, h)
    table[HALF + NORMAL_CONTACT, :] = oscillator_flow(a_n, w2_n, 0.5 * h)
    table[HALF + SHEAR_CONTACT, :] = oscillator_flow(a_t, w2_t, 0.5 * h)
    table[HALF + SHEAR_FLIGHT, :] = oscillator_flow(a_t, 0.0, 0.5 * h)
    return table


@njit(inline="always")
def _row(table, i):
    return table[i, 0], table[i, 1], table[i, 2], table[i, 3]


# ---------------------------------------------------------------------- contact switches
@njit(cache=True)
def flight_landing(d0, v0, b, span):
    """First time in (0, span] at which d0 + v0 t + b t^2 / 2 (d0 <= 0) rises above 0, or -1."""
    if b == 0.0:
        if v0 > 0.0:
            t = -d0 / v0
            if 0.0 < t <= span:
                return t
        return -1.0
    disc = v0 * v0 - 2.0 * b * d0
    if disc < 0.0:
        return -1.0
    root = math.sqrt(disc)
    q = -0.5 * (v0 + (root if v0 >= 0.0 else -root))
    best = -1.0
    for t in (q / (0.5 * b), d0 / q if q != 0.0 else -1.0):
        # the upward crossing: the penetration's rate v0 + b t must not be negative there
        if 0.0 < t <= span and v0 + b * t >= 0.0 and (best < 0.0 or t < best):
            best = t
    return best


@njit(inline="always")
def _oscillation_at(a, w2, b, d0, v0, t):
    return _apply(oscillator_flow(a, w2, t), w2, d0, v0, b)


@njit(cache=True)
def _first_non_positive(a, w2, b, d0, v0, lo, hi):
    """The time in (lo, hi] at which the oscillation first reaches delta <= 0, given a single
    crossing there; safeguarded Newton on the exact flow, to a few ulps."""
    t = hi
    d, v = _oscillation_at(a, w2, b, d0, v0, t)
    for _ in range(200):
        if hi - lo <= 4e-16 * hi:
            break
        guess = t - d / v if v != 0.0 else 0.5 * (lo + hi)
        if not (lo < guess < hi):
            guess = 0.5 * (lo + hi)
        t = guess
        d, v = _oscillation_at(a, w2, b, d0, v0, t)
        if d > 0.0:
            lo = t
        else:
            hi = t
            if d == 0.0:
                break
    return hi


@njit(cache=True)
def _velocity_zero(a, w2, b, d0, v0, lo, hi):
    """The extremum of delta in (lo, hi), where delta' goes from negative to positive."""
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if not (lo < mid < hi):
            break
        if _oscillation_at(a, w2, b, d0, v0, mid)[1] < 0.0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit(cache=True)
def contact_release(a, w2, b, d0, v0, span):
    """First time in (0, span] at which delta'' + 2 a delta' + w2 delta = b, started at
    (d0 >= 0, v0), reaches delta <= 0; -1 if it stays in contact over the whole span, -2
    if the contact is too stiff to search (more than MAX_PIECES half-periods in the span)."""
    # The oscillator's energy about its equilibrium cannot grow (a >= 0): delta stays
    # within eq +- amplitude.  This settles the embedded block without any search.
    eq = b / w2
    y0 = d0 - eq
    amplitude = math.sqrt(y0 * y0 + v0 * v0 / w2)
    if eq - amplitude > 0.0:
        return -1.0
    # Pieces shorter than half a damped period hold at most one extremum of delta.
    pieces = 1
    if w2 > a * a:
        periods = math.sqrt(w2 - a * a) * span / math.pi
        if not periods < MAX_PIECES:
            return -2.0
        pieces = int(periods) + 1
    ta, va = 0.0, v0
    for j in range(1, pieces + 1):
        tb = span * j / pieces
        db, vb = _oscillation_at(a, w2, b, d0, v0, tb)
        if db <= 0.0:
            return _first_non_positive(a, w2, b, d0, v0, ta, tb)
        if va < 0.0 < vb:  # a minimum inside: does it dip below the surface?
            t_min = _velocity_zero(a, w2, b, d0, v0, ta, tb)
            if _oscillation_at(a, w2, b, d0, v0, t_min)[0] <= 0.0:
                return _first_non_positive(a, w2, b, d0, v0, ta, t_min)
        ta, va = tb, vb
    return -1.0


# ---------------------------------------------------------------------- one step
@njit(inline="always")
def _soft_forces(kind, prm, x, vx, t, h, start, plate_accel, push):
    """The soft forces at the midpoint, in the frame there (step 2 of the module doc), from
    ``start`` = (delta, u_n, u_t, cos, sin) at the step's start; ``push`` is the plate
    frame's horizontal force at the mid time (``laws.plate_oblique``).  Returns (status, (cos,
    sin, turning rate Omega, slope at x + h vx), (normal force, tangential force, the
    drive's pull at the start position less at the midpoint, load_x, load_z))."""
    m = prm[P_M]
    pen0, _, _, cos0, sin0 = start
    t_mid = t + 0.5 * h
    x_mid = x + 0.5 * h * vx
    slope_m = profile(kind, x_mid, prm)[1]
    slope_end = profile(kind, x + h * vx, prm)[1]
    cos_m, sin_m, turn_rate = 1.0, 0.0, 0.0
    if sin0 != 0.0 or slope_m != 0.0 or slope_end != 0.0:  # a flat plate skips all of this
        cos_m, sin_m = frame(slope_m)
        turn_rate = (math.atan(slope_end) - math.atan(sin0 / cos0)) / h
        if not abs(turn_rate * h) <= MAX_TURN_PER_STEP:
            return TOO_FAST_FOR_CORRUGATION, (cos_m, sin_m, turn_rate, slope_end), (0.0, 0.0, 0.0, 0.0, 0.0)
    drive = -prm[P_KD] * (x_mid - prm[P_VD] * t_mid)
    drive_start = -prm[P_KD] * (x - prm[P_VD] * t_mid)
    if push != 0.0:  # (a vertical plate adds nothing, not even the sign of a zero)
        drive += push
        drive_start += push
    load_x, load_z = load(kind, cos_m, sin_m, prm)
    force_n = -(drive + load_x) * sin_m + load_z * cos_m - m * plate_accel * cos_m
    force_t = (drive + load_x) * cos_m + load_z * sin_m - m * plate_accel * sin_m
    return 0, (cos_m, sin_m, turn_rate, slope_end), (force_n, force_t, drive_start - drive, load_x, load_z)


@njit(inline="always")
def _turning(kind, prm, table, h, shear, start, in_contact, frame_m, x_mid, force_n, force_t):
    """On a turning frame: the forces with the centripetal term and, in contact, a
    conservative contact's curvature term at the midpoint like the other soft forces; and
    the rate at which delta changes as the tangent line under the block turns (d delta/dt
    = -u_n - delta tan(alpha) Omega), from half-step flows in the starting contact state
    (the O(h^2) accuracy the midpoint rule needs), with the turning terms.  Returns
    (normal force, tangential force, delta's rate)."""
    m = prm[P_M]
    pen0, u_n0, u_t0, _, _ = start
    cos_m, sin_m, turn_rate, _ = frame_m
    turning = (sin_m / cos_m) * turn_rate
    pen_rate0 = -u_n0 - turning * pen0
    coriolis0 = turn_rate * u_n0
    if in_contact:
        ut_mid = _apply(_row(table, HALF + SHEAR_CONTACT), prm[P_KT] / m, shear, u_t0, force_t / m + coriolis0)[1]
    else:
        ut_mid = _apply(_row(table, HALF + SHEAR_FLIGHT), 0.0, 0.0, u_t0, force_t / m + coriolis0)[1]
    force_n -= m * turn_rate * ut_mid  # centripetal
    if in_contact:
        b_mid = (-prm[P_GN] * turning * pen0 - force_n) / m
        pen_mid = _apply(_row(table, HALF + NORMAL_CONTACT), prm[P_KN] / m, pen0, pen_rate0, b_mid)[0]
    else:
        pen_mid = pen0 + 0.5 * h * pen_rate0 - 0.125 * h * h * force_n / m
    if in_contact:
        curving = curvature_force(kind, x_mid, pen_mid, cos_m, sin_m, prm)
        force_n -= curving * sin_m
        force_t += curving * cos_m
    return force_n, force_t, -turning * pen_mid


@njit(inline="always")
def _contact_segment(prm, table, h, d, v, b, span, track_energy, plate):
    """A contact segment of the normal flow from delta = d, delta' = v under the constant
    forcing b, up to a release within ``span``: (tau, released, delta, delta', the plate's
    work, the dashpot's dissipation); tau = -2 if the contact is too stiff to search.
    ``plate`` = (plate velocity at the segment's start, the step's plate acceleration,
    cos, the normal force, delta's turning rate)."""
    m, k_n, g_n = prm[P_M], prm[P_KN], prm[P_GN]
    a_n, w2_n = 0.5 * g_n / m, k_n / m
    tau = contact_release(a_n, w2_n, b, d, v, span)
    if tau == -2.0:
        return tau, False, d, v, 0.0, 0.0
    switch = tau >= 0.0
    if not switch:
        tau = span
    prop = _row(table, NORMAL_CONTACT) if tau == h else oscillator_flow(a_n, w2_n, tau)
    d1, v1 = _apply(prop, w2_n, d, v, b)
    work = dissipated = 0.0
    if track_energy:
        # Exact for this flow: impulse J0 and first moment J1 of N = -m delta'' - f_n,
        # dashpot dissipation from the energy identity.
        plate_v, plate_accel, cos_m, force_n, delta_rate = plate
        change = d1 - d
        j0 = -m * (v1 - v) - force_n * tau
        j1 = -m * (tau * v1 - change) - 0.5 * force_n * tau * tau
        work = cos_m * (plate_v * j0 + plate_accel * j1)
        oscillator_energy = 0.5 * m * (v1 - v) * (v1 + v) + 0.5 * k_n * (d1 - d) * (d1 + d)
        dissipated = (g_n * delta_rate * delta_rate * tau - (g_n * delta_rate + force_n) * change
                      - oscillator_energy)
    return tau, switch, 0.0 if switch else d1, v1, work, dissipated


@njit(inline="always")
def _normal_flow(prm, table, h, d, v, in_contact, forces, segments, track_energy):
    """Step 3: the normal direction's exact flow over the step from delta = d, delta' = v,
    the contact switches located; ``forces`` = (normal force, delta's turning rate, cos,
    plate velocity at the start, plate acceleration).  Fills ``segments`` = (lengths,
    in contact) and returns (status, segments, delta, delta', work, dissipated)."""
    m, g_n = prm[P_M], prm[P_GN]
    force_n, delta_rate, cos_m, pv0, plate_accel = forces
    seg_len, seg_contact = segments
    elapsed, n_seg = 0.0, 0
    work = dissipated = 0.0
    while True:
        span = h - elapsed
        if span <= 0.0:
            break
        if n_seg == MAX_SEGMENTS:
            return TOO_MANY_SWITCHES, n_seg, d, v, work, dissipated
        if in_contact:
            tau, switch, d1, v1, d_work, d_dissipated = _contact_segment(
                prm, table, h, d, v, (g_n * delta_rate - force_n) / m, span, track_energy,
                (pv0 + plate_accel * elapsed, plate_accel, cos_m, force_n, delta_rate))
            if tau == -2.0:
                return TOO_MANY_SWITCHES, n_seg, d, v, work, dissipated
            work += d_work
            dissipated += d_dissipated
        else:
            b = -force_n / m
            tau = flight_landing(d, v, b, span)
            switch = tau >= 0.0
            if not switch:
                tau = span
            d1 = 0.0 if switch else d + tau * (v + 0.5 * b * tau)
            v1 = v + b * tau
        seg_len[n_seg] = tau
        seg_contact[n_seg] = in_contact
        n_seg += 1
        d, v = d1, v1
        elapsed += tau
        if not switch:
            break
        in_contact = not in_contact
        # Grazing release with the forces still pressing in: stay in contact.
        if not in_contact and v == 0.0 and -force_n > 0.0:
            in_contact = True
    return 0, n_seg, d, v, work, dissipated


@njit(inline="always")
def _plate_impulse(prm, tau, u, u1, y1, change, b, w2, k_drive):
    """Impulse and first moment over a tangential segment of the contact's tangential force
    T = -k_t F - gamma_t u_t: T = m u' - m b + k_drive y, so both follow from the flow's
    ends and the oscillator's integrals m w2 (Y0, Y1) of y and t y."""
    m = prm[P_M]
    a_t = 0.5 * prm[P_GT] / m
    impulse = m * (u1 - u) - m * b * tau
    moment = m * (tau * u1 - change) - 0.5 * m * b * tau * tau
    if k_drive != 0.0:
        share = k_drive / (m * w2)
        y_integral = share * (m * b * tau - m * (u1 - u) - m * 2.0 * a_t * change)
        impulse += y_integral
        moment += share * (0.5 * m * b * tau * tau - m * (tau * u1 - change)
                           - m * 2.0 * a_t * (tau * y1 - y_integral / k_drive))
    return impulse, moment


@njit(inline="always")
def _tangential_flow(kind, prm, table, h, start, forces, segments, track_energy, totals):
    """Step 4: the tangential direction's exact flow over the normal flow's segments, from
    ``start`` = (F, u_t): F in contact (both springs pull, the drive's by the travel since
    the step began), the free travel in flight; a detachment inside the step releases F.
    ``forces`` = (tangential force, the drive's stiffness along the tangent, sin, plate
    velocity at the start, plate acceleration, whether cos = 1: the table's tangential rows
    hold k_d), ``totals`` = (work, dissipated) so far.
    Returns (F, u_t, travel, work, dissipated)."""
    m = prm[P_M]
    force_t, k_drive, sin_m, pv0, plate_accel, flat = forces
    seg_len, seg_contact, n_seg = segments
    work, dissipated = totals
    a_t = 0.5 * prm[P_GT] / m
    w2_contact, w2_flight = (prm[P_KT] + k_drive) / m, k_drive / m
    f, u = start
    travel = elapsed = 0.0
    was_contact = seg_contact[0]
    for i in range(n_seg):
        tau, engaged = seg_len[i], seg_contact[i]
        if was_contact and not engaged:  # detached inside the step: the spring is released
            if track_energy:
                dissipated += friction_energy(kind, f, prm)
            f = 0.0
        was_contact = engaged
        # Oscillator y'' + 2 a_t y' + w2 y = b with y = F in contact, the free travel in flight.
        if engaged:
            w2, y0, row = w2_contact, f, SHEAR_CONTACT
            b = (force_t - k_drive * (travel - f)) / m
        else:
            w2, y0, row = w2_flight, 0.0, SHEAR_FLIGHT
            b = (force_t - k_drive * travel) / m
        prop = _row(table, row) if tau == h and flat else oscillator_flow(a_t, w2, tau)
        y1, u1 = _apply(prop, w2, y0, u, b)
        change = y1 - y0
        if track_energy:
            dissipated += (m * b * change - 0.5 * m * (u1 - u) * (u1 + u)
                           - 0.5 * m * w2 * (y1 - y0) * (y1 + y0))
            if sin_m != 0.0:  # the tangential force's work through the plate's vertical velocity
                impulse, moment = _plate_impulse(prm, tau, u, u1, y1, change, b, w2, k_drive)
                work += sin_m * ((pv0 + plate_accel * elapsed) * impulse + plate_accel * moment)
        if engaged:
            f = y1
        travel += change
        u = u1
        elapsed += tau
    if not seg_contact[n_seg - 1]:
        f = 0.0
    return f, u, travel, work, dissipated


@njit(cache=True)
def implicit_contact_step(kind, prm, state, t, h, plate, ctx, track_energy):
    """One step of length h from ``state`` = (x, z, vx, vz, F) at time t; ``plate`` =
    (height, velocity) at t and at t + h, and the plate frame's horizontal force at
    t + h/2.  ``ctx`` holds ``step_propagators(prm, h)`` and
    the scratch arrays of MAX_SEGMENTS entries for the segments' lengths and contact states.

    Returns (status, x, z, vx, vz, F, d_phi, d_work, d_dissipated): status 0, or
    TOO_MANY_SWITCHES / TOO_FAST_FOR_CORRUGATION (the state is then not usable).
    The friction rule at the new state is the caller's (as for every integrator).
    """
    x, z, vx, vz, shear = state
    pz0, pv0, pz1, pv1, push = plate
    table, seg_len, seg_contact = ctx
    pen0, u_n0, u_t0, cos0, sin0, _ = contact(kind, x, z, vx, vz, pz0, pv0, prm)
    start = (pen0, u_n0, u_t0, cos0, sin0)
    plate_accel = (pv1 - pv0) / h
    status, frame_m, forces = _soft_forces(kind, prm, x, vx, t, h, start, plate_accel, push)
    if status != 0:
        return status, x, z, vx, vz, shear, 0.0, 0.0, 0.0
    cos_m, sin_m, turn_rate, slope_end = frame_m
    force_n, force_t, drive_lag, load_x, load_z = forces
    delta_rate = 0.0
    in_contact = pen0 > 0.0 or (pen0 == 0.0 and u_n0 < 0.0)
    if turn_rate != 0.0:
        force_n, force_t, delta_rate = _turning(kind, prm, table, h, shear, start, in_contact, frame_m,
                                                x + 0.5 * h * vx, force_n, force_t)

    status, n_seg, pen1, v, work, dissipated = _normal_flow(
        prm, table, h, pen0, delta_rate - u_n0, in_contact, (force_n, delta_rate, cos_m, pv0, plate_accel),
        (seg_len, seg_contact), track_energy)
    if status != 0:
        return status, x, z, vx, vz, shear, 0.0, 0.0, 0.0
    normal_travel = delta_rate * h - (pen1 - pen0)  # integral of u_n over the step
    u_n1 = delta_rate - v

    # The drive spring pulls along the tangent with stiffness k_d cos^2 as the block
    # travels: that part joins the exact flow (held explicit, it resonates with an
    # under-resolved tangential oscillation once dt sqrt(k_t/m) > pi); the rest of the
    # drive is taken at the step's start position and mid time, plus its pull through
    # the normal travel on a slope (at the mid value, half the step's travel).
    k_drive = prm[P_KD] * cos_m * cos_m
    force_t += (prm[P_M] * turn_rate * normal_travel / h  # Coriolis, with the step's mean u_n
                + drive_lag * cos_m + prm[P_KD] * cos_m * sin_m * 0.5 * normal_travel)
    f, u_t1, travel, work, dissipated = _tangential_flow(
        kind, prm, table, h, (shear, u_t0), (force_t, k_drive, sin_m, pv0, plate_accel, cos_m == 1.0),
        (seg_len, seg_contact, n_seg),
        track_energy, (work, dissipated))

    # Step 5: back to fixed axes at the new position.  The step's frame has turned by
    # Omega h = alpha(x + h vx) - alpha(x), which differs from alpha(x1) - alpha(x) by
    # O(h^2).  (u_t, u_n) are components in that frame, and delta is measured across it:
    # read both back in it (delta / cos gives the vertical gap, which is frame-free), so
    # the error stays O(h^3) per step.
    x1 = x + cos_m * travel - sin_m * normal_travel
    height1, slope1 = profile(kind, x1, prm)
    cos_e, sin_e = frame(slope_end if turn_rate != 0.0 or slope_end != slope1 else slope1)
    z1 = pz1 + height1 - pen1 / cos_e
    vx1 = u_t1 * cos_e - u_n1 * sin_e
    vz1 = pv1 + u_t1 * sin_e + u_n1 * cos_e

    vd = prm[P_VD]
    d_phi = 0.5 * h * ((vx - vd) * (vx - vd) + (vx1 - vd) * (vx1 - vd))
    if track_energy:
        work += prm[P_KD] * (vd * (t + 0.5 * h) - 0.5 * (x + x1)) * vd * h  # the drive's far end
        work += load_x * (x1 - x) + load_z * (z1 - z)  # the load, constant over the step
        if push != 0.0:
            work += push * (x1 - x)  # the plate frame's force, at its mid-step value
    return 0, x1, z1, vx1, vz1, f, d_phi, work, dissipated


# ---------------------------------------------------------------------- the scheme
# Called by the driver's loop, not inlined into it (``fixed_step.register``): its closed-form flows cost
# far more than the call, and inlined they doubled the loop's compile time.
INLINE_STEP = False


@njit(inline="always")
def prepare(kind, flags, drv, prm, h):
    """The step's propagators and the scratch arrays for the contact segments of a step."""
    return (step_propagators(prm, h), np.empty(MAX_SEGMENTS), np.empty(MAX_SEGMENTS, dtype=np.bool_))


@njit(inline="always")
def step(kind, flags, ctx, prm, drv, state, contact0, clock, plate, track_energy):
    # The step is h exactly (the propagator table's); the grid times' difference would
    # carry the rounding of large t.
    pz0, pv0, pzh, pvh, pz1, pv1, s1, c1, frame0, frame_half, frame1 = plate
    t, h, span = clock
    status, x, z, vx, vz, shear, d_phi, d_work, d_dissipated = implicit_contact_step(
        kind, prm, state, t, h, (pz0, pv0, pz1, pv1, frame_half), ctx, track_energy)
    contact1 = contact(kind, x, z, vx, vz, pz1, pv1, prm)
    # (the normal spring's energy is booked as its potential at observation time: no increment)
    return (status, x, z, vx, vz, shear, contact1, contact1[0], contact1[5], d_phi, d_work, d_dissipated, 0.0)
