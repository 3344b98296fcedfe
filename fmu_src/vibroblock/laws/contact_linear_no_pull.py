"""Linear viscoelastic contact that never pulls: N = max(0, k_n delta - gamma_n u_n).

The paper's spring and dashpot (``linear``), with the force clipped at 0: a dashpot that
would pull a fast-separating block lets go instead (the paper's N may be negative there,
docs/physics.md, Sec. 3).  The elastic part is the paper's, so the potential, the
curvature term on a curved plate and the rest penetration delta_0 = m g / k_n are
unchanged; the clipped force does work on the separating block that the spring alone
would have done, and the energy balance books the difference as dissipated:
(k_n delta - N) u_n >= 0, which is gamma_n u_n^2 while N > 0 and k_n delta u_n
(u_n > 0: separating) while the force is clipped.
"""
from numba import njit, types
from numba.extending import overload

from . import contact_linear
# The spring is the paper's: the same potential and elastic force (and so delta_0 and the
# curvature term); only the total force is clipped.
from .contact_linear import elastic, potential, rest  # noqa: F401  (this law's functions too)

ID = 2
LINEAR = False  # the clip is a kink: event_driven's closed-form flows do not hold
CONSERVATIVE = True  # the elastic force is -grad(k_n delta^2 / 2), curvature term included
REFUSED_BY = {
    "implicit_contact": "integrates the linear spring-dashpot's closed-form flow, which the clip at N = 0 breaks",
}


def at_least_zero(value):
    """max(value, 0)."""
    return max(value, 0.0)


@overload(at_least_zero, inline="always")
def _at_least_zero(value):
    if isinstance(value, types.Float):
        return lambda value: max(value, 0.0)
    if isinstance(value, types.Complex):
        # event_driven evaluates the contact law on the complex amplitudes of its linear
        # flows; it refuses this law (LINEAR = False), but the dispatch compiles every law.
        return lambda value: value
    return None


@njit(inline="always")
def force(penetration, u_n, prm):
    """N = max(0, k_n delta - gamma_n u_n) (the caller gates delta > 0)."""
    return at_least_zero(contact_linear.force(penetration, u_n, prm))


@njit(inline="always")
def dissipation(penetration, u_n, prm):
    """Power lost from the contact, (k_n delta - N) u_n: gamma_n u_n^2 while N > 0."""
    return (elastic(penetration, prm) - force(penetration, u_n, prm)) * u_n
