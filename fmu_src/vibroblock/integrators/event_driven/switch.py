"""Switches of ``event_driven``: which side of each switch a state is on, and the
friction law's rule applied at an event.

The spring re-arms at a touchdown or a reset where the Coulomb bound is positive, or zero
and rising; else it is held at 0 until N rises again.  The bound is the contact force's
(``laws.bound_contact_force``: the registry refuses the applied load's), the rule the
friction law's, the energy a reset releases the spring's stored energy.
"""
import math

from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ...dynamics import plate_acceleration, plate_motion
from ...laws import contact_force, friction_energy, friction_rule
from ...layout import D_AMP, D_EXT_A, D_EXT_V, D_EXT_Z, D_OMEGA, P_G, P_M, P_MUS, Y_DISSIPATED, Y_F, Y_VZ, Y_Z
from .regimes import ENGAGED, EV_CONTACT, EV_DETACH, EV_N_RISES, EV_N_ZERO, FREE, HELD

# The friction rule's detachment gate sees a block in contact: contact is decided here,
# where delta = 0 with the plate pressing in counts as contact.
TOUCHING = 1.0


@njit(inline="always")
def _contact_force_armed(kind, prm, penetration, u_n, plate_a):
    """The contact force N at a switch, and whether the spring is armed there (mu_s N > 0,
    or N = 0 and rising).  N's rate is the law's value at the rates (the law is linear):
    delta' = -u_n, u_n' = N / m - (g + the plate's acceleration)."""
    normal = contact_force(kind, max(penetration, 0.0), u_n, prm)
    normal_rate = contact_force(kind, -u_n, normal / prm[P_M] - (plate_a + prm[P_G]), prm)
    mu_s = prm[P_MUS]
    return normal, mu_s * normal > 0.0 or (mu_s > 0.0 and normal == 0.0 and normal_rate > 0.0)


@njit(inline="always")
def _release(kind, s, prm):
    """A reset of the spring: the energy it stored counts as dissipated."""
    s[Y_DISSIPATED] += friction_energy(kind, s[Y_F], prm)
    s[Y_F] = 0.0


@njit(inline="always")
def start_side(kind, s, slips, prm, drv, th, tau_e):
    """The side of each switch the stored state ``s`` is on, the friction rule applied to
    it: (in contact, regime, slips)."""
    amp, om, ext_a = drv[D_AMP], drv[D_OMEGA], drv[D_EXT_A]
    sin_th = math.sin(th)
    plate_z, plate_v = plate_motion(amp, om, sin_th, math.cos(th), drv[D_EXT_Z], drv[D_EXT_V], ext_a, tau_e)
    plate_a = plate_acceleration(amp, om, sin_th, ext_a)
    pen, u_n = plate_z - s[Y_Z], s[Y_VZ] - plate_v
    if pen > 0.0:
        in_contact = True
    elif pen == 0.0:  # touching: in contact if pressing in
        in_contact = u_n < 0.0 or (u_n == 0.0 and plate_a + prm[P_G] > 0.0)
    else:
        in_contact = False
    if not in_contact:
        if s[Y_F] != 0.0:
            _release(kind, s, prm)
        return False, FREE, slips
    normal, armed = _contact_force_armed(kind, prm, pen, u_n, plate_a)
    shear, _, reset = friction_rule(kind, s[Y_F], 0.0, TOUCHING, normal, 0.0, 0.0, prm)  # (its law has no state)
    if reset:
        slips += 1
        _release(kind, s, prm)
    s[Y_F] = shear
    return True, ENGAGED if armed else HELD, slips


@njit(inline="always")
def switch(kind, s, slips, prm, drv, event, plate_end):
    """The rule at an event, ``s`` the state there and ``plate_end`` (phase, plate height and
    velocity): (in contact, regime, just reset, slips)."""
    if event == EV_DETACH:
        _release(kind, s, prm)
        return False, FREE, False, slips
    if event == EV_N_ZERO:
        return True, HELD, False, slips
    if event == EV_N_RISES:
        s[Y_F] = 0.0
        return True, ENGAGED, False, slips
    # a touchdown or a Coulomb reset
    if event != EV_CONTACT and s[Y_F] != 0.0:
        slips += 1
        _release(kind, s, prm)
    s[Y_F] = 0.0
    th_end, plate_z, plate_v = plate_end
    plate_a = plate_acceleration(drv[D_AMP], drv[D_OMEGA], math.sin(th_end), drv[D_EXT_A])
    _, armed = _contact_force_armed(kind, prm, plate_z - s[Y_Z], s[Y_VZ] - plate_v, plate_a)
    if armed:
        return True, ENGAGED, event != EV_CONTACT, slips
    return True, HELD, False, slips
