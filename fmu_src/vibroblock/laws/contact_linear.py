"""Linear viscoelastic contact, conservative on a curved plate: N = k_n delta - gamma_n u_n, elastic force -grad(k_n delta^2 / 2).

The paper's contact (Sec. II): a spring k_n and a dashpot gamma_n along the normal.  In
fixed axes on a corrugated plate the penetration delta = (Z_p(x, t) - z) cos a is
measured to the surface's tangent line, and it depends on x through the slope too; the
elastic force is taken as the gradient of the potential U = k_n delta^2 / 2, so that a
frictionless block held on a flank cannot gain energy from it (docs/physics.md, Sec. 9).
Its normal part is k_n delta n; the gradient adds k_n delta^2 tan a da/dx along x
(``dynamics.curvature_force``).  On a flat plate, and in the tangent frame, that term
vanishes: there the law is the paper's Eqs. (1)-(6) exactly.
"""
from numba import njit

from ..layout import P_GN, P_KN

ID = 0
LINEAR = True  # linear in (delta, u_n): event_driven's closed-form flows run it
CONSERVATIVE = True  # the elastic force is -grad(potential), curvature term included


@njit(inline="always")
def force(penetration, u_n, prm):
    """N = k_n delta - gamma_n u_n, continued across delta = 0 (the caller gates it)."""
    return prm[P_KN] * penetration - prm[P_GN] * u_n


@njit(inline="always")
def elastic(penetration, prm):
    """The spring's part of N, dU/d(delta)."""
    return prm[P_KN] * penetration


@njit(inline="always")
def dissipation(penetration, u_n, prm):
    """Power the dashpot dissipates, gamma_n u_n^2 (in contact)."""
    return prm[P_GN] * u_n * u_n


@njit(inline="always")
def potential(penetration, prm):
    """U = k_n delta^2 / 2 (delta > 0; the caller gates it)."""
    return 0.5 * prm[P_KN] * penetration * penetration


def rest(load: float, p: dict) -> tuple[float, float, float]:
    """The contact at rest under ``load`` (``vibroblock.initial_state``): secant and
    tangent stiffness k_n (rest penetration load / k_n) and damping gamma_n."""
    return p["k_n"], p["k_n"], p["gamma_n"]
