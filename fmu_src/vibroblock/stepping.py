"""Fixed-step integrators over the shared dynamics, compiled with numba.

Contract every integrator obeys (a new one must too):

* it advances the arrays (y, cnt) in place by whole internal steps on the grid
  t_n = t0 + n dt, n = cnt[C_STEP]; time is never accumulated;
* the stored state always satisfies the friction rule (F = 0 out of contact, and
  |k_t F| < mu_s N in contact): the rule is applied at the end of every step, at the
  new state, and a Coulomb reset of a loaded spring increments cnt[C_SLIPS];
* the plate drive is evaluated as a function of n alone, so advancing n1 + n2 steps in
  two calls gives the same bits as n1 + n2 steps in one call;
* with ``track_energy`` it accumulates the work done on the block, the energy
  dissipated (dashpots, and k_t F^2/2 at every reset) and the normal spring's energy
  (``dynamics.energy_rates``), with the scheme's own order;
* it returns the number of steps taken, or -1 if the state stopped being finite, in
  which case the arrays are left as they were on entry (the last good state).

Integrators
-----------
``symplectic_euler`` (id 0) -- the paper's first-order scheme, as we read it: velocity
first, then position with the new velocity (semi-implicit Euler); the shear
displacement grows by dt times the new tangential velocity while the step started in
contact.  For model A this makes F exactly the horizontal travel since the contact
began.  First order, one force evaluation per step.

``rk4`` (id 1) -- classical fourth-order Runge-Kutta on (x, z, vx, vz, F, phi) with the
contact gate Theta(delta) evaluated inside each stage; the reset rule is applied after
the step.  Fourth order between events, first order across a contact switch or reset.

``event_driven`` (id 2, model A only; ``event_driven.py``) -- exact: between events model
A is linear, so flight, contact and the loaded friction spring are integrated in closed
form, and contact, detachment and Coulomb resets are located as first zeros of
closed-form signals to EVENT_TOL (1e-12 tau_0).  It meets the contract with dt only
defining the storage grid: n steps reach t0 + (n0 + n) dt directly at a cost set by the
number of events, not of steps; phi and the energy terms are integrated exactly, so
the energy residual stays at rounding level; splitting a run changes results only at
the event tolerance, not bit for bit.

``implicit_contact`` (id 3, ``implicit_contact.py``) -- stiff-stable: the linear normal and
tangential spring-dashpots are integrated in closed form over the step, contact switches
located inside it, the soft forces (drive spring, load, plate acceleration, turning of
the frame on a corrugated plate) held at their midpoint values.  Second order for smooth
motion, stable for any contact stiffness or damping; the drive spring stays explicit.
"""
import math

from numba import njit

from .dynamics import contact, energy_rates, force, friction_rule, plate_motion
from .event_driven import advance_event_driven
from .layout import (C_PHASE_STEP, C_SLIPS, C_STEP, D_AMP, D_DT, D_EXT_A, D_EXT_T, D_EXT_V, D_EXT_Z,
                     D_OMEGA, D_PHASE, D_T0, P_KT, P_M, P_VD, Y_DISSIPATED, Y_E_NORMAL, Y_F, Y_PHI, Y_PHI_C, Y_VX, Y_VZ,
                     Y_WORK, Y_X, Y_Z)

SYMPLECTIC_EULER, RK4 = 0, 1
EVENT_DRIVEN = 2
IMPLICIT_CONTACT = 3  # implicit_contact.py: contact spring-dashpots in closed form, stiff-stable
INTEGRATORS = {"symplectic_euler": SYMPLECTIC_EULER, "rk4": RK4, "event_driven": EVENT_DRIVEN,
               "implicit_contact": IMPLICIT_CONTACT}
# Evaluations of the forces per internal step: the cost unit of a scheme.
FORCE_EVALUATIONS = {"symplectic_euler": 1, "rk4": 4, "event_driven": 0,  # event_driven: cost per event, not per step
                     "implicit_contact": 2}  # one soft-force evaluation + closed-form contact flows

# The drive's sine and cosine advance by a rotation each step (a sin/cos pair costs more
# than a whole model-A step) and are recomputed exactly every RESYNC steps, counted from
# the phase anchor, so rounding cannot build up and the values depend on n only.
RESYNC = 256
# How often (in steps) a long run checks that the state is still finite.
FINITE_CHECK = 1 << 16


@njit(inline="always")
def drive_phase(drv, cnt, n):
    return drv[D_PHASE] + drv[D_OMEGA] * drv[D_DT] * (n - cnt[C_PHASE_STEP])


@njit(inline="always")
def drive_sin_cos(drv, cnt, n):
    """sin and cos of the drive phase at step n, bit-identical to what a run reaching
    step n through the rotation recurrence holds."""
    since_anchor = n - cnt[C_PHASE_STEP]
    base = n - since_anchor % RESYNC
    phase = drive_phase(drv, cnt, base)
    s, c = math.sin(phase), math.cos(phase)
    rot_s, rot_c = math.sin(drv[D_OMEGA] * drv[D_DT]), math.cos(drv[D_OMEGA] * drv[D_DT])
    for _ in range(n - base):
        s, c = s * rot_c + c * rot_s, c * rot_c - s * rot_s
    return s, c


@njit(inline="always")
def kahan_add(total, compensation, value):
    corrected = value - compensation
    new_total = total + corrected
    return new_total, (new_total - total) - corrected


@njit(inline="always")
def is_finite_state(x, z, vx, vz, shear):
    return math.isfinite(x + z + vx + vz + shear)


@njit(inline="always")
def settle_step(prm, shear, penetration, normal, slips, phi, phi_c, work, dissipated, e_normal,
                d_phi, d_work, d_dissipated, d_normal, track_energy):
    """End of every step of every scheme: the friction rule at the new state (a reset
    releases k_t F^2/2, counted as dissipated), then the step's quadratures."""
    loaded = shear
    shear, reset = friction_rule(shear, penetration, normal, prm)
    phi, phi_c = kahan_add(phi, phi_c, d_phi)
    if track_energy:
        work += d_work
        dissipated += d_dissipated + 0.5 * prm[P_KT] * (loaded * loaded - shear * shear)
        e_normal += d_normal
    return shear, slips + reset, phi, phi_c, work, dissipated, e_normal


@njit(inline="always")
def store_state(y, cnt, x, z, vx, vz, shear, phi, phi_c, work, dissipated, e_normal, n, slips):
    y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F] = x, z, vx, vz, shear
    y[Y_PHI], y[Y_PHI_C] = phi, phi_c
    y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL] = work, dissipated, e_normal
    cnt[C_STEP], cnt[C_SLIPS] = n, slips


@njit(cache=True)
def advance(kind, method, y, cnt, drv, prm, n_steps, track_energy):
    """Advance by n_steps internal steps with the chosen integrator (see module doc)."""
    if method == RK4:
        return _advance_rk4(kind, y, cnt, drv, prm, n_steps, track_energy)
    if method == EVENT_DRIVEN:
        return advance_event_driven(y, cnt, drv, prm, n_steps, track_energy)
    if method == IMPLICIT_CONTACT:
        return advance_implicit_contact(kind, y, cnt, drv, prm, n_steps, track_energy)
    return _advance_euler(kind, y, cnt, drv, prm, n_steps, track_energy)


@njit(inline="always")
def _plate_at_step(drv, s, c, t):
    return plate_motion(drv[D_AMP], drv[D_OMEGA], s, c, drv[D_EXT_Z], drv[D_EXT_V], drv[D_EXT_A],
                        t - drv[D_EXT_T])


@njit(inline="always")
def euler_step(kind, prm, x, z, vx, vz, shear, t, h, h_over_m, contact_now, plate_v, pz1, pv1, track_energy):
    """One semi-implicit Euler step of length h from a state whose contact quantities
    ``contact_now`` are known; returns the new state, its contact quantities, and the
    increments of phi, work, dissipation and normal-spring energy."""
    pen, u_n, u_t, cos_a, sin_a, normal = contact_now
    fx, fz = force(kind, x, t, pen, normal, u_t, cos_a, sin_a, shear, prm)
    d_work = d_dissipated = d_normal = 0.0
    if track_energy:
        work, dissipation, storage = energy_rates(kind, x, vx, vz, t, pen, u_n, u_t, cos_a, sin_a, normal,
                                                  shear, plate_v, prm)
        d_work, d_dissipated, d_normal = h * work, h * dissipation, h * storage
    engaged = pen > 0.0
    vx += h_over_m * fx
    vz += h_over_m * fz
    x += h * vx
    z += h * vz
    contact_new = contact(kind, x, z, vx, vz, pz1, pv1, prm)
    if engaged:
        shear += h * contact_new[2]
    dv = vx - prm[P_VD]
    return x, z, vx, vz, shear, contact_new, h * dv * dv, d_work, d_dissipated, d_normal


@njit(cache=True)
def _advance_euler(kind, y, cnt, drv, prm, n_steps, track_energy):
    t0, dt = drv[D_T0], drv[D_DT]
    dt_m = dt / prm[P_M]
    # A plate at rest (no drive, no input) needs no kinematics in the loop.
    plate_moves = drv[D_AMP] != 0.0 or drv[D_EXT_V] != 0.0 or drv[D_EXT_A] != 0.0
    x, z, vx, vz, shear = y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F]
    phi, phi_c = y[Y_PHI], y[Y_PHI_C]
    work, dissipated, e_normal = y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL]
    n, slips, anchor = cnt[C_STEP], cnt[C_SLIPS], cnt[C_PHASE_STEP]
    rot_s, rot_c = math.sin(drv[D_OMEGA] * dt), math.cos(drv[D_OMEGA] * dt)
    s, c = drive_sin_cos(drv, cnt, n)

    t = t0 + n * dt
    plate_z, plate_v = _plate_at_step(drv, s, c, t)
    state_contact = contact(kind, x, z, vx, vz, plate_z, plate_v, prm)
    done = 0
    while done < n_steps:
        n += 1
        done += 1
        t_new = t0 + n * dt
        if plate_moves:
            if ((n - anchor) & (RESYNC - 1)) == 0:
                phase = drive_phase(drv, cnt, n)
                s, c = math.sin(phase), math.cos(phase)
            else:
                s, c = s * rot_c + c * rot_s, c * rot_c - s * rot_s
            pz1, pv1 = _plate_at_step(drv, s, c, t_new)
        else:
            pz1, pv1 = plate_z, plate_v
        x, z, vx, vz, shear, state_contact, d_phi, d_work, d_dissipated, d_normal = euler_step(
            kind, prm, x, z, vx, vz, shear, t, dt, dt_m, state_contact, plate_v, pz1, pv1, track_energy)
        shear, slips, phi, phi_c, work, dissipated, e_normal = settle_step(
            prm, shear, state_contact[0], state_contact[5], slips, phi, phi_c, work, dissipated, e_normal,
            d_phi, d_work, d_dissipated, d_normal, track_energy)
        t, plate_z, plate_v = t_new, pz1, pv1
        if (done & (FINITE_CHECK - 1)) == 0 and not is_finite_state(x, z, vx, vz, shear):
            return -1
    if not is_finite_state(x, z, vx, vz, shear):
        return -1
    store_state(y, cnt, x, z, vx, vz, shear, phi, phi_c, work, dissipated, e_normal, n, slips)
    return done


@njit(inline="always")
def _rk4_rhs(kind, prm, x, z, vx, vz, shear, t, plate_z, plate_v, track_energy):
    """Accelerations, dF/dt, and the rates of the quadratures (phi, work, dissipation,
    normal-spring energy) at one stage."""
    pen, u_n, u_t, cos_a, sin_a, normal = contact(kind, x, z, vx, vz, plate_z, plate_v, prm)
    fx, fz = force(kind, x, t, pen, normal, u_t, cos_a, sin_a, shear, prm)
    d_shear = u_t if pen > 0.0 else 0.0
    dv = vx - prm[P_VD]
    work = dissipation = storage = 0.0
    if track_energy:
        work, dissipation, storage = energy_rates(kind, x, vx, vz, t, pen, u_n, u_t, cos_a, sin_a, normal,
                                                  shear, plate_v, prm)
    return fx / prm[P_M], fz / prm[P_M], d_shear, dv * dv, work, dissipation, storage


@njit(inline="always")
def rk4_step(kind, prm, x, z, vx, vz, shear, t, h, pz0, pv0, pz_half, pv_half, pz1, pv1, track_energy):
    """One classical RK4 step of length h; returns the new state and the increments of
    phi, work, dissipation and normal-spring energy."""
    half = 0.5 * h
    ax1, az1, df1, p1, w1, d1, e1 = _rk4_rhs(kind, prm, x, z, vx, vz, shear, t, pz0, pv0, track_energy)
    vx2, vz2 = vx + half * ax1, vz + half * az1
    ax2, az2, df2, p2, w2, d2, e2 = _rk4_rhs(kind, prm, x + half * vx, z + half * vz, vx2, vz2,
                                             shear + half * df1, t + half, pz_half, pv_half, track_energy)
    vx3, vz3 = vx + half * ax2, vz + half * az2
    ax3, az3, df3, p3, w3, d3, e3 = _rk4_rhs(kind, prm, x + half * vx2, z + half * vz2, vx3, vz3,
                                             shear + half * df2, t + half, pz_half, pv_half, track_energy)
    vx4, vz4 = vx + h * ax3, vz + h * az3
    ax4, az4, df4, p4, w4, d4, e4 = _rk4_rhs(kind, prm, x + h * vx3, z + h * vz3, vx4, vz4,
                                             shear + h * df3, t + h, pz1, pv1, track_energy)
    sixth = h / 6.0
    return (x + sixth * (vx + 2.0 * vx2 + 2.0 * vx3 + vx4),
            z + sixth * (vz + 2.0 * vz2 + 2.0 * vz3 + vz4),
            vx + sixth * (ax1 + 2.0 * ax2 + 2.0 * ax3 + ax4),
            vz + sixth * (az1 + 2.0 * az2 + 2.0 * az3 + az4),
            shear + sixth * (df1 + 2.0 * df2 + 2.0 * df3 + df4),
            sixth * (p1 + 2.0 * p2 + 2.0 * p3 + p4),
            sixth * (w1 + 2.0 * w2 + 2.0 * w3 + w4),
            sixth * (d1 + 2.0 * d2 + 2.0 * d3 + d4),
            sixth * (e1 + 2.0 * e2 + 2.0 * e3 + e4))


@njit(cache=True)
def _advance_rk4(kind, y, cnt, drv, prm, n_steps, track_energy):
    t0, dt = drv[D_T0], drv[D_DT]
    x, z, vx, vz, shear = y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F]
    phi, phi_c = y[Y_PHI], y[Y_PHI_C]
    work, dissipated, e_normal = y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL]
    n, slips, anchor = cnt[C_STEP], cnt[C_SLIPS], cnt[C_PHASE_STEP]
    rot_s, rot_c = math.sin(drv[D_OMEGA] * dt), math.cos(drv[D_OMEGA] * dt)
    half_s, half_c = math.sin(0.5 * drv[D_OMEGA] * dt), math.cos(0.5 * drv[D_OMEGA] * dt)
    s, c = drive_sin_cos(drv, cnt, n)
    t = t0 + n * dt
    pz0, pv0 = _plate_at_step(drv, s, c, t)
    done = 0
    while done < n_steps:
        sh, ch = s * half_c + c * half_s, c * half_c - s * half_s
        pz_half, pv_half = _plate_at_step(drv, sh, ch, t + 0.5 * dt)
        n += 1
        done += 1
        if ((n - anchor) & (RESYNC - 1)) == 0:
            phase = drive_phase(drv, cnt, n)
            s, c = math.sin(phase), math.cos(phase)
        else:
            s, c = s * rot_c + c * rot_s, c * rot_c - s * rot_s
        t_new = t0 + n * dt
        pz1, pv1 = _plate_at_step(drv, s, c, t_new)
        x, z, vx, vz, shear, d_phi, d_work, d_dissipated, d_normal = rk4_step(
            kind, prm, x, z, vx, vz, shear, t, t_new - t, pz0, pv0, pz_half, pv_half, pz1, pv1, track_energy)
        pen, u_n, u_t, cos_a, sin_a, normal = contact(kind, x, z, vx, vz, pz1, pv1, prm)
        shear, slips, phi, phi_c, work, dissipated, e_normal = settle_step(
            prm, shear, pen, normal, slips, phi, phi_c, work, dissipated, e_normal,
            d_phi, d_work, d_dissipated, d_normal, track_energy)
        t, pz0, pv0 = t_new, pz1, pv1
        if (done & (FINITE_CHECK - 1)) == 0 and not is_finite_state(x, z, vx, vz, shear):
            return -1
    if not is_finite_state(x, z, vx, vz, shear):
        return -1
    store_state(y, cnt, x, z, vx, vz, shear, phi, phi_c, work, dissipated, e_normal, n, slips)
    return done


@njit(inline="always")
def plate_at_time(drv, cnt, prm, t):
    """Plate height and velocity at an arbitrary time (off the grid): exact sin/cos."""
    anchor_time = drv[D_T0] + cnt[C_PHASE_STEP] * drv[D_DT]
    phase = drv[D_PHASE] + drv[D_OMEGA] * (t - anchor_time)
    return plate_motion(drv[D_AMP], drv[D_OMEGA], math.sin(phase), math.cos(phase),
                        drv[D_EXT_Z], drv[D_EXT_V], drv[D_EXT_A], t - drv[D_EXT_T])


@njit(cache=True)
def observe(kind, method, y, cnt, drv, prm, h, track_energy):
    """State at t_n + h, 0 <= h < dt, without touching the stored state.

    A communication point between two grid points is reached by one scratch step of
    length h from the grid state, so outputs are at the requested time while the
    stored trajectory stays on the grid (and so independent of the communication
    steps).  Returns (x, z, vx, vz, F, penetration, N, cos a, phi, slips, work,
    dissipated, normal-spring energy, t).
    """
    t = drv[D_T0] + cnt[C_STEP] * drv[D_DT]
    x, z, vx, vz, shear = y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F]
    phi, slips = y[Y_PHI], cnt[C_SLIPS]
    work, dissipated, e_normal = y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL]
    plate_z, plate_v = plate_at_time(drv, cnt, prm, t)
    state_contact = contact(kind, x, z, vx, vz, plate_z, plate_v, prm)
    if h > 0.0:
        pz1, pv1 = plate_at_time(drv, cnt, prm, t + h)
        if method == RK4:
            pzh, pvh = plate_at_time(drv, cnt, prm, t + 0.5 * h)
            x, z, vx, vz, shear, d_phi, d_work, d_dissipated, d_normal = rk4_step(
                kind, prm, x, z, vx, vz, shear, t, h, plate_z, plate_v, pzh, pvh, pz1, pv1, track_energy)
            state_contact = contact(kind, x, z, vx, vz, pz1, pv1, prm)
        elif method == IMPLICIT_CONTACT:
            x, z, vx, vz, shear, d_phi, d_work, d_dissipated, d_normal = implicit_contact_scratch(
                kind, prm, x, z, vx, vz, shear, t, h, plate_z, plate_v, pz1, pv1, track_energy)
            state_contact = contact(kind, x, z, vx, vz, pz1, pv1, prm)
        else:
            x, z, vx, vz, shear, state_contact, d_phi, d_work, d_dissipated, d_normal = euler_step(
                kind, prm, x, z, vx, vz, shear, t, h, h / prm[P_M], state_contact, plate_v, pz1, pv1,
                track_energy)
        loaded = shear
        shear, reset = friction_rule(shear, state_contact[0], state_contact[5], prm)
        slips += reset
        phi += d_phi
        if track_energy:
            work += d_work
            dissipated += d_dissipated + 0.5 * prm[P_KT] * (loaded * loaded - shear * shear)
            e_normal += d_normal
        t += h
    pen, u_n, u_t, cos_a, sin_a, normal = state_contact
    return x, z, vx, vz, shear, pen, normal, cos_a, phi, slips, work, dissipated, e_normal, t


# Imported last: implicit_contact builds on this module's drive helpers (drive_sin_cos, ...).
from .implicit_contact import advance_implicit_contact, implicit_contact_scratch  # noqa: E402
