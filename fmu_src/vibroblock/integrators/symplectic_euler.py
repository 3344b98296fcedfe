"""``symplectic_euler`` (id 0): the paper's first-order scheme, as we read it.

Velocity first, then position with the new velocity (semi-implicit Euler); the shear
displacement grows by h times the new tangential velocity while the step started in
contact, so on a flat plate F is exactly the horizontal travel since contact began.  In the tangent frame the same step on (x, zeta, u, w): the foot moves
by h u cos a at the step's starting slope.
First order, one force evaluation per step; stable while dt^2 k/m + 2 dt gamma/m <= 4
for each spring-dashpot (we ask <= 1, which keeps the contact's ringing resolved).
"""
from .. import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ..dynamics import contact, energy_rates, force, position_rates
from ..layout import P_M, P_VD


@njit(inline="always")
def prepare(kind, flags, drv, prm, h):
    return 0


@njit(inline="always")
def euler_step(kind, prm, state, t, h, contact_now, plate, track_energy, push):
    """One semi-implicit Euler step of length h from ``state`` = (x, z, vx, vz, F), whose
    contact quantities ``contact_now`` are known, ``plate`` = (its velocity at t, height
    and velocity at t + h); returns the new state, its contact quantities, and the
    increments of phi, work, dissipation and normal-spring energy.  ``push`` is an
    extra horizontal force from outside the block (a chain's coupling springs, whose
    energy the chain books itself)."""
    x, z, vx, vz, shear = state
    plate_v, pz1, pv1 = plate
    h_over_m = h / prm[P_M]
    pen, u_n, u_t, cos_a, sin_a, normal = contact_now
    fx, fz = force(kind, x, t, pen > 0.0, pen, normal, u_t, cos_a, sin_a, shear, prm)
    d_work = d_dissipated = d_normal = 0.0
    if track_energy:
        work, dissipation, storage = energy_rates(kind, x, (vx, vz), shear, t, pen > 0.0, contact_now, plate_v, prm)
        d_work, d_dissipated, d_normal = h * work, h * dissipation, h * storage
    engaged = pen > 0.0
    if push != 0.0:  # (a lone block adds nothing, not even the sign of a zero)
        fx += push
    vx += h_over_m * fx
    vz += h_over_m * fz
    rate_x, rate_z = position_rates(kind, vx, vz, cos_a)  # (vx, vz) for a point
    x += h * rate_x
    z += h * rate_z
    contact_new = contact(kind, x, z, vx, vz, pz1, pv1, prm)
    if engaged:
        shear += h * contact_new[2]
    dv = rate_x - prm[P_VD]
    return x, z, vx, vz, shear, contact_new, h * dv * dv, d_work, d_dissipated, d_normal


@njit(inline="always")
def step(kind, flags, ctx, prm, drv, state, contact0, clock, plate, track_energy):
    pz0, pv0, pzh, pvh, pz1, pv1, s1, c1, frame0, frame_half, frame1 = plate
    t, h, span = clock
    x, z, vx, vz, shear, contact1, d_phi, d_work, d_dissipated, d_normal = euler_step(
        kind, prm, state, t, h, contact0, (pv0, pz1, pv1), track_energy, frame0)
    if track_energy and frame0 != 0.0:  # the plate frame's force works on the block (laws.plate_oblique)
        d_work += h * frame0 * state[2]
    return (0, x, z, vx, vz, shear, contact1, contact1[0], contact1[5], d_phi, d_work, d_dissipated, d_normal)
