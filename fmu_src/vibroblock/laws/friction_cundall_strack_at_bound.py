"""Cundall-Strack spring held at the Coulomb bound while sliding (the DEM codes' form): |k_t F| <= mu_s N, F = 0 once detached.

The paper resets the spring to 0 when the bound breaks (``cundall_strack``); DEM codes
(Cundall and Strack, Geotechnique 29, 47, 1979, as most codes implement it) scale it back
to the bound instead, F = sign(F) mu_s N_b / k_t, so a sliding block feels the full
Coulomb force mu_s N_b: the spring is an elastic-plastic element whose plastic slip
dissipates mu_s N_b per unit of slip.  Statics and sticking are the paper's; a slip is a
steady slide at the bound, not a train of resets, and the mean kinetic friction is the
static one (the paper's reset halves it).  The energy the scaling takes from the spring,
k_t (F_before^2 - F_after^2) / 2, counts as dissipated, as a reset's does.

``coulomb_resets`` counts the times the bound was met: every step (or event) at which the
spring was held there, so it measures sliding time, not a number of slips.  The bound
is met continuously while sliding, which the integrators that locate each breaking of the
bound as an event cannot follow: ``adaptive`` and ``event_driven`` refuse this law; the
fixed-step schemes apply it at the end of every step.
"""
import math

from numba import njit

from ..layout import P_KT, P_MUS
from .friction_cundall_strack import (INTERFACE_SLIPS, energy, integrated, interface, released,  # noqa: F401
                                      spring_force, stored)  # (the same spring, sticking between its resets)

ID = 1
REFUSED_BY = {
    "adaptive": "locates each breaking of the Coulomb bound as an event, and a spring held at the bound while "
                "sliding meets it continuously (a sliding regime it does not have); use a fixed-step scheme",
    "event_driven": "its regimes reset the spring to 0 at the Coulomb bound (the paper's law); use a fixed-step "
                    "scheme",
}


@njit(inline="always")
def rule(shear, state, penetration, bound_normal, slip_rate, h, prm):
    """F = 0 once detached; |k_t F| > mu_s N_b scales F back to the bound (F = 0 where the
    bound is not positive).  Returns the new shear displacement, the law's state (none:
    0) and whether the bound was met by a loaded spring."""
    if penetration <= 0.0:
        return 0.0, 0.0, False
    limit = prm[P_MUS] * bound_normal
    if abs(prm[P_KT] * shear) > limit:
        if limit <= 0.0:  # nothing holds: as the paper's reset
            return 0.0, 0.0, shear != 0.0
        return math.copysign(limit / prm[P_KT], shear), 0.0, True
    return shear, 0.0, False
