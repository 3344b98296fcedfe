"""The one fixed-step driver: every fixed-step scheme is a ``step`` function run by it.

A scheme module provides two compiled functions (``symplectic_euler.py`` is the
smallest example):

``prepare(kind, flags, drv, prm, h) -> ctx``
    what the scheme computes once per call for steps of length h (a propagator table,
    scratch arrays, ...); any tuple.
``step(kind, flags, ctx, prm, drv, state, contact0, clock, plate, track_energy)``
    one step of length h from ``state`` = (x, z, vx, vz, F) at time t, ``clock`` =
    (t, h, span), whose contact quantities
    ``contact0`` (``dynamics.contact``: penetration, u_n, u_t, cos a, sin a, N) are
    known (in the tangent frame the slots hold (x, zeta, u, w), ``dynamics``).  ``span`` is the step as the difference of the grid times it joins (differs
    from h by rounding; a scheme uses one or the other, always the same).  ``plate`` is
    (height, velocity) at t, at t + span/2 and at t + h, and the drive's (sin, cos) at
    t + h.  Returns (status, x, z, vx, vz, F, contact1, rule_penetration, rule_normal,
    d_phi, d_work, d_dissipated, d_normal): status 0, STOP (the step is not taken: a
    scene's guard hands over) or a negative failure code; the contact quantities at
    the new state; what the friction rule is to see there (the penetration and the
    contact force; the driver swaps in the applied load when the run's Coulomb bound is
    that, ``dynamics.coulomb_bound``); and the step's increments of the quadratures.

The driver owns everything else: the grid and the plate drive, the friction rule and
the quadratures at the end of every step (``settle``), the counters, the finite-state
checks, and leaving the arrays untouched on failure (the contract in ``__init__``).
Which scheme runs is a compile-time constant (``method``, a literal) whose ``prepare``
and ``step`` are inlined into the loop (``scheme_step``), and the loop reads the
parameter, drive and counter arrays through their data pointers (``unowned``): with no
call and no reference count left in it, the loop costs what a hand-written one would.
"""
import math

from .. import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import literally, njit, types
from numba.extending import overload

from ..dispatch import called
from ..dynamics import contact, coulomb_bound, friction_rule
from ..laws import friction_released, friction_spring_force, plate_moves_sideways
from ..unowned import data_pointer, keep_alive, unowned_each
from ..layout import (C_SLIPS, C_STEP, D_DT, D_OMEGA, D_T0, N_OBS, O_CONTACT, O_COS, O_DISSIPATED, O_E_NORMAL,
                      O_F, O_FRICTION, O_NORMAL, O_PENETRATION, O_PHI, O_PLATE_VX, O_PLATE_X, O_SLIPS, O_T, O_VX,
                      O_VZ, O_WORK, O_X, O_Z,
                      Y_DISSIPATED, Y_E_NORMAL, Y_F, Y_PHI, Y_PHI_C, Y_FRICTION_STATE, Y_VX, Y_VZ, Y_WORK, Y_X, Y_Z)
from .plate import (drive_sin_cos, frame_force, next_sin_cos, phase_after, plate_after, plate_at, plate_moves,
                    plate_sideways)

OK, STOP = 0, 1
NON_FINITE = -1
# How often (in steps) a long run checks that the state is still finite.
FINITE_CHECK = 1 << 16

# method id -> (prepare, step), filled by the registry (``integrators.__init__``, through
# ``register``) before anything is compiled.
SCHEMES = {}

STEP_ARGUMENTS = "kind, flags, ctx, prm, drv, state, contact0, clock, plate, track_energy"


def register(method: int, prepare, step, inline_step: bool = True) -> None:
    """Make scheme ``method`` known to the driver.  ``inline_step``: the step is inlined
    into the loop (no call per step: a model-A Euler step costs 15 % less), else called
    (a heavier step, whose call costs little against it, compiled once: inlined into the
    loop LLVM's time roughly doubles, and a first use would exceed its 30 s budget)."""
    SCHEMES[method] = (prepare, step if inline_step else called(step, STEP_ARGUMENTS))


def scheme_prepare(method, kind, flags, drv, prm, h):
    """``prepare`` of scheme ``method`` (compiled code only)."""


def scheme_step(method, kind, flags, ctx, prm, drv, state, contact0, clock, plate, track_energy):
    """``step`` of scheme ``method`` (compiled code only)."""


# Inlined where they are called, and the scheme's function inlined in turn.  Handed out as
# a function value instead, the step stayed a call that passed and returned ~20 values
# through memory: 15 % of a model-A Euler step (17.0 against 14.8 ns).
@overload(scheme_prepare, inline="always")
def _prepare_of(method, kind, flags, drv, prm, h):
    if isinstance(method, types.IntegerLiteral):
        prepare = SCHEMES[method.literal_value][0]
        return lambda method, kind, flags, drv, prm, h: prepare(kind, flags, drv, prm, h)
    return None


def scheme_step_function(method):
    """``step`` of scheme ``method`` as a function value (compiled code only): called, not
    inlined, where a step is taken once per call (``observe``), so that the step's code
    is compiled once for the kernels, not once more per caller."""


@overload(scheme_step_function)
def _step_function_of(method):
    if isinstance(method, types.IntegerLiteral):
        step = SCHEMES[method.literal_value][1]
        return lambda method: step
    return None


@overload(scheme_step, inline="always")
def _step_of(method, kind, flags, ctx, prm, drv, state, contact0, clock, plate, track_energy):
    if isinstance(method, types.IntegerLiteral):
        step = SCHEMES[method.literal_value][1]
        return (lambda method, kind, flags, ctx, prm, drv, state, contact0, clock, plate, track_energy:
                step(kind, flags, ctx, prm, drv, state, contact0, clock, plate, track_energy))
    return None


@njit(inline="always")
def kahan_add(total, compensation, value):
    corrected = value - compensation
    new_total = total + corrected
    return new_total, (new_total - total) - corrected


@njit(inline="always")
def record_observation(obs, state, contact_now, sums, t, friction):
    """Fill the observation array (``layout.O_*``): the one layout every observe kernel
    returns.  ``state`` = (x, z, vx, vz, F); ``contact_now`` = (penetration, normal force,
    cos a, in contact); ``sums`` = (phi, resets, work, dissipated, normal spring energy)."""
    x, z, vx, vz, shear = state
    penetration, normal, cos_a, in_contact = contact_now
    phi, slips, work, dissipated, e_normal = sums
    obs[O_X], obs[O_Z], obs[O_VX], obs[O_VZ], obs[O_F] = x, z, vx, vz, shear
    obs[O_PENETRATION], obs[O_NORMAL], obs[O_COS] = penetration, normal, cos_a
    obs[O_PHI], obs[O_SLIPS], obs[O_T] = phi, slips, t
    obs[O_WORK], obs[O_DISSIPATED], obs[O_E_NORMAL] = work, dissipated, e_normal
    obs[O_CONTACT] = 1.0 if in_contact else 0.0
    obs[O_FRICTION] = friction
    obs[O_PLATE_X] = obs[O_PLATE_VX] = 0.0
    return N_OBS


@njit(inline="always")
def is_finite_state(x, z, vx, vz, shear):
    return math.isfinite(x + z + vx + vz + shear)


@njit(inline="always")
def book_energy(kind, prm, energies, increments, loaded, shear, track_energy):
    """The energy balance's sums (work, dissipated, normal spring) after a step with these
    increments; a reset of the spring from ``loaded`` to ``shear`` releases what the
    friction law says, counted as dissipated."""
    work, dissipated, e_normal = energies
    if track_energy:
        d_work, d_dissipated, d_normal = increments
        work += d_work
        dissipated += d_dissipated + friction_released(kind, loaded, shear, prm)
        e_normal += d_normal
    return work, dissipated, e_normal


@njit(inline="always")
def settle(kind, prm, friction, rule, slips, sums, increments, track_energy):
    """End of every step of every scheme: the friction rule at the new state (``friction``
    = the shear displacement and the law's state, ``rule`` = the penetration, the bound's
    N and the slip rate there, and the step's length), then the step's quadratures: ``sums`` = (phi, its
    compensation, work, dissipated, normal spring energy), ``increments`` the step's (phi,
    work, dissipated, normal spring).  Returns (F, state, slips, *sums)."""
    phi, phi_c, work, dissipated, e_normal = sums
    loaded = shear = friction[0]
    shear, state, reset = friction_rule(kind, shear, friction[1], rule[0], rule[1], rule[2], rule[3], prm)
    phi, phi_c = kahan_add(phi, phi_c, increments[0])
    work, dissipated, e_normal = book_energy(kind, prm, (work, dissipated, e_normal), increments[1:], loaded, shear,
                                             track_energy)
    return shear, state, slips + reset, phi, phi_c, work, dissipated, e_normal


@njit(cache=True)
def advance(kind, method, flags, y, cnt, drv, prm, n_steps, track_energy):
    """Advance by up to n_steps grid steps with scheme ``method``.  Returns OK, STOP (a
    scene's guard stopped before a step; the steps taken so far are stored) or a
    negative failure code (the arrays are left as they were on entry)."""
    method = literally(method)
    prm, drv, cnt = data_pointer(prm), data_pointer(drv), data_pointer(cnt)
    t0, dt = drv[D_T0], drv[D_DT]
    # The step reads the scheme's arrays (tables, scratch) through unowned views: a
    # counted array passed to a step that is called, not inlined, costs atomic counts.
    owned_ctx = scheme_prepare(method, kind, flags, drv, prm, dt)
    ctx = unowned_each(owned_ctx)
    moving = plate_moves(drv)
    x, z, vx, vz, shear, friction_state = y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F], y[Y_FRICTION_STATE]
    phi, phi_c = y[Y_PHI], y[Y_PHI_C]
    work, dissipated, e_normal = y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL]
    n, slips = cnt[C_STEP], cnt[C_SLIPS]
    rot_s, rot_c = math.sin(drv[D_OMEGA] * dt), math.cos(drv[D_OMEGA] * dt)
    half_s, half_c = math.sin(0.5 * drv[D_OMEGA] * dt), math.cos(0.5 * drv[D_OMEGA] * dt)
    s, c = drive_sin_cos(drv, cnt, n)
    t = t0 + n * dt
    pz0, pv0 = plate_at(drv, s, c, t)
    contact0 = contact(kind, x, z, vx, vz, pz0, pv0, prm)
    # An oblique plate's run is integrated in the plate's frame, moved by its force.
    sideways = plate_moves_sideways(kind)
    frame0 = frame_force(kind, drv, prm, s, c, t) if sideways else 0.0
    frame_half = frame1 = 0.0
    status = OK
    done = 0
    while done < n_steps:
        n1 = n + 1
        t1 = t0 + n1 * dt
        if moving:
            s_half, c_half = s * half_c + c * half_s, c * half_c - s * half_s
            pzh, pvh = plate_at(drv, s_half, c_half, t + 0.5 * dt)
            if sideways:
                frame_half = frame_force(kind, drv, prm, s_half, c_half, t + 0.5 * dt)
            s, c = next_sin_cos(drv, cnt, n1, s, c, rot_s, rot_c)
            pz1, pv1 = plate_at(drv, s, c, t1)
        else:
            pzh, pvh, pz1, pv1 = pz0, pv0, pz0, pv0
            if sideways:
                frame_half = frame_force(kind, drv, prm, s, c, t + 0.5 * dt)
        if sideways:
            frame1 = frame_force(kind, drv, prm, s, c, t1)
        (status, x1, z1, vx1, vz1, shear1, contact1, rule_pen, rule_normal, d_phi, d_work, d_dissipated,
         d_normal) = scheme_step(method, kind, flags, ctx, prm, drv, (x, z, vx, vz, shear), contact0,
                                 (t, dt, t1 - t), (pz0, pv0, pzh, pvh, pz1, pv1, s, c, frame0, frame_half, frame1),
                                 track_energy)
        if status != OK:
            if status < 0:
                return status
            break
        x, z, vx, vz, contact0 = x1, z1, vx1, vz1, contact1
        rule_normal = coulomb_bound(kind, rule_normal, x, t1, prm)  # the contact force, or the applied load
        shear, friction_state, slips, phi, phi_c, work, dissipated, e_normal = settle(
            kind, prm, (shear1, friction_state), (rule_pen, rule_normal, contact1[2], dt), slips,
            (phi, phi_c, work, dissipated, e_normal), (d_phi, d_work, d_dissipated, d_normal), track_energy)
        n, t, pz0, pv0, frame0 = n1, t1, pz1, pv1, frame1
        done += 1
        if (done & (FINITE_CHECK - 1)) == 0 and not is_finite_state(x, z, vx, vz, shear):
            return NON_FINITE
    keep_alive(owned_ctx)
    if not is_finite_state(x, z, vx, vz, shear):
        return NON_FINITE
    y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F], y[Y_FRICTION_STATE] = x, z, vx, vz, shear, friction_state
    y[Y_PHI], y[Y_PHI_C] = phi, phi_c
    y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL] = work, dissipated, e_normal
    cnt[C_STEP], cnt[C_SLIPS] = n, slips
    return status


@njit(cache=True)
def observe(kind, method, flags, y, cnt, drv, prm, h, track_energy, obs):
    """Fill ``obs`` (``layout.O_*``) with the state at t_n + h, 0 <= h < dt, without
    touching the stored state.

    A communication point between two grid points is reached by one scratch step of
    length h from the grid state, the plate taken exactly (not by the loop's
    recurrence) at t_n, t_n + h/2 and t_n + h: outputs are at the requested time while
    the stored trajectory stays on the grid, independent of the communication steps.
    A scratch step that fails leaves the grid state (with the plate at t_n + h)."""
    method = literally(method)
    step = scheme_step_function(method)
    prm, drv, cnt = data_pointer(prm), data_pointer(drv), data_pointer(cnt)
    t = drv[D_T0] + cnt[C_STEP] * drv[D_DT]
    x, z, vx, vz, shear = y[Y_X], y[Y_Z], y[Y_VX], y[Y_VZ], y[Y_F]
    phi, slips = y[Y_PHI], cnt[C_SLIPS]
    work, dissipated, e_normal = y[Y_WORK], y[Y_DISSIPATED], y[Y_E_NORMAL]
    n = cnt[C_STEP]
    pz0, pv0 = plate_after(drv, cnt, n, 0.0)
    state_contact = contact(kind, x, z, vx, vz, pz0, pv0, prm)
    sideways = plate_moves_sideways(kind)
    if h > 0.0:
        ctx = scheme_prepare(method, kind, flags, drv, prm, h)
        pzh, pvh = plate_after(drv, cnt, n, 0.5 * h)
        phase1 = phase_after(drv, cnt, n, h)
        s1, c1 = math.sin(phase1), math.cos(phase1)
        pz1, pv1 = plate_at(drv, s1, c1, t + h)
        frame0 = frame_half = frame1 = 0.0
        if sideways:
            frame0, frame_half = frame_after(kind, drv, cnt, prm, n, 0.0), frame_after(kind, drv, cnt, prm, n, 0.5 * h)
            frame1 = frame_force(kind, drv, prm, s1, c1, t + h)
        (status, x1, z1, vx1, vz1, shear1, contact1, rule_pen, rule_normal, d_phi, d_work, d_dissipated,
         d_normal) = step(kind, flags, ctx, prm, drv, (x, z, vx, vz, shear), state_contact, (t, h, h),
                          (pz0, pv0, pzh, pvh, pz1, pv1, s1, c1, frame0, frame_half, frame1), track_energy)
        if status == OK:
            x, z, vx, vz, shear = x1, z1, vx1, vz1, shear1
        else:
            d_phi = d_work = d_dissipated = d_normal = 0.0
        state_contact = contact(kind, x, z, vx, vz, pz1, pv1, prm)
        if status != OK:
            rule_pen, rule_normal = state_contact[0], state_contact[5]
        rule_normal = coulomb_bound(kind, rule_normal, x, t + h, prm)
        loaded = shear
        shear, _, reset = friction_rule(kind, shear, y[Y_FRICTION_STATE], rule_pen, rule_normal, state_contact[2], h,
                                        prm)
        slips += reset
        phi += d_phi
        work, dissipated, e_normal = book_energy(kind, prm, (work, dissipated, e_normal),
                                                 (d_work, d_dissipated, d_normal), loaded, shear, track_energy)
        t += h
    pen, u_n, u_t, cos_a, sin_a, normal = state_contact
    record_observation(obs, (x, z, vx, vz, shear), (pen, normal, cos_a, pen > 0.0),
                       (phi, slips, work, dissipated, e_normal),
                       t, -friction_spring_force(kind, shear, prm) if pen > 0.0 else 0.0)
    if sideways:  # the lab's x and vx: the plate frame's plus the plate's
        phase = phase_after(drv, cnt, n, h)
        plate_x, plate_vx, _ = plate_sideways(kind, drv, math.sin(phase), math.cos(phase), t)
        obs[O_X], obs[O_VX] = x + plate_x, vx + plate_vx
        obs[O_PLATE_X], obs[O_PLATE_VX] = plate_x, plate_vx
    return N_OBS


@njit(inline="always")
def frame_after(kind, drv, cnt, prm, n, h):
    """The plate frame's force a time h after grid step n (off the grid): exact sin/cos."""
    phase = phase_after(drv, cnt, n, h)
    return frame_force(kind, drv, prm, math.sin(phase), math.cos(phase), drv[D_T0] + n * drv[D_DT] + h)
