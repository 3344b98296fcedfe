"""Forces shared by all model variants, written once in global coordinates.

Formulation (docs/physics.md gives the derivation).  The block is a point r = (x, z);
the plate surface is Z_p(x, t) = plate(t) + height(x), moving vertically only.  At the
block's abscissa the surface has unit tangent t = (cos a, sin a) and outward normal
n = (-sin a, cos a), a = arctan(dZ_p/dx).  Newton's law m r'' = sum of forces with

* drive spring      (-k_d (x - V_d t), 0)
* confining load    the variant's ``load`` (gravity, or -P_l n)
* normal contact    N n,   N = k_n delta - gamma_n u_n            (only while delta > 0)
* tangential        (-k_t F - gamma_t u_t) t                     (k_t F only while delta > 0)

where delta = (Z_p - z) cos a is the penetration measured along the normal (distance
to the surface's tangent line), u_n = (r' - plate'(t) e_z) . n and
u_t = (r' - plate'(t) e_z) . t are the block's velocity relative to the plate, and F is
the Cundall-Strack shear displacement, dF/dt = u_t while in contact.  Projected on t
and n these are the paper's Eqs. (3)-(6); with a flat plate (a = 0) they are Eqs. (1)-(2)
exactly.  N may be negative while the dashpot pulls the separating block: the paper's
Heaviside factors gate on penetration only, and we follow them literally.

That is the default reading (``formulation = 0``, fixed axes).  The run's readings are
compile-time constants of ``kind`` (``vibroblock.readings``); the functions below branch
on them and the default's branches are the only ones compiled into its kernels:

* ``tangent_frame``: the paper's Eqs. (3)-(6) as printed (docs/physics.md, Sec. 4).
  The state slots (x, z, vx, vz) hold (x, zeta, u, w): the foot's abscissa, the normal
  coordinate, the tangential and the normal rate.  delta = P(t) - zeta, u_n = w - P'(t),
  u_t = u; "fx, fz" are the forces along the local tangent and normal; the position
  moves by (u cos a, w) (``position_rates``).  Outputs map to a point in ``Block``.
* ``applied_load``: the Coulomb bound's N is N_a = -(load + drive spring) . n
  (``coulomb_bound``), the drivers' friction rule sees it instead of the contact force.
* ``free_flight`` (fixed axes): off contact the block is a free particle of Eqs. (1)-(2):
  ``contact`` hands the forces the fixed axes as its frame (cos a = 1, sin a = 0,
  u_t = vx), so the load is vertical and the dashpot acts on vx.
"""
import math

from . import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from .laws import bound_normal, contact_dissipation, contact_elastic, contact_force, friction_spring_force
from .laws import friction_rule as law_friction_rule
# The one plate law, for the integrators.
from .laws.plate_vertical import acceleration as plate_acceleration, motion as plate_motion  # noqa: F401
from .layout import P_GT, P_KD, P_VD
from .laws import contact_conservative
from .models import curvature, flat_plate, frame, load, profile  # noqa: F401  (frame: the surface's, for the integrators)
from .readings import free_flight, tangent_frame


@njit(inline="always")
def normal_force(kind, penetration, u_n, prm):
    """The contact law's normal force N, 0 out of contact (``laws``: contact)."""
    if penetration > 0.0:
        return contact_force(kind, penetration, u_n, prm)
    return 0.0


@njit(inline="always")
def contact(kind, x, z, vx, vz, plate_z, plate_v, prm):
    """Penetration, normal and tangential velocity relative to the plate, the tangent,
    and the normal contact force N (0 out of contact)."""
    penetration, u_n, u_t, cos_a, sin_a, normal = surface_contact(kind, x, z, vx, vz, plate_z, plate_v, prm)
    if free_flight(kind) and not penetration > 0.0:  # a free particle: the fixed axes are its frame
        return penetration, u_n, vx, 1.0, 0.0, 0.0
    return penetration, u_n, u_t, cos_a, sin_a, normal


@njit(inline="always")
def surface_contact(kind, x, z, vx, vz, plate_z, plate_v, prm):
    """``contact`` on the surface under the block whatever the flight reading: with
    ``flight = free`` off contact it still returns the surface's frame (u_t, cos a, sin a),
    the frame of a contact phase continued across delta = 0 (the adaptive integrator's)."""
    if flat_plate(kind):  # the lab's frame (models.flat_plate): no products by cos a = 1, sin a = 0
        penetration = plate_z - z
        u_n = vz - plate_v
        return penetration, u_n, vx, 1.0, 0.0, normal_force(kind, penetration, u_n, prm)
    height, slope = profile(kind, x, prm)
    cos_a, sin_a = frame(slope)
    if tangent_frame(kind):  # state (x, zeta, u, w): the plate moves along the local normal
        penetration = plate_z - z
        u_n = vz - plate_v
        return penetration, u_n, vx, cos_a, sin_a, normal_force(kind, penetration, u_n, prm)
    penetration = (plate_z + height - z) * cos_a
    rel_vz = vz - plate_v
    u_n = rel_vz * cos_a - vx * sin_a
    u_t = vx * cos_a + rel_vz * sin_a
    return penetration, u_n, u_t, cos_a, sin_a, normal_force(kind, penetration, u_n, prm)


@njit(inline="always")
def position_rates(kind, vx, vz, cos_a):
    """Rates of the position slots: (vx, vz) for a point; (u cos a, w) in the tangent frame,
    whose foot advances along the surface at the tangential rate u."""
    if tangent_frame(kind):
        return vx * cos_a, vz
    return vx, vz


@njit(inline="always")
def frame_load(kind, cos_a, sin_a, prm):
    """The load's components along the local tangent and normal, (L.t, L.n)."""
    load_x, load_z = load(kind, cos_a, sin_a, prm)
    return load_x * cos_a + load_z * sin_a, load_z * cos_a - load_x * sin_a


@njit(inline="always")
def curvature_force(kind, x, penetration, cos_a, sin_a, prm):
    """The x-component the gradient of a conservative contact's potential U(delta) adds to
    its normal force N n on a curved plate in fixed axes: U'(delta) delta tan(a) da/dx
    = U'(delta) delta sin(a) cos(a) h''(x), since delta = (Z_p - z) cos(a) varies with x
    through cos(a) too (docs/physics.md, Sec. 9).  Zero on a flat plate, in the tangent
    frame (whose equations have no curvature terms), and for a law that is not conservative."""
    if sin_a == 0.0 or tangent_frame(kind) or not contact_conservative(kind):
        return 0.0
    return contact_elastic(kind, penetration, prm) * penetration * sin_a * cos_a * curvature(kind, x, prm)


@njit(inline="always")
def force(kind, x, t, engaged, penetration, normal, u_t, cos_a, sin_a, shear, prm):
    """Total force on the block (callers divide by m once per step, not per call).
    ``engaged`` gates the contact's tangential spring and curvature term (a scheme that
    continues a contact phase across delta = 0 keeps it open); ``penetration`` is delta."""
    tangential = -prm[P_GT] * u_t
    if engaged:
        tangential -= friction_spring_force(kind, shear, prm)
    if tangent_frame(kind):  # along the local tangent and normal (Eqs. 3-6)
        stretch = prm[P_KD] * (x - prm[P_VD] * t)
        load_t, load_n = frame_load(kind, cos_a, sin_a, prm)
        return -stretch * cos_a + tangential + load_t, normal + stretch * sin_a + load_n
    if flat_plate(kind):  # the lab's frame: the normal force along z, the tangential along x
        load_x, load_z = load(kind, 1.0, 0.0, prm)
        return -prm[P_KD] * (x - prm[P_VD] * t) + tangential + load_x, normal + load_z
    load_x, load_z = load(kind, cos_a, sin_a, prm)
    fx = -prm[P_KD] * (x - prm[P_VD] * t) - normal * sin_a + tangential * cos_a + load_x
    if engaged:
        fx += curvature_force(kind, x, penetration, cos_a, sin_a, prm)
    fz = normal * cos_a + tangential * sin_a + load_z
    return fx, fz


@njit(inline="always")
def energy_rates(kind, x, velocity, shear, t, engaged, contact_now, plate_v, prm):
    """Rates of the energy balance at the state (x, ``velocity`` = (vx, vz), shear F) whose
    contact quantities are ``contact_now`` (``contact``), the contact's terms counted while
    ``engaged``: work done on the block by the drive's far end, the
    plate and the load; power dissipated by the dashpots; power stored in the normal
    spring (-k_n delta u_n, which is d(k_n delta^2 / 2)/dt on a flat plate).

    With kinetic energy K, drive-spring energy k_d (x - V_d t)^2 / 2 and tangential
    spring energy k_t F^2 / 2, Newton's law gives
    d(K + E_drive + E_normal + E_shear)/dt = work rate - dissipation rate, exactly;
    the energy a reset releases (k_t F^2 / 2) counts as dissipated.  In the tangent
    frame K = m (u^2 + w^2) / 2 and the normal components of load and drive spring work
    on zeta; the balance is again exact.
    """
    vx, vz = velocity
    penetration, u_n, u_t, cos_a, sin_a, normal = contact_now
    tangential = -prm[P_GT] * u_t
    dissipation = prm[P_GT] * u_t * u_t
    storage = 0.0
    if engaged:
        tangential -= friction_spring_force(kind, shear, prm)
        dissipation += contact_dissipation(kind, penetration, u_n, prm)
        storage = -contact_elastic(kind, penetration, prm) * u_n
    if tangent_frame(kind):  # the normal components of load and drive work on zeta (docs/physics.md, Sec. 7)
        load_t, load_n = frame_load(kind, cos_a, sin_a, prm)
        work = (prm[P_KD] * (prm[P_VD] * t - x) * prm[P_VD] + normal * plate_v + load_t * vx
                + (load_n + prm[P_KD] * (x - prm[P_VD] * t) * sin_a) * vz)
        return work, dissipation, storage
    load_x, load_z = load(kind, cos_a, sin_a, prm)
    work = (prm[P_KD] * (prm[P_VD] * t - x) * prm[P_VD]
            + plate_v * (normal * cos_a + tangential * sin_a)
            + load_x * vx + load_z * vz)
    return work, dissipation, storage


@njit(inline="always")
def coulomb_bound(kind, normal, x, t, prm):
    """The N of the Coulomb bound mu_s N at the block's abscissa x and time t (``laws``:
    bound): the contact force ``normal`` (coulomb_normal = 0), or the applied load N_a
    (coulomb_normal = 1)."""
    return bound_normal(kind, normal, x, t, prm)


@njit(inline="always")
def friction_rule(kind, shear, state, penetration, normal, slip_rate, h, prm):
    """The friction law's rule at a new state (``laws``: friction; the paper's: F = 0 once
    detached, or when |k_t F| >= mu_s N) at the end of a step of length h, ``state`` the
    law's state and ``slip_rate`` the tangential velocity relative to the plate there.
    Returns the new shear displacement, the law's new state and whether a reset (or a
    slip's start) happened."""
    return law_friction_rule(kind, shear, state, penetration, normal, slip_rate, h, prm)
