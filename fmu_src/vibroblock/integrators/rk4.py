"""``rk4`` (id 1): classical fourth-order Runge-Kutta on (x, z, vx, vz, F, phi) (in the
tangent frame on (x, zeta, u, w, F, phi), the position moving at ``position_rates``).

The contact gate Theta(delta) is evaluated inside each stage; the friction rule is the
driver's, after the step.  Fourth order between events, first order across a contact
switch or a reset.  Four force evaluations per step; stable while
dt^2 k/m + 2 dt gamma/m <= 8 (imaginary axis) or ~5.6 (real axis): we ask <= 4.
"""
from .. import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ..dynamics import contact, energy_rates, force, position_rates
from ..layout import P_M, P_VD


# Called by the driver's loop, not inlined into it (``fixed_step.register``): four stages cost
# far more than the call, and inlined they doubled the loop's compile time.
INLINE_STEP = False


@njit(inline="always")
def prepare(kind, flags, drv, prm, h):
    return 0


@njit(inline="always")
def _rates(kind, prm, state, t, plate_v, push, contact_now, track_energy):
    """Accelerations, dF/dt, and the rates of the quadratures (phi, work, dissipation,
    normal-spring energy) at one stage, ``state`` = (x, z, vx, vz, F), whose contact
    quantities ``contact_now`` (``dynamics.contact``) are known; ``push`` is the plate
    frame's horizontal force (``laws.plate_oblique``), whose work is booked."""
    x, z, vx, vz, shear = state
    pen, u_n, u_t, cos_a, sin_a, normal = contact_now
    fx, fz = force(kind, x, t, pen > 0.0, pen, normal, u_t, cos_a, sin_a, shear, prm)
    d_shear = u_t if pen > 0.0 else 0.0
    rate_x, rate_z = position_rates(kind, vx, vz, cos_a)  # (vx, vz) for a point
    dv = rate_x - prm[P_VD]
    work = dissipation = storage = 0.0
    if track_energy:
        work, dissipation, storage = energy_rates(kind, x, (vx, vz), shear, t, pen > 0.0, contact_now, plate_v, prm)
    if push != 0.0:  # (a vertical plate adds nothing, not even the sign of a zero)
        fx += push
        work += push * vx
    return rate_x, rate_z, fx / prm[P_M], fz / prm[P_M], d_shear, dv * dv, work, dissipation, storage


# Compiled once and called by stages 2-4: inlining it at every stage cost three to five
# times the compile time (21-46 s against 8-9 s for rk4's advance kernel) for little
# speed, since its arguments are scalars and the parameters a pointer.  The first stage's
# rates are inlined into the step (one copy, some 3 s more compile time): called as a
# function instead, they left rk4 on model B at 0.85-0.88x e856204's speed, not 1.0x.
@njit
def stage_rates(kind, prm, x, z, vx, vz, shear, t, plate_z, plate_v, push, track_energy):
    """``_rates`` at a stage's state, its contact quantities evaluated there."""
    contact_now = contact(kind, x, z, vx, vz, plate_z, plate_v, prm)
    return _rates(kind, prm, (x, z, vx, vz, shear), t, plate_v, push, contact_now, track_energy)


@njit(inline="always")
def rk4_step(kind, prm, state, t, h, plate, contact0, track_energy):
    """One classical RK4 step of length h from ``state`` = (x, z, vx, vz, F), whose contact
    quantities at the plate's height and velocity at t are ``contact0``, ``plate`` =
    (height, velocity) at t, t + h/2 and t + h, the drive's (sin, cos) at t + h and the
    plate frame's force at t, t + h/2 and t + h; returns the new state and the increments
    of phi, work, dissipation and normal-spring energy."""
    x, z, vx, vz, shear = state
    pz0, pv0, pz_half, pv_half, pz1, pv1 = plate[:6]
    push0, push_half, push1 = plate[8:11]
    half = 0.5 * h
    # The first stage is at the step's start, whose contact quantities the driver has
    # already evaluated (at the previous step's end, with the same state and plate): one
    # surface evaluation (sin, cos and a square root on a corrugated plate) fewer of the
    # step's five, with bit-identical results.
    rx1, rz1, ax1, az1, df1, p1, w1, d1, e1 = _rates(kind, prm, state, t, pv0, push0, contact0, track_energy)
    vx2, vz2 = vx + half * ax1, vz + half * az1
    rx2, rz2, ax2, az2, df2, p2, w2, d2, e2 = stage_rates(kind, prm, x + half * rx1, z + half * rz1, vx2, vz2,
                                                   shear + half * df1, t + half, pz_half, pv_half, push_half,
                                                   track_energy)
    vx3, vz3 = vx + half * ax2, vz + half * az2
    rx3, rz3, ax3, az3, df3, p3, w3, d3, e3 = stage_rates(kind, prm, x + half * rx2, z + half * rz2, vx3, vz3,
                                                   shear + half * df2, t + half, pz_half, pv_half, push_half,
                                                   track_energy)
    vx4, vz4 = vx + h * ax3, vz + h * az3
    rx4, rz4, ax4, az4, df4, p4, w4, d4, e4 = stage_rates(kind, prm, x + h * rx3, z + h * rz3, vx4, vz4,
                                                   shear + h * df3, t + h, pz1, pv1, push1, track_energy)
    sixth = h / 6.0
    return (x + sixth * (rx1 + 2.0 * rx2 + 2.0 * rx3 + rx4),
            z + sixth * (rz1 + 2.0 * rz2 + 2.0 * rz3 + rz4),
            vx + sixth * (ax1 + 2.0 * ax2 + 2.0 * ax3 + ax4),
            vz + sixth * (az1 + 2.0 * az2 + 2.0 * az3 + az4),
            shear + sixth * (df1 + 2.0 * df2 + 2.0 * df3 + df4),
            sixth * (p1 + 2.0 * p2 + 2.0 * p3 + p4),
            sixth * (w1 + 2.0 * w2 + 2.0 * w3 + w4),
            sixth * (d1 + 2.0 * d2 + 2.0 * d3 + d4),
            sixth * (e1 + 2.0 * e2 + 2.0 * e3 + e4))


@njit(inline="always")
def step(kind, flags, ctx, prm, drv, state, contact0, clock, plate, track_energy):
    # The step is the difference of the grid times it joins (span), so that its stages
    # sit at the times the plate was evaluated for.
    t, h, span = clock
    x, z, vx, vz, shear, d_phi, d_work, d_dissipated, d_normal = rk4_step(kind, prm, state, t, span, plate,
                                                                          contact0, track_energy)
    pz1, pv1 = plate[4], plate[5]
    contact1 = contact(kind, x, z, vx, vz, pz1, pv1, prm)
    return (0, x, z, vx, vz, shear, contact1, contact1[0], contact1[5], d_phi, d_work, d_dissipated, d_normal)
