"""Coulomb bound mu_s N_L with N_L the applied load's normal component alone, -load . n.

m g in model A, m g cos a in B, P_l in C: the paper's "mu_s m g" of Sec. III A, taken
literally on a corrugated plate, without the drive spring's share that
``applied_load`` adds.  It follows neither the plate's vibration nor the drive, so it
cannot self-lock: on a flank with tan a >= 1 / mu_s the load's tangential part alone
exceeds the bound and the block slides down, where the contact-force bound (whose N
grows with the uphill pull of the drive) can hold it (docs/physics.md, Sec. 5).
"""
from numba import njit

from ..models import frame, load, profile

ID = 2


@njit(inline="always")
def normal(kind, contact_normal, x, t, prm):
    """N_L = -load . n at abscissa x."""
    cos_a, sin_a = frame(profile(kind, x, prm)[1])
    load_x, load_z = load(kind, cos_a, sin_a, prm)
    return load_x * sin_a - load_z * cos_a
