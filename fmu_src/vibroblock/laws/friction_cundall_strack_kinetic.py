"""Cundall-Strack spring with a kinetic bound: held at mu_d N while sliding, mu_d = mu_k / (1 + abs(u_t) / v_w) (velocity weakening for v_w > 0, Carlson-Langer's form); sticks when the slip reverses.

Static friction is the paper's: the spring k_t F holds the block while |k_t F| <= mu_s N_b.
When the bound breaks, the block slides and the spring is held at the kinetic bound

    |k_t F| = mu_d(u_t) N_b,   mu_d(u_t) = mu_k / (1 + |u_t| / v_w),

as DEM codes hold it at mu_s N (``cundall_strack_at_bound``), but at a kinetic coefficient
mu_k <= mu_s and weakening with the slip rate |u_t| (v_w = 0: no weakening, mu_d = mu_k).
The block sticks again when its slip rate u_t reverses against the spring (the slip stops):
the spring then holds it elastically from where it was, until the static bound breaks again.

Carlson and Langer's friction (Phys. Rev. Lett. 62, 2632, 1989; Phys. Rev. A 40, 6470,
1989) is F_0 phi(2 alpha v / v_1) with phi(y) = (1 - sigma) / (1 + |y| / (1 - sigma)) while
sliding, |F| <= F_0 while stuck.  With F_0 = mu_s N it is this law with
mu_k = (1 - sigma) mu_s and v_w = (1 - sigma) v_1 / (2 alpha), the stick enforced by the
stiff spring k_t instead of a set-valued force.

The rule is applied at each step's end, so the mean kinetic force exceeds mu_d N_b by
about k_t |u_t| dt / 2 (first order in dt).  The state: whether the block slides
(``layout.Y_FRICTION_STATE``).  ``coulomb_resets`` counts the
times the static bound broke (slips begun).  The energy the hold takes from the spring,
k_t (F_before^2 - F_after^2) / 2, counts as dissipated.  ``adaptive`` and ``event_driven``
refuse the law (they locate each breaking of the bound as an event and reset the spring).
"""
import math

from numba import njit

from ..layout import P_KT, P_MUS, slot
from ..parameters import NON_NEGATIVE, Parameter
from .friction_cundall_strack import (INTERFACE_SLIPS, energy, integrated, interface, released,  # noqa: F401
                                      spring_force, stored)  # (the same spring, sticking between its resets)

ID = 2
PARAMETERS = (
    Parameter("mu_k", 0.4, "1", "kinetic friction coefficient: the spring's bound while sliding (friction_law = 2; "
              "<= mu_s)", NON_NEGATIVE),
    Parameter("v_w", 0.0, "delta_0/tau_0", "weakening velocity of the kinetic coefficient mu_k / (1 + abs(u_t)/v_w) "
              "(friction_law = 2; 0: no weakening)", NON_NEGATIVE),
)
P_MUK, P_VW = slot("mu_k"), slot("v_w")
REFUSED_BY = {
    "adaptive": "locates each breaking of the Coulomb bound as an event and resets the spring, and this law holds "
                "the spring at a kinetic bound while sliding (a regime it does not have); use a fixed-step scheme",
    "event_driven": "its regimes reset the spring to 0 at the Coulomb bound (the paper's law); use a fixed-step "
                    "scheme",
}


def check(parameters: dict) -> str | None:
    """Why the parameters cannot run this law, or None."""
    if parameters["mu_k"] > parameters["mu_s"]:
        return (f"mu_k = {parameters['mu_k']!r} exceeds mu_s = {parameters['mu_s']!r}: the kinetic coefficient "
                "(friction_law = 2) must not exceed the static one")
    return None


@njit(inline="always")
def kinetic(slip_rate, prm):
    """mu_d(u_t) = mu_k / (1 + |u_t| / v_w), mu_k for v_w = 0."""
    if prm[P_VW] > 0.0:
        return prm[P_MUK] / (1.0 + abs(slip_rate) / prm[P_VW])
    return prm[P_MUK]


@njit(inline="always")
def rule(shear, sliding, penetration, bound_normal, slip_rate, h, prm):
    """F = 0 once detached.  Stuck: the static bound |k_t F| > mu_s N_b starts a slip.
    Sliding (``sliding`` = 1): F held at sign(F) mu_d N_b / k_t while the slip goes on in
    F's direction, stuck again once it reverses.  Returns (F, sliding, whether a slip began)."""
    if penetration <= 0.0:
        return 0.0, 0.0, False
    if sliding != 0.0 and slip_rate * shear <= 0.0:  # the slip stopped: held elastically from here
        sliding = 0.0
    began = False
    if sliding == 0.0 and abs(prm[P_KT] * shear) > prm[P_MUS] * bound_normal:
        sliding, began = 1.0, True
    if sliding != 0.0:
        limit = kinetic(slip_rate, prm) * bound_normal
        if limit <= 0.0:  # nothing holds: as the paper's reset
            return 0.0, 0.0, began or shear != 0.0
        return math.copysign(limit / prm[P_KT], shear), sliding, began
    return shear, 0.0, False
