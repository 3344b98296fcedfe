"""The paper's Cundall-Strack spring with reset: dF/dt = u_t in contact, force -k_t F; F = 0 once detached or when |k_t F| >= mu_s N.

Sec. II of the paper: the tangential spring k_t stores the shear displacement F while the
block touches the plate.  The spring is reset to zero (not held at the bound) when the
Coulomb bound breaks, so the mean kinetic friction is about half the static one, and a
slip is a train of resets.  The energy a reset releases, k_t F^2 / 2, counts as dissipated.
"""
from numba import njit

from ..layout import P_KT, P_MUS

ID = 0
# The spring sticks to the plate until its reset: no slip of the interface between resets
# (``interface``), so an error-controlled integrator carries no state of the law.
INTERFACE_SLIPS = False


@njit(inline="always")
def spring_force(shear, prm):
    """The spring's pull along the tangent's opposite, k_t F (in contact only)."""
    return prm[P_KT] * shear


@njit(inline="always")
def energy(shear, prm):
    """The spring's stored energy k_t F^2 / 2."""
    return 0.5 * prm[P_KT] * shear * shear


@njit(inline="always")
def released(before, after, prm):
    """Energy the spring gives up when its displacement jumps from ``before`` to ``after``
    (a reset): counted as dissipated."""
    return 0.5 * prm[P_KT] * (before * before - after * after)


@njit(inline="always")
def rule(shear, state, penetration, bound_normal, slip_rate, h, prm):
    """F = 0 once detached, or when |k_t F| >= mu_s N_b.  Returns the new shear
    displacement, the law's state (none: 0) and whether a reset released a loaded spring
    (resets of an already relaxed spring are not counted)."""
    if penetration <= 0.0:
        return 0.0, 0.0, False
    if abs(prm[P_KT] * shear) >= prm[P_MUS] * bound_normal:
        return 0.0, 0.0, shear != 0.0
    return shear, 0.0, False


@njit(inline="always")
def integrated(state):
    """The variable an error-controlled integrator carries for the law's state: itself."""
    return state


@njit(inline="always")
def stored(value):
    return value


@njit(inline="always")
def interface(shear, state, bound_normal, prm):
    """The interface's slip rate along F and the rate of the law's state, in continuous
    time (error-controlled integrators): none, the spring holds until the rule resets it."""
    return 0.0, 0.0
