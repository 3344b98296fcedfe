"""Scene reductions: run only the physics a scene needs.

Three options drop parts of the full model (each is a Boolean FMU parameter, see
``parameters.SCENE_OPTIONS``); this module is the step that runs a block with any of
them, a scheme of the shared fixed-step driver (``integrators.fixed_step``) registered
as ``reduced_scene``, on the usual grid and under the same contract.

``rigid_contact`` (models A, B, C)
    The block cannot penetrate the plate: while attached it rides the surface and the
    normal force is whatever keeps it there; it leaves when that force would have to
    pull (N < 0), flies, and lands with restitution 0 (the normal relative velocity is
    removed, its kinetic energy dissipated).  Drops the contact oscillator (k_n,
    gamma_n): no contact ringing, no dt limit from k_n.  The detachment threshold
    becomes max plate acceleration = load / m (A = g / omega^2), the paper's line,
    instead of the compliant A_c(omega).
``frozen_vertical`` (model A)
    The vertical motion is not integrated: the block sits on the steady in-contact
    orbit of the harmonic drive (``orbits.steady_orbit``), pressed in quasi-statically by
    an external plate acceleration.  Exact for model A on that orbit (vertical and
    horizontal motions couple only through N).  A guard watches the orbit's
    penetration: when it would reach 0, which happens from A = A_c(omega) (not from
    A omega^2 = g: near resonance A_c is far lower), the kernel stops and the block
    continues with the full model from the same state.
``coulomb_friction`` (models A, B, C)
    Plain Coulomb friction instead of the Cundall-Strack spring: stuck (no relative
    tangential motion) while the needed force stays below mu_s N, else sliding against
    mu_s N.  Drops k_t and the history variable F.  Note the paper's static and kinetic
    coefficients are equal here, so the spring's reset - the source of the paper's
    stick-slip - has no counterpart: see docs/scene_reductions.md for what it changes.

Scheme: the paper's semi-implicit Euler step, with the rigid contact and the Coulomb
stick treated at velocity level (Moreau's time-stepping): the normal impulse is the one
that cancels the inward normal velocity, the friction force the one that stops the
tangential relative motion, clipped to +- mu_s N.  First order.
"""
import math

from . import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from .dynamics import contact, curvature_force, friction_rule
from .laws import contact_dissipation, contact_elastic, friction_spring_force
from .integrators.fixed_step import OK, STOP, book_energy, record_observation
from .integrators.plate import drive_sin_cos, phase_after, plate_after, plate_at
from .layout import (C_SLIPS, C_STEP, D_AMP, D_DT, D_EXT_A, D_OMEGA, D_T0, P_G, P_GN, P_GT, P_KD, P_KN, P_M,
                     P_MUS, P_VD, Y_DISSIPATED, Y_E_NORMAL, Y_F, Y_PHI, Y_VX, Y_VZ, Y_WORK, Y_X, Y_Z)
from .models import frame, load, profile
from .unowned import data_pointer

RIGID, FROZEN, COULOMB = 1, 2, 4
# The id of this scheme in the integrator registry (internal: chosen by the scene options).
SCHEME_ID = 100
# A rigidly attached block sits exactly on the surface; the plate's height recomputed at
# an output time (exact sin/cos instead of the step's recurrence) may differ in the last
# bits.  Penetrations down to -ATTACHED_TOLERANCE (1 + |z|) still count as attached: any
# real flight leaves the surface by far more within its first step.
ATTACHED_TOLERANCE = 1e-12


@njit(inline="always")
def orbit_response(prm, amplitude, omega):
    """Complex amplitude R of the steady orbit y = z - Z_p = -W/k_n + Im(R e^{i theta}) of
    m y'' + gamma_n y' + k_n y = -W + m A omega^2 sin(theta) (model A, W = m g)."""
    m, k_n, g_n = prm[P_M], prm[P_KN], prm[P_GN]
    response = m * amplitude * omega * omega / complex(k_n - m * omega * omega, g_n * omega)
    return response.real, response.imag


@njit(inline="always")
def frozen_penetration(prm, omega, r_re, r_im, s, c, ext_a):
    """Penetration and relative normal velocity u_n on the frozen vertical motion at the
    drive phase (sin s, cos c), with the external acceleration pressing quasi-statically."""
    m = prm[P_M]
    rot_re, rot_im = r_re * c - r_im * s, r_re * s + r_im * c
    return (m * (prm[P_G] + ext_a)) / prm[P_KN] - rot_im, omega * rot_re


@njit(inline="always")
def scene_step(kind, flags, prm, state, t, h, plate, frozen_end, track_energy):
    """One reduced step of length h from ``state`` = (x, z, vx, vz, F), ``plate`` = (height,
    velocity) at t and at t + h, ``frozen_end`` the frozen orbit's (penetration, u_n) at
    t + h.  Returns (x, z, vx, vz, F, engaged, N, T, d_phi, d_work,
    d_dissipated, d_normal): the new state, whether the block is in contact at its end,
    the normal force and the Coulomb friction force of the step (for the friction rule
    and the outputs), and the increments of the quadratures."""
    m = prm[P_M]
    x, z, vx, vz, shear = state
    pz0, pv0, pz1, pv1 = plate
    frozen_pen1, frozen_un1 = frozen_end
    rigid, frozen, coulomb = (flags & RIGID) != 0, (flags & FROZEN) != 0, (flags & COULOMB) != 0
    pen, u_n, u_t, c, s, normal = contact(kind, x, z, vx, vz, pz0, pv0, prm)
    plate_accel = (pv1 - pv0) / h
    engaged = pen > 0.0 or (rigid and pen >= -ATTACHED_TOLERANCE * (1.0 + abs(z))) or frozen
    # Forces other than the contact's normal force and the Coulomb friction.
    drive = -prm[P_KD] * (x - prm[P_VD] * t)
    load_x, load_z = load(kind, c, s, prm)
    tangential = -prm[P_GT] * u_t
    if engaged and not coulomb:
        tangential -= friction_spring_force(kind, shear, prm)
    fx = drive + load_x + tangential * c
    fz = load_z + tangential * s
    if not rigid and pen > 0.0:  # the compliant contact's full force, as in the full model
        fx += curvature_force(kind, x, pen, c, s, prm)
    if rigid:
        # The impulse that cancels the inward normal velocity relative to the plate's
        # velocity at the step end; none if the block would leave by itself.
        un_free = u_n + h / m * (-fx * s + fz * c) - plate_accel * h * c
        normal = -m * un_free / h if (engaged and un_free < 0.0) else 0.0
        engaged = normal > 0.0
    friction = 0.0
    stuck = False
    if coulomb and engaged and normal > 0.0:
        ut_free = u_t + h / m * (fx * c + fz * s) - plate_accel * h * s
        bound = prm[P_MUS] * normal
        friction = min(max(-m * ut_free / h, -bound), bound)
        stuck = abs(m * ut_free / h) <= bound
    fx += -normal * s + friction * c
    fz += normal * c + friction * s
    vx1 = vx + h / m * fx
    vz1 = vz + h / m * fz
    if stuck:  # no relative tangential motion at all, not a rounding residue of it
        slip = vx1 * c + (vz1 - pv1) * s
        vx1 -= slip * c
        vz1 -= slip * s
    x1 = x + h * vx1
    z1 = z + h * vz1
    height1, slope1 = profile(kind, x1, prm)
    c1, s1 = frame(slope1)
    if frozen:  # model A: the prescribed vertical motion
        z1, vz1 = pz1 + height1 - frozen_pen1, pv1 + frozen_un1
    impact = impact_work = 0.0
    engaged_end = engaged
    if rigid:
        landed = (pz1 + height1 - z1) * c1 > 0.0
        if engaged or landed:
            engaged_end = True
            z1 = pz1 + height1  # on the surface
            un1 = (vz1 - pv1) * c1 - vx1 * s1
            if un1 < 0.0:  # restitution 0: the inward normal velocity is lost
                vx1 += un1 * s1
                vz1 -= un1 * c1
                impact = 0.5 * m * un1 * un1
                impact_work = -m * un1 * c1 * pv1  # the moving plate's share of the impulse's work
    elif not frozen:
        engaged_end = (pz1 + height1 - z1) > 0.0
    if engaged and not coulomb:
        shear += h * (vx1 * c1 + (vz1 - pv1) * s1)  # dF = u_t dt at the new velocity
    d_work = d_dissipated = d_normal = 0.0
    if track_energy:
        # The plate's work: forces through its velocity at the step's start (as the paper's
        # scheme), but constraint impulses (rigid N, Coulomb stick) bring the block to the
        # plate's velocity at the step's end, so they work through the mean velocity.
        constraint_v = 0.5 * (pv0 + pv1)
        normal_v = constraint_v if rigid else pv0
        d_work = (prm[P_KD] * (prm[P_VD] * t - x) * prm[P_VD] * h
                  + (normal_v * normal * c + (pv0 * tangential + constraint_v * friction) * s) * h
                  + load_x * (x1 - x) + load_z * (z1 - z) + impact_work)
        d_dissipated = prm[P_GT] * u_t * u_t * h + impact
        if coulomb:
            d_dissipated -= friction * (vx1 * c1 + (vz1 - pv1) * s1) * h
        if not rigid and pen > 0.0:
            d_dissipated += contact_dissipation(kind, pen, u_n, prm) * h
            d_normal = -contact_elastic(kind, pen, prm) * u_n * h
    dv = vx1 - prm[P_VD]
    return x1, z1, vx1, vz1, shear, engaged_end, normal, friction, h * dv * dv, d_work, d_dissipated, d_normal


@njit(inline="always")
def _end_normal(kind, rigid, x, z, vx, vz, pz, pv, step_normal, prm):
    """The normal force the friction rule sees at a step's end: the step's constraint
    force for a rigid contact, the spring-dashpot's at the new state otherwise."""
    if rigid:
        return step_normal
    return contact(kind, x, z, vx, vz, pz, pv, prm)[5]


# Called by the driver's loop, not inlined into it (``fixed_step.register``): its rigid contact and impacts cost
# far more than the call, and inlined they doubled the loop's compile time.
INLINE_STEP = False


@njit(inline="always")
def prepare(kind, flags, drv, prm, h):
    """The frozen orbit's complex amplitude (``orbit_response``)."""
    return orbit_response(prm, drv[D_AMP], drv[D_OMEGA])


@njit(inline="always")
def step(kind, flags, ctx, prm, drv, state, contact0, clock, plate, track_energy):
    """One reduced step (``scene_step``) under the driver's contract.  With FROZEN it
    returns STOP, the step not taken, where the frozen orbit would lose contact at the
    step's end: the caller hands over to the full model there."""
    pz0, pv0, pzh, pvh, pz1, pv1, s1, c1 = plate[:8]  # (a scene refuses the oblique plate: no frame force)
    t, h, span = clock
    x, z, vx, vz, shear = state
    rigid, frozen, coulomb = (flags & RIGID) != 0, (flags & FROZEN) != 0, (flags & COULOMB) != 0
    pen_f, un_f = 0.0, 0.0
    if frozen:
        pen_f, un_f = frozen_penetration(prm, drv[D_OMEGA], ctx[0], ctx[1], s1, c1, drv[D_EXT_A])
        if pen_f <= 0.0:  # the guard: the block would detach here, hand over
            return STOP, x, z, vx, vz, shear, contact0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    x, z, vx, vz, shear, engaged, normal, friction, d_phi, d_work, d_dissipated, d_normal = scene_step(
        kind, flags, prm, state, t, h, (pz0, pv0, pz1, pv1), (pen_f, un_f), track_energy)
    if coulomb:  # no spring: nothing to reset (the driver's rule sees no contact and keeps F = 0)
        return OK, x, z, vx, vz, shear, contact0, 0.0, 0.0, d_phi, d_work, d_dissipated, d_normal
    end_normal = _end_normal(kind, rigid, x, z, vx, vz, pz1, pv1, normal, prm)
    # contact0 is passed on unused: the reduced step works out its contact itself.
    return (OK, x, z, vx, vz, shear, contact0, 1.0 if engaged else 0.0, end_normal, d_phi, d_work, d_dissipated,
            d_normal)


@njit(cache=True)
def observe(kind, method, flags, y, cnt, drv, prm, h, track_energy, obs):
    """``fixed_step.observe`` for a reduced block: the state at t_n + h (one scratch step
    from the grid state), and the contact state, normal and friction forces acting there
    (those of a step of dt starting at that state)."""
    prm, drv, cnt = data_pointer(prm), data_pointer(drv), data_pointer(cnt)
    dt = drv[D_DT]
    rigid, coulomb = (flags & RIGID) != 0, (flags & COULOMB) != 0
    r_re, r_im = orbit_response(prm, drv[D_AMP], drv[D_OMEGA])
    t = drv[D_T0] + cnt[C_STEP] * dt
    x, z, vx, vz, shear = y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F]
    phi, slips = y[Y_PHI], cnt[C_SLIPS]
    work, dissipated, e_normal = y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL]
    # At the grid point, the plate exactly as the kernel saw it (its sin/cos recurrence):
    # a rigidly attached block then sits on the surface to the last bit.
    s0, c0 = drive_sin_cos(drv, cnt, cnt[C_STEP])
    pz0, pv0 = plate_at(drv, s0, c0, t)
    if h > 0.0:
        pz1, pv1 = plate_after(drv, cnt, cnt[C_STEP], h)
        phase = phase_after(drv, cnt, cnt[C_STEP], h)
        pen_f, un_f = frozen_penetration(prm, drv[D_OMEGA], r_re, r_im, math.sin(phase), math.cos(phase),
                                         drv[D_EXT_A])
        x, z, vx, vz, shear, engaged, normal, friction, d_phi, d_work, d_dissipated, d_normal = scene_step(
            kind, flags, prm, (x, z, vx, vz, shear), t, h, (pz0, pv0, pz1, pv1), (pen_f, un_f), track_energy)
        loaded = shear
        if coulomb:
            shear = 0.0
        else:
            end_normal = _end_normal(kind, rigid, x, z, vx, vz, pz1, pv1, normal, prm)
            shear, _, reset = friction_rule(kind, shear, 0.0, 1.0 if engaged else 0.0, end_normal, 0.0, h,
                                            prm)  # (scenes run the paper's law, which has no state)
            slips += reset
        phi += d_phi
        work, dissipated, e_normal = book_energy(kind, prm, (work, dissipated, e_normal),
                                                 (d_work, d_dissipated, d_normal), loaded, shear, track_energy)
        t += h
        pz0, pv0 = pz1, pv1
    # The forces acting at the reported state: those of a step of dt starting there.
    pz2, pv2 = plate_after(drv, cnt, cnt[C_STEP], h + dt)
    phase = phase_after(drv, cnt, cnt[C_STEP], h + dt)
    pen_f, un_f = frozen_penetration(prm, drv[D_OMEGA], r_re, r_im, math.sin(phase), math.cos(phase), drv[D_EXT_A])
    probe = scene_step(kind, flags, prm, (x, z, vx, vz, shear), t, dt, (pz0, pv0, pz2, pv2), (pen_f, un_f), False)
    pen, u_n, u_t, cos_a, sin_a, normal = contact(kind, x, z, vx, vz, pz0, pv0, prm)
    in_contact = pen > 0.0
    if rigid:
        normal = probe[6]
        in_contact = pen >= -ATTACHED_TOLERANCE * (1.0 + abs(z)) and normal > 0.0
    friction = probe[7] if coulomb else (-friction_spring_force(kind, shear, prm) if in_contact else 0.0)
    return record_observation(obs, (x, z, vx, vz, shear), (pen, normal, cos_a, in_contact),
                              (phi, slips, work, dissipated, e_normal), t, friction)
