"""``adaptive`` (id 4, every model and reading): error-controlled, stiff-stable steps with located events.

On model A, whose every regime is linear, the registry hands a run over to the exact flows
of ``event_driven`` instead (option ``exact_flows``, on by default; where event_driven
cannot run the reading or the parameters these steps run).  What follows is the method
of models B and C, and of model A with that option off.

Methods.  Two embedded pairs under one error control, chosen by stiffness.  Where the
motion is not stiff (ringing contact and friction springs, flights, slips: the tolerance
limits the step), DOP853: Dormand & Prince's explicit pair of order 8 with estimators of
orders 5 and 3 (Hairer, Norsett & Wanner, Solving ODEs I, Sec. II.10; scipy's tableau),
12 stages and the new state's rate, which is the next step's first.  Where its steps would
meet its stability bound (a long stick whose ringing has died, the block creeping at
~1e-8 delta_0/tau_0: an explicit step is held to h ~ 1 there), RODAS4 below.  A run starts
with one Jacobian and takes the explicit pair if its first step lies inside the bound for
every mode the contact can have (h max(||J||_inf, the fastest contact or friction-spring
rate) < EXPLICIT_CALM).  The explicit pair hands over to RODAS4 once h rho > EXPLICIT_STIFF
on STIFF_AFTER accepted steps (rho from its last two rates: Hairer's DOP853 test); RODAS4
hands back, at least STIFF_HOLD steps later, once its step is again inside the bound.
The ``jacobians`` counter counts RODAS4's linearisations.  Measured on the work-precision
benchmark's B and C scenarios (harness/benchmarks/work_precision.py) at rtol 1e-6: 2-17x
less time than RODAS4 alone (2.4x with 689 located resets in 300 tau_0, 17x on a ringing
stick), more at tighter tolerances.

RODAS4.  A Rosenbrock method of order 4 with an embedded order-3 estimate (RODAS4,
Hairer & Wanner, Solving ODEs II, Sec. IV.7: six stages, L-stable and stiffly
accurate, so a step far longer than the contact's and the friction spring's periods
damps what has rung down instead of amplifying it) on the state (x, z, vx, vz, F) and
the quadratures (phi, work, dissipation, normal-spring energy), which ride along as
extra components that feed nothing back.  Every step solves five linear systems with
one LU factorisation of (I/(h gamma) - J); J is the Jacobian of the forces on the
five-dimensional state by central differences (so any variant or formulation that
``dynamics`` computes is differentiated the same way), and the explicit time
dependence (plate, drive's far end) enters through a difference quotient in t.  The
step is accepted when the weighted RMS of the embedded error over the five state
components is <= 1 (weights atol + rtol max(|y0|, |y1|)); the next step is
h 0.9 err^(-1/4) (DOP853: err^(-1/8)), within [0.2, 6] h.  While the plate moves harmonically a step spans
at most CYCLE_FRACTION of its period, so no landing or grazing contact is stepped over
unseen; a long stick without vibration is crossed in steps growing sixfold each.  The
one exception is a flight above the plate's reach (the block higher than the plate at its
highest, the external input at rest): no phase of the plate can meet the block there, so a
step may span up to REACH_SHARE of the time a quadratic model of that clearance gives
until the block could be within the reach again.  Such a step is kept only if the
clearance stays positive at its interpolant's samples and its end; else it is retaken at
the cap, which then holds until the flight's landing.  A block launched high (the paper's
Fig. 5 above the onset) thus crosses its flights in tens of steps instead of 16 a period.

Dense output.  Each RODAS4 step carries its third-order interpolant (from stages 1-5), each
DOP853 step the cubic Hermite interpolant of its end values and rates; both serve only to
sample the event values, the switches being refined on full steps.

Regimes and events (N: the contact force k_n delta - gamma_n u_n, continued across
delta = 0 within a contact phase; B = mu_s N, the Coulomb bound):

==========  ===========================  =====================================
regime      event (value crosses 0)      after the event
==========  ===========================  =====================================
flight      delta rises through 0        contact: loaded if B > 0, else held
loaded      delta falls through 0        flight, F = 0 (k_t F^2/2 dissipated)
            B - k_t F or B + k_t F       Coulomb reset: F = 0, counted if F != 0;
            falls through 0              loaded if B > 0, else held
held        delta falls through 0        flight
(F = 0)     B rises through 0            loaded (F restarts from 0)
cascade     delta falls through 0        flight
(F = 0)     B falls through 0            held
==========  ===========================  =====================================

A reset that follows the previous one within CASCADE_GAP ends in the cascade regime
(the dashpot pulling the block out makes resets accumulate at the zero of N; the
spring is held at zero from there until N has crossed zero, the cascade's limit).

Location.  After an accepted step, the event values are checked on its interpolant at
EVENT_SAMPLES points; in the first sub-interval where one changes sign, the earliest
root of the interpolant is the first guess, and the switch time is then refined by
regula falsi (Illinois) on full steps of the method in use from the step's start, until the
bracket is shorter than EVENT_TOL.  The state is restarted from the far end of that
bracket -- the full-order step to within EVENT_TOL after the true zero, on the far side
-- and the reset rule is applied there, not at a step's end.

Readings (docs/physics.md; compile-time bits of ``kind``, so the default reading's
kernels do the arithmetic they did before the others were covered).  The tangent frame
moves the position slots at ``position_rates`` (dx/dt = u cos a, d zeta/dt = w) and phi
integrates (dx/dt - V_d)^2 with that dx/dt; its contact, forces and energy rates are
``dynamics``'s.  The Coulomb bound's N is ``coulomb_bound`` of the continued contact
force, at the block's x and the time of the value (the applied load depends on both, so
every event value is evaluated at its own time).  Free flight: ``dynamics.contact`` hands
the forces the fixed axes and N = 0 at delta <= 0, a switch of frame at delta = 0.
Inside a regime whose force is continued across delta = 0 that switch would be a kink
(a jump of u_t, of the dashpot's and the load's directions) in the right-hand side that
the Jacobian, the error estimate and the full steps of the event search straddle: the
located landing or detachment would be where the step crossed the kink, not where delta
crosses zero.  So each regime keeps one frame on both sides of delta = 0: the contact
regimes the surface's (``dynamics.surface_contact``), the flight regime the fixed axes
(u_t = vx, cos a = 1, sin a = 0); the frame switches only at the located event, with the
regime.  The tangent frame with free flight is refused for every integrator (no position
in the plane, docs/physics.md Sec. 6).

Stroboscopic jumps.  While the block is held (regime loaded) on a plate that moves
harmonically, whole plate periods are taken many at a time through the period map's
affine model, with error control per period crossed and a hand-back to resolved steps
before any switch (the section "stroboscopic jumps" below; ``max_jump`` bounds a jump,
below STROBE_MIN it turns them off; ``cnt[C_JUMPED]`` counts the periods crossed).

Grid.  As ``event_driven``: dt only sets the grid on which the state is stored; a call
integrates from t0 + n dt to t0 + (n + n_steps) dt.  Splits agree to the tolerances
(the step sequence depends on where a run stops), not bit for bit.
"""
import math

import numpy as np
from .. import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ..dynamics import contact, coulomb_bound, energy_rates, force, plate_motion, position_rates, surface_contact
from ..laws import contact_force
from .fixed_step import kahan_add, record_observation
from .plate import TWO_PI, drive_phase
from ..layout import (C_ACCEPTED, C_EVENTS, C_JACOBIANS, C_JUMPED, C_REJECTED, C_SLIPS, C_STEP,
                      D_AMP, D_DT, D_EXT_A, D_EXT_T, D_EXT_V, D_EXT_Z, D_OMEGA, D_T0, N_OBS, P_ATOL, P_GN,
                      P_GT, P_KD, P_KN, P_KT, P_M, P_MAX_JUMP, P_MUS, P_RTOL, P_VD, Y_DISSIPATED, Y_E_NORMAL, Y_F,
                      Y_PHI, Y_PHI_C, Y_VX, Y_VZ, Y_WORK, Y_X, Y_Z)
from ..readings import free_flight
from scipy.integrate._ivp import dop853_coefficients as _DOP853

# Statuses (negative: failure, the arrays untouched).
OK = 0
NON_FINITE = -1
STEP_TOO_SMALL = -2
TOO_MANY_STEPS = -3
TOO_MANY_EVENTS = -4

# Largest step while the plate moves harmonically, as a fraction of its period.
CYCLE_FRACTION = 1.0 / 16.0
# A flight above the plate's reach (the block higher than the plate at its highest) may
# step past that cap, up to this share of the time its clearance model gives until the
# block could first be within the reach again (see ``_reach_time``).
REACH_SHARE = 0.5
# Points of each step's interpolant at which the event values are checked.
EVENT_SAMPLES = 4
# Switch times are located to this (tau_0) after the true zero.
EVENT_TOL = 1e-12
# Resets closer together than this (tau_0) are the accumulation before a zero of N.
CASCADE_GAP = 1e-9
# Internal steps (accepted + rejected) one call may take: ~20-30 s on one core.
MAX_STEPS = 1 << 24
# Events in a row without the time moving by more than EVENT_TOL before the run stops.
MAX_IMMEDIATE = 64
# A call moves the plate's clock (``_clock``) to its local time at least every
# REBASE_CYCLES plate periods, so omega u stays below ~400 rad (rounding ~6e-14 rad).
REBASE_CYCLES = 64
# Step-size control.
SAFETY, GROW, SHRINK = 0.9, 6.0, 0.2
# Leaps across the error estimate's hump: a lightly damped mode (the friction spring
# rings for 2m/gamma_t ~ 1e4) whose amplitude the local errors keep at the tolerance
# makes the estimate grow with h while h |lambda| ~ 1-1000 and vanish beyond (both
# embedded solutions damp it).  After LEAP_AFTER accepted steps in a row that could not
# grow, a step LEAP times longer is tried; it is kept only if its own error estimate
# passes (else it counts as rejected).
LEAP_AFTER, LEAP = 8, 1e4

# Regimes.
FLIGHT, LOADED, HELD, CASCADE = 0, 1, 2, 3
# Events.
EV_NONE, EV_CONTACT, EV_DETACH, EV_RESET_PLUS, EV_RESET_MINUS, EV_REARM, EV_HOLD = range(7)

# State vector of the integration: the five state components, then the quadratures.
NS = 5
NQ = 4
NV = NS + NQ

# RODAS4 (Hairer & Wanner, Sec. IV.7, Table 7.3): the transformed stages
# (I/(h gamma) - J) k_i = f(t + c_i h, y + sum a_ij k_j) + sum (c_ij / h) k_j + h d_i f_t.
GAMMA = 0.25
STAGE_C = np.array([0.0, 0.386, 0.21, 0.63, 1.0, 1.0])
STAGE_D = np.array([0.25, -0.1043, 0.1035, -0.0362, 0.0, 0.0])
STAGE_A = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [1.544, 0.0, 0.0, 0.0, 0.0],
    [0.9466785280815826, 0.2557011698983284, 0.0, 0.0, 0.0],
    [3.314825187068521, 2.896124015972201, 0.9986419139977817, 0.0, 0.0],
    [1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950, 0.0],
    [1.221224509226641, 6.019134481288629, 12.53708332932087, -0.6878860361058950, 1.0]])
STAGE_CC = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [-5.6688, 0.0, 0.0, 0.0, 0.0],
    [-2.430093356833875, -0.2063599157091915, 0.0, 0.0, 0.0],
    [-0.1073529058151375, -9.594562251023355, -20.47028614809616, 0.0, 0.0],
    [7.496443313967647, -10.24680431464352, -33.99990352819905, 11.70890893206160, 0.0],
    [8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136, -6.058818238834054]])
# Dense output y(s) = (1 - s) y0 + s (y1 + (1 - s) (w2 + s w3)), w_r = sum_j DENSE[r, j] k_j.
DENSE = np.array([
    [10.12623508344586, -7.487995877610167, -34.80091861555747, -7.992771707568823, 1.025137723295662],
    [-0.6762803392801253, 6.087714651680015, 16.43084320892478, 24.76722511418386, -6.594389125716872]])

EPS = 2.220446049250313e-16
JAC_STEP = 1e-5  # relative increment of the central differences (~eps^(1/3))

# DOP853 (Dormand & Prince's explicit pair of order 8 with error estimators of orders 5
# and 3; Hairer, Norsett & Wanner, Solving ODEs I, Sec. II.10), the tableau as scipy
# ships it: 12 stages, the 13th rate f(t + h, y1) serving the error estimate, the step's
# Hermite interpolant and the next step's first stage.
EXPLICIT_STAGES = 12
EXPLICIT_A = np.ascontiguousarray(_DOP853.A[:EXPLICIT_STAGES, :EXPLICIT_STAGES])
EXPLICIT_B = np.ascontiguousarray(_DOP853.B)
EXPLICIT_C = np.ascontiguousarray(_DOP853.C[:EXPLICIT_STAGES])
EXPLICIT_E5 = np.ascontiguousarray(_DOP853.E5)
EXPLICIT_E3 = np.ascontiguousarray(_DOP853.E3)
# Where the motion is not stiff (ringing contact and friction springs, flights, slips:
# the step is limited by accuracy, not stability) the explicit pair takes the steps: its
# eighth order needs several times fewer steps than RODAS4 at rtol <= 1e-6, and a step
# costs 13 rates instead of 17 rates and an LU.  It hands over to RODAS4 when its steps
# meet its stability bound (h |lambda| ~ 6 on the negative axis): h rho > EXPLICIT_STIFF
# on STIFF_AFTER accepted steps (rho estimated from the last two rates, as Hairer's
# DOP853 does); RODAS4 hands back once its steps are short enough for the explicit pair,
# h ||J||_inf < EXPLICIT_CALM, and at least STIFF_HOLD steps after the last hand-over.
EXPLICIT_STIFF = 6.1
STIFF_AFTER = 15
STIFF_FORGET = 6  # non-stiff steps in a row that clear the count of stiff ones (as DOP853)
EXPLICIT_CALM = 1.0
STIFF_HOLD = 32


# --------------------------------------------------------------------------- physics
@njit(inline="always")
def _clock(drv, cnt, n0):
    """The plate's clock at grid step n0: (its phase in [0, 2 pi), the external input's
    time).  A call reads the plate from local times u after its clock's origin,
    phase + omega u: the sum rounds to ~1e-16 of omega u, where omega (t + u) at t ~ 1e9
    would round to ~1e-7 rad and put the plate ~1e-8 off between replays of a period
    (the stroboscopic jumps' check refused every jump there)."""
    clk = np.empty(2)
    clk[0] = drive_phase(drv, cnt, n0)
    clk[1] = (drv[D_T0] - drv[D_EXT_T]) + n0 * drv[D_DT]
    return clk


@njit(inline="always")
def _advance_clock(drv, clk, du, whole_periods):
    """Move the clock's origin by du: its phase by omega du (reduced), or not at all when
    du spans whole plate periods (a stroboscopic jump: the plate is where it was, exactly,
    so that the periods replayed after the jump see the same plate as the one recorded)."""
    if not whole_periods:
        phase = clk[0] + drv[D_OMEGA] * du
        clk[0] = phase - TWO_PI * math.floor(phase / TWO_PI)
    clk[1] += du


@njit(inline="always")
def _moved_origin(shift, t_base, done, u_end, last_reset):
    """The call's local times after its origin moves forward by ``shift`` (the local
    time u there becomes 0): the origin's absolute time, the time covered before it, the
    call's end and the last reset, in that order."""
    return t_base + shift, done + shift, u_end - shift, last_reset - shift


@njit(inline="always")
def _plate(drv, clk, u):
    """Plate height and velocity at local time u after the clock's origin (``_clock``)."""
    phase = clk[0] + drv[D_OMEGA] * u
    return plate_motion(drv[D_AMP], drv[D_OMEGA], math.sin(phase), math.cos(phase), drv[D_EXT_Z], drv[D_EXT_V],
                        drv[D_EXT_A], clk[1] + u)


@njit(inline="always")
def _rhs(kind, regime, v, t, pz, pv, prm, track_energy, out):
    """Rates of the state and the quadratures in one regime.  Within a contact phase the
    normal force k_n delta - gamma_n u_n is continued across delta = 0 (the event, not the
    force, ends the phase), so a step may straddle a switch smoothly.  Each regime keeps
    one frame on both sides of delta = 0 for the same reason: a contact phase the surface's
    (``surface_contact``), a flight with ``flight = free`` the fixed axes."""
    x, z, vx, vz = v[0], v[1], v[2], v[3]
    shear = v[4] if regime == LOADED else 0.0
    pen, u_n, u_t, cos_a, sin_a, normal = surface_contact(kind, x, z, vx, vz, pz, pv, prm)
    if regime == FLIGHT:
        normal = 0.0
        gate = -1.0
        if free_flight(kind):  # a free particle: the fixed axes are its frame (dynamics.contact)
            u_t, cos_a, sin_a = vx, 1.0, 0.0
    else:
        normal = contact_force(kind, pen, u_n, prm)  # continued across delta = 0
        gate = 1.0
    fx, fz = force(kind, x, t, gate > 0.0, pen, normal, u_t, cos_a, sin_a, shear, prm)
    inv_m = 1.0 / prm[P_M]
    rate_x, rate_z = position_rates(kind, vx, vz, cos_a)  # (vx, vz); (u cos a, w) in the tangent frame
    out[0], out[1], out[2], out[3] = rate_x, rate_z, fx * inv_m, fz * inv_m
    out[4] = u_t if regime == LOADED else 0.0
    drift = rate_x - prm[P_VD]
    out[5] = drift * drift
    if track_energy:
        # The rates are gated on delta > 0; within a contact phase they are continued like
        # the force: gate open, and the normal spring's power, which is linear in delta,
        # scaled from delta = 1 (so that the quadratures' rows of the Jacobian have no kink).
        work, dissipation, storage = energy_rates(kind, x, vx, vz, t, gate, u_n, u_t, cos_a, sin_a, normal, shear,
                                                  pv, prm)
        out[6], out[7], out[8] = work, dissipation, storage * pen if regime != FLIGHT else 0.0
    else:
        out[6] = out[7] = out[8] = 0.0


@njit(inline="always")
def _bound(kind, v, t, pz, pv, prm):
    """Penetration and the Coulomb bound mu_s N at time t: N the contact force continued
    across delta = 0, or the applied load at the block's x and t (``coulomb_bound``)."""
    pen, u_n, u_t, cos_a, sin_a, normal = surface_contact(kind, v[0], v[1], v[2], v[3], pz, pv, prm)
    return pen, prm[P_MUS] * coulomb_bound(kind, contact_force(kind, pen, u_n, prm), v[0], t, prm)


@njit(inline="always")
def _event_value(event, pen, bound, spring):
    """Positive before the switch, negative once it has happened."""
    if event == EV_CONTACT:
        return -pen
    if event == EV_DETACH:
        return pen
    if event == EV_RESET_PLUS:
        return bound - spring
    if event == EV_RESET_MINUS:
        return bound + spring
    if event == EV_REARM:
        return -bound
    return bound  # EV_HOLD


@njit(inline="always")
def _events_of(regime):
    """The events a regime watches: (first, count) in the order contact/detach, resets, N."""
    if regime == FLIGHT:
        return EV_CONTACT, 1
    if regime == LOADED:
        return EV_DETACH, 3
    return EV_DETACH, 2


@njit(inline="always")
def _event_at(regime, i):
    if regime == FLIGHT:
        return EV_CONTACT
    if i == 0:
        return EV_DETACH
    if regime == LOADED:
        return EV_RESET_PLUS if i == 1 else EV_RESET_MINUS
    return EV_REARM if regime == HELD else EV_HOLD


@njit(inline="always")
def _value(kind, regime, i, v, t, pz, pv, prm):
    pen, bound = _bound(kind, v, t, pz, pv, prm)
    return _event_value(_event_at(regime, i), pen, bound, prm[P_KT] * v[4])


@njit(inline="always")
def _clearance(kind, v, top, prm):
    """The block's height above the plate at its highest (-delta with the plate at ``top``):
    where it is positive, no phase of the plate reaches the block (delta grows with the
    plate's height in either frame, since cos a > 0)."""
    pen = surface_contact(kind, v[0], v[1], v[2], v[3], top, 0.0, prm)[0]
    return -pen


@njit(inline="always")
def _reach_time(kind, v, f0, top, tau, probe, prm):
    """Time until a block in flight could first be within the plate's reach: the first
    zero of a quadratic model of its clearance (value, rate and curvature by central
    differences along the position's Taylor path over +-tau; in the tangent frame the
    abscissa's acceleration is taken as u').  0 if the block is within reach now, inf if
    the model never comes back to zero.  A model, not a bound: the step that uses it is
    checked on its samples (``_evolve``)."""
    g0 = _clearance(kind, v, top, prm)
    if not g0 > 0.0:
        return 0.0
    for i in range(NS):
        probe[i] = v[i]
    half = 0.5 * tau * tau
    probe[0] = v[0] + tau * f0[0] + half * f0[2]
    probe[1] = v[1] + tau * f0[1] + half * f0[3]
    g_plus = _clearance(kind, probe, top, prm)
    probe[0] = v[0] - tau * f0[0] + half * f0[2]
    probe[1] = v[1] - tau * f0[1] + half * f0[3]
    g_minus = _clearance(kind, probe, top, prm)
    g1 = (g_plus - g_minus) / (2.0 * tau)
    g2 = (g_plus - 2.0 * g0 + g_minus) / (tau * tau)
    # g0 + g1 t + g2 t^2 / 2 = 0: its smallest positive root, in the form free of cancellation.
    disc = g1 * g1 - 2.0 * g2 * g0
    if not disc >= 0.0:
        return math.inf
    denominator = -g1 + math.sqrt(disc)
    if not denominator > 0.0:
        return math.inf
    return 2.0 * g0 / denominator


# --------------------------------------------------------------------------- linear algebra
@njit(inline="always")
def _factor(jac, c, lu, piv):
    """LU (partial pivoting) of c I - J on the state block; False if singular."""
    for i in range(NS):
        for j in range(NS):
            lu[i, j] = -jac[i, j]
        lu[i, i] += c
    for k in range(NS):
        p = k
        best = abs(lu[k, k])
        for i in range(k + 1, NS):
            if abs(lu[i, k]) > best:
                best, p = abs(lu[i, k]), i
        piv[k] = p
        if best == 0.0 or not math.isfinite(best):
            return False
        if p != k:
            for j in range(NS):
                lu[k, j], lu[p, j] = lu[p, j], lu[k, j]
        inv = 1.0 / lu[k, k]
        for i in range(k + 1, NS):
            lu[i, k] *= inv
            f = lu[i, k]
            for j in range(k + 1, NS):
                lu[i, j] -= f * lu[k, j]
    return True


@njit(inline="always")
def _solve(jac, c, lu, piv, r):
    """Solve (c I - J) k = r in place; the quadrature rows follow from the state's
    (their columns of J are zero).  ``_factor`` swaps whole rows, multipliers included,
    so r takes all the interchanges before the forward substitution (interleaving them
    would pair a row's value with another row's multipliers after a later swap)."""
    for k in range(NS):
        p = piv[k]
        if p != k:
            r[k], r[p] = r[p], r[k]
    for k in range(NS):
        for i in range(k + 1, NS):
            r[i] -= lu[i, k] * r[k]
    for k in range(NS - 1, -1, -1):
        s = r[k]
        for j in range(k + 1, NS):
            s -= lu[k, j] * r[j]
        r[k] = s / lu[k, k]
    inv_c = 1.0 / c
    for i in range(NS, NV):
        s = r[i]
        for j in range(NS):
            s += jac[i, j] * r[j]
        r[i] = s * inv_c


# --------------------------------------------------------------------------- one step
# _linearise and _rosenbrock are compiled functions of their own, called from _evolve
# rather than inlined (_rosenbrock has four call sites): the same arithmetic, their code
# once per kind, and about a quarter of the compile time of each kind's kernels.
@njit(cache=True)
def _linearise(kind, regime, v, t_abs, drv, clk, u, prm, track_energy, f0, jac, ft, work):
    """f at the step's start, its Jacobian on the state block (central differences) and
    its explicit time derivative (a difference quotient over an exactly representable
    increment)."""
    pz, pv = _plate(drv, clk, u)
    _rhs(kind, regime, v, t_abs, pz, pv, prm, track_energy, f0)
    probe = work[0]
    plus, minus = work[1], work[2]
    for i in range(NV):
        probe[i] = v[i]
    for j in range(NS):
        step = JAC_STEP * max(1.0, abs(v[j]))
        probe[j] = v[j] + step
        up = probe[j] - v[j]
        _rhs(kind, regime, probe, t_abs, pz, pv, prm, track_energy, plus)
        probe[j] = v[j] - step
        down = v[j] - probe[j]
        _rhs(kind, regime, probe, t_abs, pz, pv, prm, track_energy, minus)
        probe[j] = v[j]
        inv = 1.0 / (up + down)
        for i in range(NV):
            jac[i, j] = (plus[i] - minus[i]) * inv
    # time: the increment is what t_abs + dt_probe - t_abs really is
    scale = 1.0
    if drv[D_OMEGA] > 0.0 and drv[D_AMP] != 0.0:
        scale = min(1.0, 1.0 / drv[D_OMEGA])
    dt_probe = max(1e-3 * scale, 64.0 * EPS * abs(t_abs))
    t_up = t_abs + dt_probe
    t_down = t_abs - dt_probe
    span = t_up - t_down
    pz1, pv1 = _plate(drv, clk, u + (t_up - t_abs))
    _rhs(kind, regime, v, t_up, pz1, pv1, prm, track_energy, plus)
    pz0, pv0 = _plate(drv, clk, u - (t_abs - t_down))
    _rhs(kind, regime, v, t_down, pz0, pv0, prm, track_energy, minus)
    inv = 1.0 / span
    for i in range(NV):
        ft[i] = (plus[i] - minus[i]) * inv


@njit(cache=True)
def _rosenbrock(kind, regime, v, t_abs, drv, clk, u, h, prm, track_energy, f0, jac, ft, lu, piv, k, stage,
                rate, out):
    """One RODAS4 step of length h from v (quadratures of v are 0): fills ``out`` with the
    new state and the quadrature increments and ``k`` with the stages; returns the
    weighted RMS error of the state (inf if the matrix is singular)."""
    c = 1.0 / (h * GAMMA)
    if not _factor(jac, c, lu, piv):
        return math.inf
    for s in range(6):
        if s == 0:
            for i in range(NV):
                rate[i] = f0[i]
        else:
            for i in range(NV):
                acc = v[i]
                for j in range(s):
                    acc += STAGE_A[s, j] * k[j, i]
                stage[i] = acc
            pz, pv = _plate(drv, clk, u + STAGE_C[s] * h)
            _rhs(kind, regime, stage, t_abs + STAGE_C[s] * h, pz, pv, prm, track_energy, rate)
        inv_h = 1.0 / h
        for i in range(NV):
            acc = rate[i] + h * STAGE_D[s] * ft[i]
            for j in range(s):
                acc += STAGE_CC[s, j] * inv_h * k[j, i]
            k[s, i] = acc
        _solve(jac, c, lu, piv, k[s])
    err = 0.0
    for i in range(NV):
        out[i] = stage[i] + k[5, i]  # stiffly accurate: the last stage's argument plus k6
    rtol, atol = prm[P_RTOL], prm[P_ATOL]
    for i in range(NS):
        weight = atol + rtol * max(abs(v[i]), abs(out[i]))
        e = k[5, i] / weight
        err += e * e
    err = math.sqrt(err / NS)
    if not math.isfinite(err):
        return math.inf
    return err


@njit(inline="always")
def _dense(v, out, k, s, res):
    """The step's interpolant at fraction s of the step (state components)."""
    for i in range(NS):
        w2 = 0.0
        w3 = 0.0
        for j in range(5):
            w2 += DENSE[0, j] * k[j, i]
            w3 += DENSE[1, j] * k[j, i]
        res[i] = (1.0 - s) * v[i] + s * (out[i] + (1.0 - s) * (w2 + s * w3))


@njit(cache=True)
def _explicit(kind, regime, v, t_abs, drv, clk, u, h, prm, track_energy, f0, kx, stage, out):
    """One DOP853 step of length h from v (quadratures of v are 0; f0 the rate at v):
    fills ``out`` with the new state and the quadrature increments, ``kx`` with the 12
    stages and the rate at the new state, ``stage`` with the last stage's argument;
    returns the weighted RMS error of the state (the two estimators combined as in DOP853)."""
    for i in range(NV):
        kx[0, i] = f0[i]
    for s in range(1, EXPLICIT_STAGES):
        for i in range(NV):
            acc = 0.0
            for j in range(s):
                acc += EXPLICIT_A[s, j] * kx[j, i]
            stage[i] = v[i] + h * acc
        pz, pv = _plate(drv, clk, u + EXPLICIT_C[s] * h)
        _rhs(kind, regime, stage, t_abs + EXPLICIT_C[s] * h, pz, pv, prm, track_energy, kx[s])
    for i in range(NV):
        acc = 0.0
        for j in range(EXPLICIT_STAGES):
            acc += EXPLICIT_B[j] * kx[j, i]
        out[i] = v[i] + h * acc
    pz, pv = _plate(drv, clk, u + h)
    _rhs(kind, regime, out, t_abs + h, pz, pv, prm, track_energy, kx[EXPLICIT_STAGES])
    rtol, atol = prm[P_RTOL], prm[P_ATOL]
    err5 = err3 = 0.0
    for i in range(NS):
        e5 = e3 = 0.0
        for j in range(EXPLICIT_STAGES + 1):
            e5 += EXPLICIT_E5[j] * kx[j, i]
            e3 += EXPLICIT_E3[j] * kx[j, i]
        weight = atol + rtol * max(abs(v[i]), abs(out[i]))
        err5 += (e5 / weight) ** 2
        err3 += (e3 / weight) ** 2
    if err5 == 0.0 and err3 == 0.0:
        return 0.0
    err = abs(h) * err5 / math.sqrt((err5 + 0.01 * err3) * NS)
    if not math.isfinite(err):
        return math.inf
    return err


@njit(inline="always")
def _explicit_stiffness(h, kx, stage, out):
    """h rho with rho ~ |f(y1) - f(y12)| / |y1 - y12| over the state (DOP853's test)."""
    num = den = 0.0
    for i in range(NS):
        num += (kx[EXPLICIT_STAGES, i] - kx[EXPLICIT_STAGES - 1, i]) ** 2
        den += (out[i] - stage[i]) ** 2
    return h * math.sqrt(num / den) if den > 0.0 else 0.0


@njit(inline="always")
def _jacobian_norm(jac):
    """||J||_inf on the state block: a bound of the spectral radius."""
    norm = 0.0
    for i in range(NS):
        row = 0.0
        for j in range(NS):
            row += abs(jac[i, j])
        norm = max(norm, row)
    return norm


@njit(inline="always")
def _mode_rate(k, gamma, m):
    """The largest |lambda| of m s^2 + gamma s + k."""
    disc = gamma * gamma - 4.0 * k * m
    if disc >= 0.0:
        return (gamma + math.sqrt(disc)) / (2.0 * m)
    return math.sqrt(k / m)


@njit(inline="always")
def _stiffest_rate(prm):
    """The fastest rate of the contact's and the friction spring's modes: the explicit pair
    is chosen only for steps inside its bound for them, whatever the regime (a step taken
    in flight would otherwise meet them at the next landing, where the explicit pair can
    only resolve what RODAS4 steps across)."""
    m = prm[P_M]
    return max(_mode_rate(prm[P_KN], prm[P_GN], m), _mode_rate(prm[P_KT], prm[P_GT], m))


@njit(inline="always")
def _interpolate(explicit, v, out, k, kx, h, s, res):
    """The step's interpolant at fraction s (state components): RODAS4's own, or for the
    explicit pair the cubic Hermite of its end values and rates (event values are only
    sampled on it; switches are refined on full steps)."""
    if explicit:
        s2 = s * s
        s3 = s2 * s
        a0, a1 = 2.0 * s3 - 3.0 * s2 + 1.0, -2.0 * s3 + 3.0 * s2
        b0, b1 = h * (s3 - 2.0 * s2 + s), h * (s3 - s2)
        for i in range(NS):
            res[i] = a0 * v[i] + a1 * out[i] + b0 * kx[0, i] + b1 * kx[EXPLICIT_STAGES, i]
    else:
        _dense(v, out, k, s, res)


@njit(inline="always")
def _control_exponent(explicit):
    """The step control's exponent, -1 / (order of the error estimate + 1)."""
    return -0.125 if explicit else -0.25


@njit(inline="always")
def _step(explicit, kind, regime, v, t_abs, drv, clk, u, h, prm, track_energy, f0, jac, ft, lu, piv, k, kx,
          stage, rate, out):
    """One step of the method in use; its weighted RMS error."""
    if explicit:
        return _explicit(kind, regime, v, t_abs, drv, clk, u, h, prm, track_energy, f0, kx, stage, out)
    return _rosenbrock(kind, regime, v, t_abs, drv, clk, u, h, prm, track_energy, f0, jac, ft, lu, piv, k, stage,
                       rate, out)


# --------------------------------------------------------------------------- stroboscopic jumps
# A block held by friction on a harmonically vibrating plate settles on an orbit that
# repeats every plate period while the slow variables (the spring's stretch, the
# tangential spring, the position along the corrugation) creep: at the paper's
# parameters a stick lasts 1e7-1e9 periods, and resolving each costs ~16-30 steps.  The
# map over one period, P(y, D) (D the drive's far end, V_d t), is then nearly affine: the
# contact and spring forces are linear in the state, only the surface's slope moves with
# x, and that by little per period.  So from y_0 the periods are taken K at a time:
#   delta_{n+1} = M delta_n + r + n q,   delta_n = y_n - y_0,
# with r = P(y_0, D_0) - y_0 from one resolved period (whose step sequence is recorded),
# M = dP/dy and q = V_d T dP/dD from replays of that sequence on perturbed starts (finite
# differences that share every step, so they carry no step-selection noise).  Ringing
# modes that have not died are carried exactly by M^n (they are linear); K periods cost
# log2(K) products of 11 x 11 matrices.  The quadratures (phi, energies) are quadratic
# in the velocities: the linear model sums their per-period increments to first order
# in delta, and as the state drifts (delta_n ~ n d) the true increment leaves it by
# rho(n) ~ c n^2.  That second-order term is measured, not neglected: c from the period
# the jump lands on, the sum corrected by c (K-1) K (2K-1) / 6.  Without it the jumps
# along a paper-parameter stick shrank to a few hundred periods as the block crept off a
# crest, bounded by phi alone (model C held at a crest, tangent frame, omega = 0.1,
# A = A_c/3, rtol 1e-6: 3.2e6 plate periods in 1.1e7 steps; 1.0e6 with it).
#
# Error control.  The state a jump lands on is checked by replaying the same step
# sequence from it: the increment of that period against the linear model's prediction
# must stay within rtol/atol (error per period crossed), else the jump is retaken
# shorter.  phi is checked halfway: the period there is replayed too, and its residual
# must be the c (K/2)^2 of the quadratic law within rtol of a period's increment -- a
# ringing that the jump carries linearly breaks that law first.  The landing's replay is
# the next jump's resolved period, and a model that passed is kept for the next jump
# (its error, should the state have drifted too far for it, is the next check's).
# Events: each event value's minimum over the resolved periods (its margin) is watched; a
# jump may use up at most STROBE_MARGIN of any margin at the rate the last jump showed,
# and a period whose replay (halfway or at the landing) meets an event, or a jump allowed
# fewer than STROBE_MIN periods, hands back to resolved stepping, which locates the switch
# on its own step.  (Envelope following, as for circuits driven by a fast periodic source.)
STROBE_MIN = 4          # fewest periods a jump spans
STROBE_FIRST = 8        # the first jump of a session, before a margin's rate is known
STROBE_GROW = 8.0       # largest growth of the jump from one jump to the next
STROBE_MARGIN = 0.5     # largest fraction of an event's margin one jump may use up
STROBE_STEPS = 2048     # steps the recorded period may hold
STROBE_KEEP = 1.0       # a model whose jump passed within this fraction of the tolerance is kept
STROBE_WAIT = 2         # periods of resolved stepping before the next try, doubled after each failed try
STROBE_WAIT_MAX = 1024
# What a try costs and when it may pay.  A try replays ~STROBE_TRY periods (the recorded
# one, two per state column and for the pull, the landing and the halfway check) for a
# first jump of STROBE_FIRST, so it pays only where the longer jumps that reuse its model
# have room: a call tries only while STROBE_PAYBACK periods remain, and only while its
# refused tries, this one counted, stay within STROBE_SHARE of the periods it has advanced
# (the first try after 32 periods).  So a run whose tries are all refused (a ringing
# spring) pays at most that share, and a short call is resolved as with jumps off.
STROBE_TRY = 16
STROBE_PAYBACK = 32
STROBE_SHARE = 0.5
STROBE_EPS = 1e-6       # relative perturbation of the state's finite differences
STROBE_PULL = 1e-4      # change of the drive's pull (k_d times its far end's shift) of the drive's difference
NA = NV + 2             # affine model on (delta, quadratures, 1, n)


@njit(cache=True)
def _period(kind, regime, v0, t_abs, shift, drv, clk, period, cap, h_first, prm, track_energy, hs, n_hs,
            out, margins, scale, tally, f0, jac, ft, lu, piv, k, stage, rate, trial, probe, scratch, explicit, kx):
    """One plate period from v0 at the clock's origin (quadratures of v0 are 0): with
    n_hs = 0 by error-controlled steps whose lengths are recorded in hs, else by
    replaying hs[:n_hs].  ``shift`` moves
    the drive's far end (the time the forces see, not the plate's).  Writes the end state
    and the period's quadrature increments to ``out``, each event value's minimum over the
    step ends and interpolant samples to ``margins``, and each state component's largest
    magnitude at the step ends to ``scale`` (the orbit's size, for the error weights).
    Returns the number of steps, or -1 if an event value went negative or a step failed."""
    n_events = _events_of(regime)[1]
    for i in range(NV):
        out[i] = 0.0
        probe[i] = v0[i]
    pz, pv = _plate(drv, clk, 0.0)
    for e in range(n_events):
        margins[e] = _value(kind, regime, e, v0, t_abs + shift, pz, pv, prm)
        if margins[e] <= 0.0:
            return -1
    for i in range(NS):
        scale[i] = abs(v0[i])
    record = n_hs == 0
    local = 0.0
    h = min(h_first, cap, period)
    steps = 0
    while True:
        if record:
            if local >= period:
                break
            if steps >= STROBE_STEPS:
                return -1
            h = min(h, period - local)
        else:
            if steps >= n_hs:
                break
            h = hs[steps]
        if explicit:
            pz, pv = _plate(drv, clk, local)
            _rhs(kind, regime, probe, t_abs + shift + local, pz, pv, prm, track_energy, f0)
        else:
            _linearise(kind, regime, probe, t_abs + shift + local, drv, clk, local, prm, track_energy, f0,
                       jac, ft, scratch)
            tally[2] += 1
        err = _step(explicit, kind, regime, probe, t_abs + shift + local, drv, clk, local, h, prm,
                    track_energy, f0, jac, ft, lu, piv, k, kx, stage, rate, trial)
        exponent = _control_exponent(explicit)
        if record and not err <= 1.0:
            tally[1] += 1
            h *= SHRINK if not math.isfinite(err) else max(SHRINK, SAFETY * err ** exponent)
            if h <= 16.0 * EPS * max(1.0, abs(t_abs + local)):
                return -1
            continue
        if not math.isfinite(err):
            return -1
        tally[0] += 1
        for sample in range(1, EVENT_SAMPLES + 1):
            s = sample / EVENT_SAMPLES
            if sample == EVENT_SAMPLES:
                for i in range(NS):
                    scratch[0, i] = trial[i]
            else:
                _interpolate(explicit, probe, trial, k, kx, h, s, scratch[0])
            pz, pv = _plate(drv, clk, local + s * h)
            for e in range(n_events):
                g = _value(kind, regime, e, scratch[0], t_abs + shift + local + s * h, pz, pv, prm)
                if g <= 0.0:
                    return -1
                margins[e] = min(margins[e], g)
        for i in range(NS):
            probe[i] = trial[i]
            scale[i] = max(scale[i], abs(trial[i]))
        for i in range(NS, NV):
            out[i] += trial[i]
        local += h
        if record:
            hs[steps] = h
            h = min(h * min(GROW, max(SHRINK, SAFETY * (max(err, 1e-12) ** exponent))), cap)
        steps += 1
    for i in range(NS):
        out[i] = probe[i]
    return steps


@njit(cache=True)
def _affine_power(g, power, vec, sq, tmp):
    """vec <- g^power vec (binary powering; g is overwritten by its squares)."""
    while power > 0:
        if power & 1:
            for i in range(NA):
                acc = 0.0
                for j in range(NA):
                    acc += g[i, j] * vec[j]
                tmp[i] = acc
            for i in range(NA):
                vec[i] = tmp[i]
        power >>= 1
        if power == 0:
            break
        for i in range(NA):
            for j in range(NA):
                acc = 0.0
                for l in range(NA):
                    acc += g[i, l] * g[l, j]
                sq[i, j] = acc
        for i in range(NA):
            for j in range(NA):
                g[i, j] = sq[i, j]


@njit(inline="always")
def _apply_periods(g, periods, y0, vec, moved, work, sq, tmp):
    """The model's K periods from y0: vec <- g^K (0, 0, 1, 0) (state change, quadratures'
    sums, 1, K) and moved <- the state there (quadratures 0); work holds g's powers."""
    for i in range(NA):
        vec[i] = 0.0
        for j in range(NA):
            work[i, j] = g[i, j]
    vec[NV] = 1.0
    _affine_power(work, periods, vec, sq, tmp)
    for i in range(NS):
        moved[i] = y0[i] + vec[i]
    for i in range(NS, NV):
        moved[i] = 0.0


@njit(cache=True)
def _stroboscopic(kind, regime, v, t_base, drv, clk, u_end, period, cap, h_first, prm, track_energy, dq,
                  tally, f0, jac, ft, lu, piv, k, stage, rate, trial, probe, scratch, explicit, kx):
    """Take the plate periods from the clock's origin (time t_base) K at a time while the
    block stays in the ``regime`` (LOADED) without a switch (the section's comment
    above), up to local time u_end.  Moves v (state slots) and returns the time jumped
    (0 if no jump was taken); dq gets the quadratures' increments, tally (accepted,
    rejected, Jacobians, periods jumped) the costs.  Every period is replayed on the
    clock's phase (the jumps span whole periods), so the plate it sees is the recorded
    one to the bit."""
    n_events = _events_of(regime)[1]
    hs = np.empty(STROBE_STEPS)
    y0 = np.zeros(NV)
    base = np.zeros(NV)
    moved = np.zeros(NV)
    check = np.zeros(NV)
    cols = np.zeros((NS + 1, NV))
    margins = np.zeros(3)
    margins_moved = np.zeros(3)
    margins_before = np.zeros(3)
    scale = np.zeros(NS)
    scale_moved = np.zeros(NS)
    g = np.zeros((NA, NA))
    work = np.zeros((NA, NA))
    sq = np.zeros((NA, NA))
    vec = np.zeros(NA)
    tmp = np.zeros(NA)
    vec_mid = np.zeros(NA)
    moved_mid = np.zeros(NV)
    check_mid = np.zeros(NV)
    margins_mid = np.zeros(3)
    scale_mid = np.zeros(NS)
    curvature = np.zeros(4)
    at = np.empty(2)  # the clock of a replayed period's start
    u = 0.0
    for i in range(4):
        dq[i] = 0.0
    for i in range(NS):
        y0[i] = v[i]
    n_hs = _period(kind, regime, y0, t_base, 0.0, drv, clk, period, cap, h_first, prm, track_energy, hs,
                   0, base, margins, scale, tally, f0, jac, ft, lu, piv, k, stage, rate, trial, probe, scratch,
                   explicit, kx)
    if n_hs <= 0:
        return 0.0
    rtol, atol, vd = prm[P_RTOL], prm[P_ATOL], prm[P_VD]
    jump = float(STROBE_FIRST)
    last_jump = 0.0
    model_current = False  # cols hold dP/dy, dP/dD taken at this or an earlier y0
    model_fresh = False  # ... taken at this y0
    while True:
        t_abs = t_base + u
        at[0], at[1] = clk[0], clk[1] + u
        if model_current:
            model_fresh = False
        else:
            model_current = model_fresh = True
        # The linear model at y0: columns of dP/dy and dP/dD by replays of hs, central
        # differences (the slope's dependence on x makes one-sided ones biased).  They
        # change slowly along a stick, so a model that predicted the last landing well is
        # kept (only r = P(y0) - y0 is new, from the landing's replay).
        for j in range(NS if model_fresh else 0):
            for i in range(NV):
                cols[j, i] = 0.0
            step = STROBE_EPS * max(1.0, abs(y0[j]))
            for side in range(2):
                for i in range(NV):
                    moved[i] = y0[i]
                moved[j] = y0[j] + step if side == 0 else y0[j] - step
                if _period(kind, regime, moved, t_abs, 0.0, drv, at, period, cap, h_first, prm,
                           track_energy, hs, n_hs, check, margins_moved, scale_moved, tally, f0, jac, ft, lu, piv, k,
                           stage, rate, trial, probe, scratch, explicit, kx) < 0:
                    return u
                for i in range(NV):
                    if side == 0:
                        cols[j, i] = check[i]
                    else:
                        cols[j, i] = (cols[j, i] - check[i]) / (2.0 * step)
        for i in range(NV if model_fresh else 0):
            cols[NS, i] = 0.0
        if model_fresh and vd != 0.0 and prm[P_KD] > 0.0:
            # The pull is linear in the far end's position: a shift the finite difference
            # resolves far above the rounding of the positions (k_d is ~1e-6 at the paper's),
            # taken both ways so that the quadratures (quadratic in the velocities) lose
            # their second-order term.
            shift = STROBE_PULL / (prm[P_KD] * abs(vd))
            for side in range(2):
                sign = 1.0 if side == 0 else -1.0
                if _period(kind, regime, y0, t_abs, sign * shift, drv, at, period, cap, h_first, prm,
                           track_energy, hs, n_hs, check, margins_moved, scale_moved, tally, f0, jac, ft, lu, piv, k,
                           stage, rate, trial, probe, scratch, explicit, kx) < 0:
                    return u
                for i in range(NV):
                    cols[NS, i] += sign * check[i] * period / (2.0 * shift)  # per period of drive travel
        while True:
            # The jump's length: the call's end, and each margin at the rate the last jump used it up.
            room = math.floor((u_end - u) / period) - 1.0
            allowed = min(jump, room, math.floor(prm[P_MAX_JUMP]))
            if last_jump > 0.0:
                for e in range(n_events):
                    rate_e = (margins_before[e] - margins[e]) / last_jump
                    if rate_e > 0.0:
                        allowed = min(allowed, math.floor(STROBE_MARGIN * margins[e] / rate_e))
            if allowed < STROBE_MIN:
                return u
            count = int(allowed)
            # g: the one-period map of (delta, quadratures, 1, n).
            # delta' = M delta + r + n q; quadratures' = quadratures + (their rows of M) delta + r + n q
            for i in range(NA):
                for j in range(NA):
                    g[i, j] = 0.0
            for i in range(NV):
                for j in range(NS):
                    g[i, j] = cols[j, i]
                if i >= NS:
                    g[i, i] = 1.0
                g[i, NV] = base[i] - y0[i] if i < NS else base[i]
                g[i, NV + 1] = cols[NS, i]
            g[NV, NV] = 1.0
            g[NV + 1, NV] = 1.0
            g[NV + 1, NV + 1] = 1.0
            _apply_periods(g, count, y0, vec, moved, work, sq, tmp)
            ok = math.isfinite(vec[0] + vec[1] + vec[2] + vec[3] + vec[4] + vec[5])
            steps = -1
            if ok:
                at[1] = clk[1] + u + count * period
                steps = _period(kind, regime, moved, t_abs + count * period, 0.0, drv, at,
                                period, cap, h_first, prm, track_energy, hs, n_hs, check, margins_moved, scale_moved, tally, f0,
                                jac, ft, lu, piv, k, stage, rate, trial, probe, scratch, explicit, kx)
            if steps > 0:
                # The period halfway, replayed from the model's state there (quadratures' check).
                mid = count // 2
                _apply_periods(g, mid, y0, vec_mid, moved_mid, work, sq, tmp)
                at[1] = clk[1] + u + mid * period
                steps = _period(kind, regime, moved_mid, t_abs + mid * period, 0.0, drv, at,
                                period, cap, h_first, prm, track_energy, hs, n_hs, check_mid, margins_mid, scale_mid,
                                tally, f0, jac, ft, lu, piv, k, stage, rate, trial, probe, scratch, explicit, kx)
            err = math.inf
            if steps > 0:
                # The landed period's increment against the model's, r + (M - I) delta_K + K q,
                # within the tolerances: error per period crossed, as a resolved period's steps
                # are held to theirs (the rounding of the plate's phase and of the positions sets
                # a floor of ~1e-12 per period that no jump length can get under).
                err = 0.0
                for i in range(NS):
                    predicted = base[i] - y0[i] + cols[NS, i] * count
                    for j in range(NS):
                        predicted += (cols[j, i] - (1.0 if i == j else 0.0)) * vec[j]
                    weight = atol + rtol * max(abs(y0[i]), abs(moved[i]), scale[i])
                    e = (check[i] - moved[i] - predicted) / weight
                    err += e * e
                # The quadratures' second order (the section's comment): c from the landed
                # period; phi's residual halfway against c (K/2)^2, to rtol of a period's.
                for i in range(NS, NV):
                    at_end = base[i] + cols[NS, i] * count
                    for j in range(NS):
                        at_end += cols[j, i] * vec[j]
                    curvature[i - NS] = (check[i] - at_end) / (float(count) * count)
                at_mid = base[NS] + cols[NS, NS] * mid
                for j in range(NS):
                    at_mid += cols[j, NS] * vec_mid[j]
                e = ((check_mid[NS] - at_mid) - curvature[0] * float(mid) * mid) / (
                    rtol * (abs(base[NS]) + vd * vd * period) + 1e-300)
                err += e * e
                err = math.sqrt(err / (NS + 1))
            if err <= 1.0 or not model_fresh:
                break
            # Retake it shorter (the model at y0 stands); an event met right after the
            # jump may have happened within it.
            jump = count * (0.25 if not math.isfinite(err) else max(0.1, min(0.5, 0.8 * err ** -0.5)))
        if not err <= 1.0:
            model_current = False  # a kept model failed: take it afresh at y0 and try again
            continue
        # Accept: the landed state, and its replayed period as the next model's base.
        u += count * period
        tally[3] += count
        for i in range(NS):
            y0[i] = moved[i]
            v[i] = moved[i]
        kk = float(count)
        for i in range(4):
            dq[i] += vec[NS + i] + curvature[i] * (kk - 1.0) * kk * (2.0 * kk - 1.0) / 6.0
        for i in range(NV):
            base[i] = check[i]
        for e in range(n_events):
            margins_before[e] = margins[e]
            margins[e] = margins_moved[e]
        for i in range(NS):
            scale[i] = scale_moved[i]
        last_jump = float(count)
        jump = count * min(STROBE_GROW, max(1.0, 0.8 * max(err, 1e-12) ** -0.5))
        model_current = err <= STROBE_KEEP


# --------------------------------------------------------------------------- regimes
@njit(inline="always")
def _regime_after_contact(bound):
    return LOADED if bound > 0.0 else HELD


@njit(cache=True)
def _evolve(kind, y, cnt, drv, prm, n0, u_end, track_energy, out, costs):
    """Integrate from grid step n0 (state y) over local time u_end.  Writes the final state
    to ``out`` (layout of y), the slip count to costs[0] and the cost counters (accepted,
    rejected, events, Jacobians, periods jumped) to costs[1:6].  Returns OK or a negative status."""
    kt = prm[P_KT]
    half_kt = 0.5 * kt
    t_base = drv[D_T0] + n0 * drv[D_DT]  # the time at the clock's origin; local times u count from there
    clk = _clock(drv, cnt, n0)
    v = np.zeros(NV)
    v[0], v[1], v[2], v[3], v[4] = y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F]
    phi, phi_c = y[Y_PHI], y[Y_PHI_C]
    work_sum, dissipated, e_normal = y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL]
    slips = cnt[C_SLIPS]
    accepted = rejected = events = jacobians = 0
    jumped = 0

    f0 = np.zeros(NV)
    ft = np.zeros(NV)
    jac = np.zeros((NV, NS))
    lu = np.zeros((NS, NS))
    piv = np.zeros(NS, dtype=np.int64)
    k = np.zeros((6, NV))
    kx = np.zeros((EXPLICIT_STAGES + 1, NV))
    stage = np.zeros(NV)
    rate = np.zeros(NV)
    trial = np.zeros(NV)
    best = np.zeros(NV)
    probe = np.zeros(NV)
    scratch = np.zeros((3, NV))
    # The switch between the explicit pair and RODAS4 (see EXPLICIT_STIFF).
    stiff = calm = 0
    hold = 0

    # The regime of the stored state, with the friction rule applied to it.
    pz, pv = _plate(drv, clk, 0.0)
    pen, bound = _bound(kind, v, t_base, pz, pv, prm)
    if pen > 0.0:
        if abs(kt * v[4]) >= bound:
            if v[4] != 0.0:
                slips += 1
                dissipated += half_kt * v[4] * v[4]
            v[4] = 0.0
        regime = _regime_after_contact(bound)
    else:
        if v[4] != 0.0:
            dissipated += half_kt * v[4] * v[4]
            v[4] = 0.0
        regime = FLIGHT

    cap = math.inf
    if drv[D_OMEGA] > 0.0 and drv[D_AMP] != 0.0:
        cap = CYCLE_FRACTION * 2.0 * math.pi / drv[D_OMEGA]
    # Stroboscopic jumps need a plate that repeats: the harmonic drive, the external input at rest.
    period = 0.0
    if cap < math.inf and drv[D_EXT_V] == 0.0 and drv[D_EXT_A] == 0.0 and prm[P_MAX_JUMP] >= STROBE_MIN:
        period = 2.0 * math.pi / drv[D_OMEGA]
    # A flight above the plate's reach steps past the cap (REACH_SHARE): the plate's
    # highest point is known while it moves harmonically, the external input at rest.
    top = math.nan
    if cap < math.inf and drv[D_EXT_V] == 0.0 and drv[D_EXT_A] == 0.0:
        top = abs(drv[D_AMP]) + drv[D_EXT_Z]
    within_reach = False  # a step past the cap met the reach: capped until the next event
    strobe_next = 0.0
    done = 0.0  # the time covered before the clock's origin
    rebase_after = REBASE_CYCLES * 2.0 * math.pi / drv[D_OMEGA] if cap < math.inf else math.inf
    try_clk = np.empty(2)
    strobe_wait = STROBE_WAIT
    refused = 0  # periods replayed by this call's refused tries (STROBE_TRY each)
    dq = np.zeros(4)
    tally = np.zeros(4, dtype=np.int64)
    rtol = prm[P_RTOL]
    h = h_want = min(cap, 0.1 * rtol ** 0.25)  # h_want: the error control's step, before the cap
    # The first method: the explicit pair unless the first step already meets its stability bound.
    _linearise(kind, regime, v, t_base, drv, clk, 0.0, prm, track_energy, f0, jac, ft, scratch)
    jacobians += 1
    stiffest = _stiffest_rate(prm)
    explicit = next_explicit = h * max(_jacobian_norm(jac), stiffest) < EXPLICIT_CALM
    u = 0.0
    last_reset = -math.inf
    immediate = 0
    stagnant = 0
    status = OK
    fresh = not explicit  # the linearisation at (u, v, regime) is current (the explicit pair: f0 only)
    while u < u_end:
        if accepted + rejected >= MAX_STEPS:
            status = TOO_MANY_STEPS
            break
        t_abs = t_base + u
        if next_explicit != explicit:
            explicit = next_explicit
            fresh = False
            stagnant = 0
        if u >= rebase_after:
            # Move the clock's origin here, so that the plate's phase omega u never
            # carries the rounding of a long local time (REBASE_CYCLES).
            _advance_clock(drv, clk, u, False)
            t_base, done, u_end, last_reset = _moved_origin(u, t_base, done, u_end, last_reset)
            strobe_next -= u
            u = 0.0
            t_abs = t_base
            fresh = False  # the rate read on the moved clock, as after a try (whose bits it then matches)
        if (period > 0.0 and regime == LOADED and u >= strobe_next and u_end - u >= STROBE_PAYBACK * period
                and STROBE_SHARE * (done + u) >= (refused + STROBE_TRY) * period):
            # The try runs on a clock whose origin is here; the call's clock moves there
            # only if a jump is taken (a refused try leaves the run as it was, bit for bit).
            try_clk[0], try_clk[1] = clk[0], clk[1]
            _advance_clock(drv, try_clk, u, False)
            tally[:] = 0
            u_jumped = _stroboscopic(kind, regime, v, t_abs, drv, try_clk, u_end - u, period, cap, h, prm,
                                     track_energy, dq, tally, f0, jac, ft, lu, piv, k, stage, rate, trial, probe,
                                     scratch, explicit, kx)
            accepted += tally[0]
            rejected += tally[1]
            jacobians += tally[2]
            jumped += tally[3]
            fresh = False  # the try's replays used f0, jac and the stages as scratch
            if u_jumped > 0.0:
                # Whole periods: the plate's phase at the landing is the try's, exactly.
                _advance_clock(drv, try_clk, u_jumped, True)
                clk[0], clk[1] = try_clk[0], try_clk[1]
                t_base, done, u_end, last_reset = _moved_origin(u + u_jumped, t_base, done, u_end, last_reset)
                u = 0.0
                phi, phi_c = kahan_add(phi, phi_c, dq[0])
                work_sum += dq[1]
                dissipated += dq[2]
                e_normal += dq[3]
                strobe_wait = STROBE_WAIT
                if not math.isfinite(v[0] + v[1] + v[2] + v[3] + v[4]):
                    status = NON_FINITE
                    break
            else:
                strobe_wait = min(2 * strobe_wait, STROBE_WAIT_MAX)
                refused += STROBE_TRY
            strobe_next = u + strobe_wait * period
            continue
        if not fresh:
            if explicit:
                pz, pv = _plate(drv, clk, u)
                _rhs(kind, regime, v, t_abs, pz, pv, prm, track_energy, f0)
            else:
                _linearise(kind, regime, v, t_abs, drv, clk, u, prm, track_energy, f0, jac, ft, scratch)
                jacobians += 1
            fresh = True
        if regime == FLIGHT and h_want > cap and not within_reach and top == top:
            h = min(h_want, max(cap, REACH_SHARE * _reach_time(kind, v, f0, top, cap, probe, prm)))
        remaining = u_end - u
        err = math.inf
        if not explicit and stagnant >= LEAP_AFTER and LEAP * h < cap:
            stagnant = 0
            h_leap = min(LEAP * h, remaining)
            err = _rosenbrock(kind, regime, v, t_abs, drv, clk, u, h_leap, prm, track_energy, f0, jac, ft, lu,
                              piv, k, stage, rate, trial)
            if err <= 1.0:
                h = h_leap
            else:
                rejected += 1
        last = h >= remaining
        if last:
            h = remaining
        if not err <= 1.0:
            err = _step(explicit, kind, regime, v, t_abs, drv, clk, u, h, prm, track_energy, f0, jac, ft, lu, piv,
                        k, kx, stage, rate, trial)
        exponent = _control_exponent(explicit)
        if not err <= 1.0:
            rejected += 1
            stagnant = 0
            h *= SHRINK if not math.isfinite(err) else max(SHRINK, SAFETY * err ** exponent)
            h_want = h
            if h <= 16.0 * EPS * max(1.0, abs(t_abs)):
                status = STEP_TOO_SMALL
                break
            continue
        if h > cap:
            # Past the cap only in a flight above the plate's reach: the step must stay
            # there at its samples and its end, else it is retaken at the cap (and the
            # flight keeps the cap until its landing).
            for sample in range(1, EVENT_SAMPLES + 1):
                if sample == EVENT_SAMPLES:
                    for i in range(NS):
                        probe[i] = trial[i]
                else:
                    _interpolate(explicit, v, trial, k, kx, h, sample / EVENT_SAMPLES, probe)
                if not _clearance(kind, probe, top, prm) > 0.0:
                    within_reach = True
            if within_reach:
                rejected += 1
                h = cap
                continue
        accepted += 1
        growth = min(GROW, max(SHRINK, SAFETY * (max(err, 1e-12) ** exponent)))
        stagnant = stagnant + 1 if growth < 2.0 else 0
        h_next = h * growth
        # The method for the next step (taken there, so that this step's events are
        # refined with the method that took it).
        if explicit:
            if _explicit_stiffness(h, kx, stage, trial) > EXPLICIT_STIFF:
                stiff += 1
                calm = 0
                if stiff >= STIFF_AFTER:
                    next_explicit, stiff, hold = False, 0, STIFF_HOLD
            else:
                calm += 1
                if calm >= STIFF_FORGET:
                    stiff = 0
        else:
            hold = max(hold - 1, 0)
            if hold == 0 and min(h_next, cap) * max(_jacobian_norm(jac), stiffest) < EXPLICIT_CALM:
                next_explicit, stiff, calm = True, 0, 0

        # Events: the first sub-interval of the interpolant in which a value changes sign.
        first_event, n_events = _events_of(regime)
        event = EV_NONE
        s_hi, s_sample = 1.0, 1.0
        previous = 0.0
        for sample in range(1, EVENT_SAMPLES + 1):
            s = sample / EVENT_SAMPLES
            if sample == EVENT_SAMPLES:
                for i in range(NS):
                    probe[i] = trial[i]
            else:
                _interpolate(explicit, v, trial, k, kx, h, s, probe)
            pz, pv = _plate(drv, clk, u + s * h)
            earliest = math.inf
            for e in range(n_events):
                if _value(kind, regime, e, probe, t_base + (u + s * h), pz, pv, prm) < 0.0:
                    # the interpolant's root in (previous, s): a few regula falsi iterations
                    a, b = previous, s
                    _interpolate(explicit, v, trial, k, kx, h, a, best)
                    pza, pva = _plate(drv, clk, u + a * h)
                    ga = _value(kind, regime, e, best, t_base + (u + a * h), pza, pva, prm)
                    if a == 0.0:
                        ga = max(ga, 0.0)
                    gb = _value(kind, regime, e, probe, t_base + (u + s * h), pz, pv, prm)
                    root = b
                    if ga > 0.0:
                        for _ in range(40):
                            root = b - gb * (b - a) / (gb - ga)
                            if not (a < root < b):
                                root = 0.5 * (a + b)
                            _interpolate(explicit, v, trial, k, kx, h, root, best)
                            pzr, pvr = _plate(drv, clk, u + root * h)
                            gr = _value(kind, regime, e, best, t_base + (u + root * h), pzr, pvr, prm)
                            if gr < 0.0:
                                b, gb = root, gr
                                ga *= 0.5
                            else:
                                a, ga = root, gr
                                gb *= 0.5
                            if (b - a) * h <= EVENT_TOL:
                                break
                        root = b
                    else:
                        root = a
                    if root < earliest:
                        earliest = root
                        event = _event_at(regime, e)
            if event != EV_NONE:
                s_hi, s_sample = earliest, s
                break
            previous = s

        if event == EV_NONE:
            for i in range(NS):
                v[i] = trial[i]
            phi, phi_c = kahan_add(phi, phi_c, trial[5])
            work_sum += trial[6]
            dissipated += trial[7]
            e_normal += trial[8]
            u = u_end if last else u + h
            fresh = explicit  # the explicit pair's last rate is the next step's first
            if explicit:
                for i in range(NV):
                    f0[i] = kx[EXPLICIT_STAGES, i]
            h_want = h_next
            h = min(h_want, cap)
            immediate = 0
            continue

        # Refine the switch on full steps from the step's start: find a step length whose
        # value is past zero (the interpolant's root, the sample that showed the sign
        # change, the whole step), then regula falsi (Illinois) between it and the last
        # length short of zero.
        e_index = 0
        for e in range(n_events):
            if _event_at(regime, e) == event:
                e_index = e
        tol = max(EVENT_TOL, 4.0 * EPS * (abs(t_abs) + h))
        pz, pv = _plate(drv, clk, u)
        lo, g_lo = 0.0, max(_value(kind, regime, e_index, v, t_abs, pz, pv, prm), 0.0)
        hi, g_hi = -1.0, 0.0
        for attempt in range(3):
            length = s_hi * h if attempt == 0 else (s_sample * h if attempt == 1 else h)
            if length <= lo:
                continue
            if attempt == 2:
                for i in range(NV):
                    probe[i] = trial[i]
            else:
                _step(explicit, kind, regime, v, t_abs, drv, clk, u, length, prm, track_energy, f0, jac, ft, lu,
                      piv, k, kx, stage, rate, probe)
            pz, pv = _plate(drv, clk, u + length)
            g = _value(kind, regime, e_index, probe, t_base + (u + length), pz, pv, prm)
            if g < 0.0:
                hi, g_hi = length, g
                for i in range(NV):
                    best[i] = probe[i]
                break
            lo, g_lo = length, g
        if hi < 0.0:
            # The value dipped below zero and back within the step on the interpolant
            # only: the full steps see no switch (a graze within the tolerances).
            for i in range(NS):
                v[i] = trial[i]
            phi, phi_c = kahan_add(phi, phi_c, trial[5])
            work_sum += trial[6]
            dissipated += trial[7]
            e_normal += trial[8]
            u = u_end if last else u + h
            fresh = False
            h_want = h_next
            h = min(h_want, cap)
            continue
        side = 0
        for iteration in range(100):
            if hi - lo <= tol:
                break
            guess = hi - g_hi * (hi - lo) / (g_hi - g_lo) if g_lo > g_hi else 0.5 * (lo + hi)
            if not (lo < guess < hi):
                guess = 0.5 * (lo + hi)
                if not (lo < guess < hi):
                    break
            _step(explicit, kind, regime, v, t_abs, drv, clk, u, guess, prm, track_energy, f0, jac, ft, lu, piv,
                  k, kx, stage, rate, probe)
            pz, pv = _plate(drv, clk, u + guess)
            g = _value(kind, regime, e_index, probe, t_base + (u + guess), pz, pv, prm)
            if g < 0.0:
                hi, g_hi = guess, g
                for i in range(NV):
                    best[i] = probe[i]
                if side == -1:
                    g_lo *= 0.5
                side = -1
            else:
                lo, g_lo = guess, g
                if side == 1:
                    g_hi *= 0.5
                side = 1
        # Restart at the switch.
        for i in range(NS):
            v[i] = best[i]
        phi, phi_c = kahan_add(phi, phi_c, best[5])
        work_sum += best[6]
        dissipated += best[7]
        e_normal += best[8]
        if hi >= u_end - u:
            u = u_end
        else:
            u += hi
        events += 1
        if hi <= EVENT_TOL:
            immediate += 1
            if immediate > MAX_IMMEDIATE:
                status = TOO_MANY_EVENTS
                break
        else:
            immediate = 0
        pz, pv = _plate(drv, clk, u)
        pen, bound = _bound(kind, v, t_base + u, pz, pv, prm)
        if event == EV_CONTACT:
            v[4] = 0.0
            regime = _regime_after_contact(bound)
        elif event == EV_DETACH:
            dissipated += half_kt * v[4] * v[4]
            v[4] = 0.0
            regime = FLIGHT
        elif event == EV_RESET_PLUS or event == EV_RESET_MINUS:
            if v[4] != 0.0:
                slips += 1
                dissipated += half_kt * v[4] * v[4]
            v[4] = 0.0
            if bound > 0.0:
                regime = CASCADE if u - last_reset < CASCADE_GAP else LOADED
            else:
                regime = HELD
            last_reset = u
        elif event == EV_REARM:
            v[4] = 0.0
            regime = LOADED
        else:  # EV_HOLD: the cascade's limit, N reached zero
            regime = HELD
        fresh = False
        within_reach = False
        h_want = max(h_next, h)
        h = min(h_want, cap)
        if not math.isfinite(v[0] + v[1] + v[2] + v[3] + v[4]):
            status = NON_FINITE
            break
    if status == OK and not math.isfinite(v[0] + v[1] + v[2] + v[3] + v[4] + phi + work_sum + dissipated):
        status = NON_FINITE
    out[Y_X], out[Y_Z], out[Y_VX], out[Y_VZ], out[Y_F] = v[0], v[1], v[2], v[3], v[4]
    out[Y_PHI], out[Y_PHI_C] = phi, phi_c
    out[Y_WORK], out[Y_DISSIPATED], out[Y_E_NORMAL] = work_sum, dissipated, e_normal
    costs[0], costs[1], costs[2], costs[3], costs[4], costs[5] = slips, accepted, rejected, events, jacobians, jumped
    return status


@njit(cache=True)
def advance(kind, method, flags, y, cnt, drv, prm, n_steps, track_energy):
    """Advance by n_steps grid steps (see the module doc): the end time
    t0 + (n + n_steps) dt is reached by error-controlled steps whatever n_steps is.
    Returns 0, or a negative status with the arrays untouched."""
    out = y.copy()
    costs = np.zeros(6, dtype=np.int64)
    n = cnt[C_STEP]
    status = _evolve(kind, y, cnt, drv, prm, n, n_steps * drv[D_DT], track_energy, out, costs)
    if status < 0:
        return status
    y[:] = out
    cnt[C_STEP] = n + n_steps
    cnt[C_SLIPS] = costs[0]
    cnt[C_ACCEPTED] += costs[1]
    cnt[C_REJECTED] += costs[2]
    cnt[C_EVENTS] += costs[3]
    cnt[C_JACOBIANS] += costs[4]
    cnt[C_JUMPED] += costs[5]
    return status


@njit(cache=True)
def observe(kind, method, flags, y, cnt, drv, prm, h, track_energy, obs):
    """Fill ``obs`` with the state at t_n + h (0 <= h < dt) by a short integration from
    the grid state, without touching the stored state (layout of ``fixed_step.observe``)."""
    n = cnt[C_STEP]
    out = y.copy()
    costs = np.zeros(6, dtype=np.int64)
    slips = cnt[C_SLIPS]
    if h > 0.0:
        status = _evolve(kind, y, cnt, drv, prm, n, h, track_energy, out, costs)
        if status < 0:
            out[:] = math.nan
        else:
            slips = costs[0]
    t = drv[D_T0] + n * drv[D_DT] + h
    pz, pv = _plate(drv, _clock(drv, cnt, n), h)
    pen, u_n, u_t, cos_a, sin_a, normal = contact(kind, out[Y_X], out[Y_Z], out[Y_VX], out[Y_VZ], pz, pv, prm)
    record_observation(obs, out[Y_X], out[Y_Z], out[Y_VX], out[Y_VZ], out[Y_F], pen, normal, cos_a, out[Y_PHI], slips,
                       t, out[Y_WORK], out[Y_DISSIPATED], out[Y_E_NORMAL], pen > 0.0,
                       -prm[P_KT] * out[Y_F] if pen > 0.0 else 0.0)
    return N_OBS
