"""Model C: corrugated plate A_x sin(omega_x x), block confined by a force P_l normal to the surface (paper Eqs. 5-6)."""
from numba import njit

from ..layout import P_PL
from .model_b import profile as corrugated_profile


@njit(inline="always")
def profile(x, prm):
    return corrugated_profile(x, prm)


@njit(inline="always")
def load(cos_a, sin_a, prm):
    # -P_l along the outward normal n = (-sin a, cos a)
    return prm[P_PL] * sin_a, -prm[P_PL] * cos_a
