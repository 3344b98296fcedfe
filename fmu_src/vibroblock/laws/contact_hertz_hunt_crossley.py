"""Hertzian contact with Hunt-Crossley damping, never pulling: N = max(0, k_n delta^(3/2) - gamma_n delta^(3/2) u_n).

A sphere pressed into a flat by delta carries the elastic force k_n delta^(3/2) (Hertz),
here with the paper's k_n as its stiffness (force / length^(3/2)).  Hunt and Crossley
(J. Appl. Mech. 42, 440, 1975) scale the dashpot with the same power of delta,
lambda delta^(3/2) d(delta)/dt, so that the force starts and ends at 0 with the contact
(no jump at touchdown, no pull at a slow separation) and the coefficient of restitution
falls linearly with the impact speed v0: e = 1 - alpha v0 to first order, with
lambda = (3/2) alpha k_n.  The dashpot coefficient is the paper's gamma_n (force /
(length^(3/2) velocity)), so alpha = 2 gamma_n / (3 k_n); d(delta)/dt = -u_n.  A fast
separation (u_n > k_n / gamma_n) would still make the force pull; it is clipped at 0
as in ``linear_no_pull``, and the clipped work is booked as dissipated.

At rest under a load W the penetration is (W / k_n)^(2/3) (docs/physics.md, Sec. 3):
delta_0 = m g / k_n stays the paper's unit of length, and with the paper's
m = g = k_n = 1 the rest penetration is 1 delta_0 under either law.  The contact's
stiffness there is (3/2) k_n (W / k_n)^(1/3), its damping gamma_n (W / k_n).
"""
import cmath
import math

from numba import njit, types
from numba.extending import overload

from ..layout import P_GN, P_KN
from .contact_linear_no_pull import at_least_zero

ID = 3
LINEAR = False  # the powers of delta: event_driven's closed-form flows do not hold
CONSERVATIVE = True  # the elastic force is -grad((2/5) k_n delta^(5/2)), curvature term included
REFUSED_BY = {
    "implicit_contact": "integrates the linear spring-dashpot's closed-form flow, which a Hertzian spring does "
                        "not have",
}


def three_halves_power(value):
    """value^(3/2) for value >= 0 (in Python too: the energy observation reads ``potential``)."""
    return value * math.sqrt(max(value, 0.0))


@overload(three_halves_power, inline="always")
def _three_halves_power(value):
    if isinstance(value, types.Float):
        # max: a caller evaluating the law exactly at the surface may pass -0.0 or a rounding below it
        return lambda value: value * math.sqrt(max(value, 0.0))
    if isinstance(value, types.Complex):
        # event_driven evaluates the contact law on the complex amplitudes of its linear
        # flows; it refuses this law (LINEAR = False), but the dispatch compiles every law.
        return lambda value: value * cmath.sqrt(value)
    return None


@njit(inline="always")
def elastic(penetration, prm):
    """The spring's part of N, dU/d(delta) = k_n delta^(3/2)."""
    return prm[P_KN] * three_halves_power(penetration)


@njit(inline="always")
def force(penetration, u_n, prm):
    """N = max(0, delta^(3/2) (k_n - gamma_n u_n)) (the caller gates delta > 0)."""
    return at_least_zero(three_halves_power(penetration) * (prm[P_KN] - prm[P_GN] * u_n))


@njit(inline="always")
def dissipation(penetration, u_n, prm):
    """Power lost from the contact, (k_n delta^(3/2) - N) u_n: gamma_n delta^(3/2) u_n^2 while N > 0."""
    return (elastic(penetration, prm) - force(penetration, u_n, prm)) * u_n


@njit(inline="always")
def potential(penetration, prm):
    """U = (2/5) k_n delta^(5/2) (delta > 0; the caller gates it)."""
    return 0.4 * prm[P_KN] * penetration * three_halves_power(penetration)


def rest(load: float, p: dict) -> tuple[float, float, float]:
    """The contact at rest under the load ``load`` (``vibroblock.initial_state``): its
    secant stiffness load / delta_r (delta_r = (load / k_n)^(2/3), the rest penetration),
    and its tangent stiffness (3/2) k_n delta_r^(1/2) and damping gamma_n delta_r^(3/2),
    the linearisation a steady-orbit start uses."""
    penetration = (load / p["k_n"]) ** (2.0 / 3.0)
    secant = load / penetration if penetration > 0.0 else p["k_n"]  # no load: any stiffness rests at delta = 0
    return secant, 1.5 * p["k_n"] * math.sqrt(penetration), p["gamma_n"] * penetration ** 1.5
