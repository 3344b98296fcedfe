"""Model C: corrugated plate A_x sin(omega_x x), block confined by a force P_l normal to the surface (paper Eqs. 5-6)."""
from numba import njit

from ..layout import slot
from ..parameters import NON_NEGATIVE, Parameter
from .model_b import CORRUGATION, DEFAULTS as MODEL_B_DEFAULTS
from .model_b import curvature, profile as corrugated_profile  # noqa: F401  (curvature: model B's)

PARAMETERS = (*CORRUGATION,
              Parameter("P_l", 1.0, "m_0 delta_0/tau_0^2", "confining force, normal to the plate surface", NON_NEGATIVE))
# The paper gives P_l = 1 and says the rest is model B's.
DEFAULTS = MODEL_B_DEFAULTS
P_PL = slot("P_l")


@njit(inline="always")
def profile(x, prm):
    return corrugated_profile(x, prm)


@njit(inline="always")
def load(cos_a, sin_a, prm):
    # -P_l along the outward normal n = (-sin a, cos a)
    return prm[P_PL] * sin_a, -prm[P_PL] * cos_a
