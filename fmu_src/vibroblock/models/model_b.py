"""Model B: corrugated plate A_x sin(omega_x x), block confined by gravity (paper Eqs. 3-4)."""
import math

from numba import njit

from ..layout import P_G, P_M, slot
from ..parameters import NON_NEGATIVE, Parameter

CORRUGATION = (
    Parameter("A_x", 1e3, "delta_0", "corrugation amplitude: plate surface A_x sin(omega_x x)", NON_NEGATIVE),
    Parameter("omega_x", 2e-2, "1/delta_0", "corrugation wave number", NON_NEGATIVE),
)
PARAMETERS = ("g", *CORRUGATION)
# The paper's Sec. III B drives the corrugated models more slowly and softly than model A.
DEFAULTS = {"k_d": 5e-6, "V_d": 2e-4}
P_AX, P_WX = slot("A_x"), slot("omega_x")


@njit(inline="always")
def profile(x, prm):
    phase = prm[P_WX] * x
    return prm[P_AX] * math.sin(phase), prm[P_AX] * prm[P_WX] * math.cos(phase)


@njit(inline="always")
def load(cos_a, sin_a, prm):
    return 0.0, -prm[P_M] * prm[P_G]


@njit(inline="always")
def curvature(x, prm):
    return -prm[P_AX] * prm[P_WX] * prm[P_WX] * math.sin(prm[P_WX] * x)
