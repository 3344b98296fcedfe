"""Model B: corrugated plate A_x sin(omega_x x), block confined by gravity (paper Eqs. 3-4)."""
import math

from numba import njit

from ..layout import P_AX, P_G, P_M, P_WX


@njit(inline="always")
def profile(x, prm):
    phase = prm[P_WX] * x
    return prm[P_AX] * math.sin(phase), prm[P_AX] * prm[P_WX] * math.cos(phase)


@njit(inline="always")
def load(cos_a, sin_a, prm):
    return 0.0, -prm[P_M] * prm[P_G]
