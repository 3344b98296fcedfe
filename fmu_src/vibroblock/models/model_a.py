"""Model A: flat plate, block confined by gravity (paper Eqs. 1-2)."""
from numba import njit

from ..layout import P_G, P_M

PARAMETERS = ("g",)
# No slope anywhere: the surface's frame is the lab's (cos a = 1, sin a = 0), and the
# contact and forces skip the products by them (``models.flat_plate``).
FLAT = True


@njit(inline="always")
def profile(x, prm):
    return 0.0, 0.0


@njit(inline="always")
def load(cos_a, sin_a, prm):
    return 0.0, -prm[P_M] * prm[P_G]


@njit(inline="always")
def curvature(x, prm):
    return 0.0
