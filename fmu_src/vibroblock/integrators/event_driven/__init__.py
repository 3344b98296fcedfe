"""``event_driven`` (id 2, model A only): exact integration between located events.

The driver (this module) runs segments of exact flow between events; its parts are the
seams of the method: ``regimes`` (the closed-form flows), ``signals`` (the one form every
event value takes), ``next_event`` (the first zero of the active signals),
``quadratures`` (the integrals over a segment), ``switch`` (the friction law's rule at an
event) and ``period_skipping`` (locked orbits).

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
from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ...dynamics import normal_force, plate_motion
from ...laws import friction_spring_force
from ...unowned import data_pointer, keep_alive, unowned, unowned_each
from ...layout import (C_EVENTS, C_JUMPED, C_PHASE_STEP, C_SLIPS, C_STEP, D_AMP, D_DT, D_EXT_A, D_EXT_T, D_EXT_V,
                       D_EXT_Z, D_OMEGA, D_T0, N_OBS, Y_DISSIPATED, Y_E_NORMAL, Y_F, Y_PHI, Y_VX, Y_VZ, Y_WORK, Y_X,
                       Y_Z)
from ..fixed_step import record_observation
from ..plate import grid_phase, plate_after
from .next_event import detachment, first_zero, next_event
from .period_skipping import TOUCHDOWNS, N_RECORD, drive_stretch, touchdown
from .quadratures import segment_quadratures
from .regimes import (CASCADE, ENGAGED, EV_CONTACT, EV_NONE, carry, contact_constants, contact_flow, flight_flow,
                      horizontal_flow, segment_end)
from .signals import N_ROWS, R_CONTACT, SIG_LEN
from .switch import start_side, switch

# Events are located to this time (tau_0) past their true zero, or to 8 ulp of the time
# since the segment began, whichever is larger.
EVENT_TOL = 1e-12
# Zero-length segments allowed in a row before the scheme forces progress (grazing).
MAX_IMMEDIATE = 16


@njit(inline="always")
def _segment_length(u_ev, event, u_rem, immediate, tol):
    """The segment's length and end event; a grazing that keeps switching back and forth
    at one instant moves on by one tolerance.  Returns (u, event, zero-length segments in a row)."""
    if u_ev >= u_rem:
        u, event = u_rem, EV_NONE
    else:
        u = u_ev
    if u > 0.0:
        return u, event, 0
    immediate += 1
    if immediate > MAX_IMMEDIATE:
        return min(tol, u_rem), EV_NONE, 0
    return u, event, immediate


@njit(cache=True)
def _evolve(kind, s, slips, drv, prm, window, options, costs):
    """Integrate model A over window = (anchor, n_ref, off, n_to, off_to): from t0 + n_ref dt
    + off to t0 + n_to dt + off_to, the drive's phase anchored at grid step ``anchor``;
    options = (track_energy, tol, skip_periods).

    Evolves the state ``s`` in place and returns the slip count, or -1 if an event search
    failed or the state stopped being finite.  Adds the events it located to costs[0] and
    the plate periods it skipped to costs[1].
    """
    anchor, n_ref, off, n_to, off_to = window
    track_energy, tol, skip_periods = options
    drv, prm = data_pointer(drv), data_pointer(prm)
    # The state, the costs (both owned by the caller for the whole call) and the scratch
    # are read through unowned views: each counted view of them passed to a search or a
    # quadrature cost two atomic operations, a fifth of a run's time.
    s, costs = unowned(s), unowned(costs)
    owned = (np.zeros((N_ROWS, SIG_LEN)), np.zeros((TOUCHDOWNS, N_RECORD)))
    sig, book = unowned_each(owned)
    dt, om = drv[D_DT], drv[D_OMEGA]
    ext_origin = drv[D_T0] - drv[D_EXT_T]
    consts = contact_constants(prm, drv)
    in_contact, regime, slips = start_side(kind, s, slips, prm, drv, grid_phase(drv, anchor, n_ref) + om * off,
                                           ext_origin + n_ref * dt + off)
    # Touchdown book for skipping periods (only a purely harmonic drive repeats).
    periodic_drive = skip_periods and om > 0.0 and drv[D_EXT_V] == 0.0 and drv[D_EXT_A] == 0.0
    touchdowns = 0
    detach_n, detach_off = n_ref, math.nan  # the detachment of this contact (nan: not sought yet)
    vertical = (0j, 0.0, 0.0)
    just_reset = False
    immediate = 0
    while True:
        u_rem = (n_to - n_ref) * dt + (off_to - off)
        if u_rem <= 0.0:
            break
        th = grid_phase(drv, anchor, n_ref) + om * off
        tau_e = ext_origin + n_ref * dt + off
        e_th = complex(math.cos(th), math.sin(th))
        stretch = drive_stretch(prm, drv, n_ref, off, s[Y_X])
        flow = horizontal_flow(kind, regime, stretch, s[Y_F], s[Y_VX], prm)
        if in_contact:
            plate_z, plate_v = plate_motion(drv[D_AMP], om, e_th.imag, e_th.real, drv[D_EXT_Z], drv[D_EXT_V],
                                            drv[D_EXT_A], tau_e)
            vertical = contact_flow(kind, sig, consts, s[Y_Z] - plate_z, s[Y_VZ] - plate_v, e_th, om, prm)
            if math.isnan(detach_off):
                detach_n, detach_off = detachment(sig, n_ref, off, dt, u_rem, tol)
                if math.isnan(detach_off):
                    return -1
            loaded = regime == ENGAGED
            u_ev, event, regime = next_event(kind, prm, sig, regime, just_reset,
                                             (detach_n - n_ref) * dt + (detach_off - off), u_rem, tol,
                                             (stretch, s[Y_VX], s[Y_F]), flow, consts[3])
            if loaded and regime == CASCADE:  # the cascade was cut: the spring no longer loads
                flow = horizontal_flow(kind, regime, stretch, s[Y_F], s[Y_VX], prm)
        else:
            flight_flow(sig, s[Y_Z], s[Y_VZ], drv, prm, tau_e, e_th)
            u_ev, event = first_zero(sig[R_CONTACT], 0.0, u_rem, tol), EV_CONTACT
        if math.isnan(u_ev):
            return -1
        just_reset = False
        u, event, immediate = _segment_length(u_ev, event, u_rem, immediate, tol)

        state, xi_end, plate_end = segment_end(s, prm, drv, flow, vertical, consts, regime, in_contact, u, th, tau_e)
        segment_quadratures(kind, s, sig, prm, drv, flow, (xi_end[0], xi_end[1], state[0], state[1]),
                            (u, stretch, tau_e, e_th), in_contact, track_energy)
        s[Y_X], s[Y_Z], s[Y_VX], s[Y_VZ], s[Y_F] = state
        if not math.isfinite(s[Y_X] + s[Y_Z] + s[Y_VX] + s[Y_VZ] + s[Y_F] + s[Y_PHI]):
            return -1
        if u == u_rem:
            n_ref, off = n_to, off_to
        else:
            off += u
            if off >= dt:
                n_ref, off = carry(n_ref, off, dt)
        if event == EV_NONE:
            continue
        costs[0] += 1
        in_contact, regime, just_reset, slips = switch(kind, s, slips, prm, drv, event, plate_end)
        if event == EV_CONTACT:
            detach_off = math.nan
            if periodic_drive:  # a touchdown: if the motion has locked onto a period, add whole periods at once
                touchdowns, slips, n_ref, off = touchdown(book, touchdowns, s, slips, prm, drv, (n_ref, off),
                                                          (n_to, off_to), plate_end, costs)
    keep_alive(owned)
    return slips


@njit(cache=True)
def advance(kind, method, flags, y, cnt, drv, prm, n_steps, track_energy):
    """Advance model A by n_steps grid steps exactly (see the module doc): the end time
    t0 + (n + n_steps) dt is reached directly, whatever n_steps is.  Returns 0, or -1
    (the arrays untouched) if the state stopped being finite."""
    return advance_exact(kind, y, cnt, drv, prm, n_steps, track_energy, EVENT_TOL, True)


@njit(cache=True)
def advance_exact(kind, y, cnt, drv, prm, n_steps, track_energy, tol, skip_periods):
    """``advance`` with its event tolerance and period skipping chosen (for tests)."""
    n = cnt[C_STEP]
    out = y.copy()
    costs = np.zeros(2, np.int64)
    slips = _evolve(kind, out, cnt[C_SLIPS], drv, prm, (cnt[C_PHASE_STEP], n, 0.0, n + n_steps, 0.0),
                    (track_energy, tol, skip_periods), costs)
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
        slips = _evolve(kind, out, slips, drv, prm, (cnt[C_PHASE_STEP], n, 0.0, n, h), (track_energy, EVENT_TOL, False),
                        np.zeros(2, np.int64))
        if slips < 0:
            out[:] = math.nan
            slips = cnt[C_SLIPS]
    plate_z, plate_v = plate_after(drv, cnt, n, h)
    pen = plate_z - out[Y_Z]
    normal = normal_force(kind, pen, out[Y_VZ] - plate_v, prm)
    friction = -friction_spring_force(kind, out[Y_F], prm) if pen > 0.0 else 0.0
    record_observation(obs, (out[Y_X], out[Y_Z], out[Y_VX], out[Y_VZ], out[Y_F]), (pen, normal, 1.0, pen > 0.0),
                       (out[Y_PHI], slips, out[Y_WORK], out[Y_DISSIPATED], out[Y_E_NORMAL]),
                       drv[D_T0] + n * drv[D_DT] + h, friction)
    return N_OBS
