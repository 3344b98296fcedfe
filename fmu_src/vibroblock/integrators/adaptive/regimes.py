"""The right-hand side of each contact regime, its event values, and the plate's clock.

Regimes and events (N: the contact force, continued across delta = 0 within a contact
phase; B = mu_s N, the Coulomb bound; k_t F the friction spring's force):

==========  ===========================  =====================================
regime      event (value crosses 0)      after the event
==========  ===========================  =====================================
flight      delta rises through 0        contact: loaded if B > 0, else held
loaded      delta falls through 0        flight, F = 0 (its energy dissipated)
            B - k_t F or B + k_t F       Coulomb reset: F = 0, counted if F != 0;
            falls through 0              loaded if B > 0, else held
held        delta falls through 0        flight
(F = 0)     B rises through 0            loaded (F restarts from 0)
cascade     delta falls through 0        flight
(F = 0)     B falls through 0            held
==========  ===========================  =====================================

A friction law whose interface slips at every stress (rate-and-state: ``INTERFACE_SLIPS``)
has no reset to locate: its loaded regime watches the contact and its bound's N instead,
and a bound that falls through 0 ends it (held, the spring's energy dissipated); F then
relaxes at the interface's slip rate, dF/dt = u_t - V, and the law's state (ln theta:
``laws.rate_state``) is a sixth state component.  Under the other laws theta's rate is 0 and it rides along
unchanged (the integration's arithmetic on the other components is the same, to the bit).

Every force, the frame and the energy rates are ``vibroblock.dynamics``'s, the contact
force and the friction spring the run's laws (``vibroblock.laws``).  Within a contact
phase the normal force is continued across delta = 0 (the event, not the force, ends the
phase), so a step may straddle a switch smoothly, and each regime keeps one frame on both
sides of delta = 0 for the same reason: a contact phase the surface's
(``surface_contact``), a flight with ``flight = free`` the fixed axes.

The plate is read from a clock: its phase at an origin (reduced modulo 2 pi exactly,
``plate.drive_phase``) plus omega u for the local time u since then.  Summed as
omega (t + u), at t ~ 1e9 the phase would round to ~1e-7 rad and put the plate ~1e-8 off
between replays of one period (the stroboscopic jumps' check refused every jump there).
"""
import math

import numpy as np
from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ...dynamics import coulomb_bound, energy_rates, force, plate_motion, position_rates, surface_contact
from ...laws import contact_force, friction_interface, friction_interface_slips, friction_spring_force
from ...layout import D_AMP, D_DT, D_EXT_A, D_EXT_T, D_EXT_V, D_EXT_Z, D_OMEGA, D_T0, P_M, P_MUS, P_VD
from ...readings import free_flight
from ..plate import TWO_PI, drive_phase

# Regimes.
FLIGHT, LOADED, HELD, CASCADE = 0, 1, 2, 3
# Events.
EV_NONE, EV_CONTACT, EV_DETACH, EV_RESET_PLUS, EV_RESET_MINUS, EV_REARM, EV_HOLD = range(7)

# State vector of the integration: the six state components (x, z, vx, vz, F and the
# friction law's state theta), then the quadratures (phi, work, dissipation,
# normal-spring energy), which feed nothing back.
NS = 6
THETA = 5
NQ = 4
NV = NS + NQ
# The state components every law integrates: the error norms count theta only where it moves.
NS_MOTION = 5


# --------------------------------------------------------------------------- the plate's clock
@njit(inline="always")
def clock(drv, cnt, n0):
    """The plate's clock at grid step n0: (its phase in [0, 2 pi), the external input's time)."""
    clk = np.empty(2)
    clk[0] = drive_phase(drv, cnt, n0)
    clk[1] = (drv[D_T0] - drv[D_EXT_T]) + n0 * drv[D_DT]
    return clk


@njit(inline="always")
def advance_clock(drv, clk, du, whole_periods):
    """Move the clock's origin by du: its phase by omega du (reduced), or not at all when
    du spans whole plate periods (a stroboscopic jump: the plate is where it was, exactly,
    so that the periods replayed after the jump see the same plate as the one recorded)."""
    if not whole_periods:
        phase = clk[0] + drv[D_OMEGA] * du
        clk[0] = phase - TWO_PI * math.floor(phase / TWO_PI)
    clk[1] += du


@njit(inline="always")
def plate(drv, clk, u):
    """Plate height and velocity at local time u after the clock's origin."""
    phase = clk[0] + drv[D_OMEGA] * u
    return plate_motion(drv[D_AMP], drv[D_OMEGA], math.sin(phase), math.cos(phase), drv[D_EXT_Z], drv[D_EXT_V],
                        drv[D_EXT_A], clk[1] + u)


# --------------------------------------------------------------------------- right-hand side
@njit(inline="always")
def rhs(kind, regime, v, t, pz, pv, prm, track_energy, out):
    """Rates of the state and the quadratures in one regime (the module's doc: the force
    continued across delta = 0 and one frame per regime)."""
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
    out[THETA] = 0.0
    interface_loss = 0.0
    if regime == LOADED and friction_interface_slips(kind):
        slip, out[THETA] = friction_interface(kind, shear, v[THETA], coulomb_bound(kind, normal, x, t, prm), prm)
        out[4] -= slip
        interface_loss = friction_spring_force(kind, shear, prm) * slip
    drift = rate_x - prm[P_VD]
    out[6] = drift * drift
    if track_energy:
        # Within a contact phase the rates are continued across delta = 0 like the force
        # (so that the quadratures' rows of the Jacobian have no kink): the gate is the regime.
        work, dissipation, storage = energy_rates(kind, x, (vx, vz), shear, t, gate > 0.0,
                                                  (pen, u_n, u_t, cos_a, sin_a, normal), pv, prm)
        out[7], out[8], out[9] = work, dissipation + interface_loss, storage
    else:
        out[7] = out[8] = out[9] = 0.0


@njit(inline="always")
def rates(system, clk, v, t_abs, u, out):
    """``rhs`` at local time u on the clock (absolute time t_abs); ``system`` is the tuple
    (kind, regime, drv, prm, track_energy)."""
    kind, regime, drv, prm, track_energy = system
    pz, pv = plate(drv, clk, u)
    rhs(kind, regime, v, t_abs, pz, pv, prm, track_energy, out)


# --------------------------------------------------------------------------- event values
@njit(inline="always")
def bound(kind, v, t, pz, pv, prm):
    """Penetration and the Coulomb bound mu_s N at time t: N the contact force continued
    across delta = 0, or the applied load at the block's x and t (``coulomb_bound``)."""
    pen, u_n, u_t, cos_a, sin_a, normal = surface_contact(kind, v[0], v[1], v[2], v[3], pz, pv, prm)
    normal_bound = coulomb_bound(kind, contact_force(kind, pen, u_n, prm), v[0], t, prm)
    # A slipping interface has no Coulomb bound (mu_s plays no part): its regimes turn on N_b's sign alone.
    return pen, normal_bound if friction_interface_slips(kind) else prm[P_MUS] * normal_bound


@njit(inline="always")
def event_value(event, pen, bound_now, spring):
    """Positive before the switch, negative once it has happened."""
    if event == EV_CONTACT:
        return -pen
    if event == EV_DETACH:
        return pen
    if event == EV_RESET_PLUS:
        return bound_now - spring
    if event == EV_RESET_MINUS:
        return bound_now + spring
    if event == EV_REARM:
        return -bound_now
    return bound_now  # EV_HOLD


@njit(inline="always")
def events_of(kind, regime):
    """The events a regime watches: (first, count) in the order contact/detach, resets, N."""
    if regime == FLIGHT:
        return EV_CONTACT, 1
    if regime == LOADED and not friction_interface_slips(kind):
        return EV_DETACH, 3
    return EV_DETACH, 2


@njit(inline="always")
def event_at(kind, regime, i):
    """The regime's i-th event (``events_of``'s order)."""
    if regime == FLIGHT:
        return EV_CONTACT
    if i == 0:
        return EV_DETACH
    if regime == LOADED:
        if friction_interface_slips(kind):
            return EV_HOLD  # no reset: the loaded phase ends where its bound's N does
        return EV_RESET_PLUS if i == 1 else EV_RESET_MINUS
    return EV_REARM if regime == HELD else EV_HOLD


@njit(inline="always")
def switch_values(kind, v, t, pz, pv, prm):
    """What every event value is made of at state v, time t, plate (pz, pv): the
    penetration, the Coulomb bound and the friction spring's force.  A loop over a
    regime's events takes them once (the compiler cannot hoist them past the law's call)."""
    pen, bound_now = bound(kind, v, t, pz, pv, prm)
    return pen, bound_now, friction_spring_force(kind, v[4], prm)


@njit(inline="always")
def value(kind, regime, i, v, t, pz, pv, prm):
    """The regime's i-th event value at state v, time t, plate (pz, pv)."""
    pen, bound_now, spring = switch_values(kind, v, t, pz, pv, prm)
    return event_value(event_at(kind, regime, i), pen, bound_now, spring)


@njit(inline="always")
def value_at(system, clk, i, v, t_abs, u):
    """``value`` at local time u on the clock (absolute time t_abs)."""
    kind, regime, drv, prm, track_energy = system
    pz, pv = plate(drv, clk, u)
    return value(kind, regime, i, v, t_abs, pz, pv, prm)


@njit(inline="always")
def regime_after_contact(bound_now):
    return LOADED if bound_now > 0.0 else HELD


# --------------------------------------------------------------------------- flights above the plate's reach
@njit(inline="always")
def clearance(kind, v, top, prm):
    """The block's height above the plate at its highest (-delta with the plate at ``top``):
    where it is positive, no phase of the plate reaches the block (delta grows with the
    plate's height in either frame, since cos a > 0)."""
    pen = surface_contact(kind, v[0], v[1], v[2], v[3], top, 0.0, prm)[0]
    return -pen


@njit(inline="always")
def reach_time(kind, v, f0, top, tau, probe, prm):
    """Time until a block in flight could first be within the plate's reach: the first
    zero of a quadratic model of its clearance (value, rate and curvature by central
    differences along the position's Taylor path over +-tau; in the tangent frame the
    abscissa's acceleration is taken as u').  0 if the block is within reach now, inf if
    the model never comes back to zero.  A model, not a bound: the step that uses it is
    checked on its samples (``driver``)."""
    g0 = clearance(kind, v, top, prm)
    if not g0 > 0.0:
        return 0.0
    for i in range(NS):
        probe[i] = v[i]
    half = 0.5 * tau * tau
    probe[0] = v[0] + tau * f0[0] + half * f0[2]
    probe[1] = v[1] + tau * f0[1] + half * f0[3]
    g_plus = clearance(kind, probe, top, prm)
    probe[0] = v[0] - tau * f0[0] + half * f0[2]
    probe[1] = v[1] - tau * f0[1] + half * f0[3]
    g_minus = clearance(kind, probe, top, prm)
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
