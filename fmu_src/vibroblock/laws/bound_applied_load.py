"""Coulomb bound mu_s N_a with N_a the applied load's and the drive spring's normal components, -(load + drive) . n.

m g in model A, m g cos a - k_d (x - V_d t) sin a in B, P_l - k_d (x - V_d t) sin a in C:
the paper's "mu_s m g" of Sec. III A extended to a corrugated plate.  It does not follow
the plate's vibration (claim C2 holds by construction).  With the drive spring's share it
can self-lock on a flank with tan a >= 1 / mu_s (docs/physics.md).
"""
from numba import njit

from ..layout import P_KD, P_VD
from ..models import frame, load, profile

ID = 1


@njit(inline="always")
def normal(kind, contact_normal, x, t, prm):
    """N_a = -(load + drive spring) . n at abscissa x and time t."""
    cos_a, sin_a = frame(profile(kind, x, prm)[1])
    load_x, load_z = load(kind, cos_a, sin_a, prm)
    return load_x * sin_a - load_z * cos_a - prm[P_KD] * (x - prm[P_VD] * t) * sin_a
