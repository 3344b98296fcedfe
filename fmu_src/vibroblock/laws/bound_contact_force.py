"""Coulomb bound mu_s N with N the contact force k_n delta - gamma_n u_n (the paper's Eqs. 2, 4, 6 as printed).

N oscillates with the plate, so a vibration below the detachment threshold already moves
the bound and shortens sticks (claim C2 is then a measurement, docs/claims.md).  N may be
negative while the dashpot pulls a separating block, which resets the spring.
"""
from numba import njit

ID = 0


@njit(inline="always")
def normal(kind, contact_normal, x, t, prm):
    """The bound's N: the contact force itself."""
    return contact_normal
