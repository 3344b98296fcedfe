"""Rate-and-state friction (Dieterich-Ruina) with the aging law: dtheta/dt = 1 - V theta / D_c; the contact's spring k_t in series with the slipping interface.

The friction coefficient, the interface's slip and the step are in ``laws.rate_state``.
The aging (Dieterich) law heals a stationary contact: theta grows as the time of
contact while V = 0, and relaxes to D_c / V at steady sliding, so mu_ss = mu_0 +
(a - b) ln(V / V_0).  Over a step at the slip rate V it is integrated exactly:
theta_1 = theta_0 exp(-V h / D_c) + h (1 - exp(-V h / D_c)) / (V h / D_c).
"""
import math

from numba import njit

from .friction_cundall_strack import energy, released, spring_force  # noqa: F401  (the same spring)
from .rate_state import (INTERFACE_SLIPS, P_DC, PARAMETERS, REFUSED_BY, initial_state, integrated,  # noqa: F401
                         interface_with, relative_expm1, rule_with, stored)

ID = 3


@njit(inline="always")
def evolve(theta, slip_rate, h, prm):
    """theta after h at the slip rate V >= 0 (exact for V held over the step)."""
    x = slip_rate * h / prm[P_DC]
    return theta * math.exp(-x) + h * relative_expm1(x)


@njit(inline="always")
def log_state_rate(log_theta, slip_rate, prm):
    """d(ln theta)/dt = 1 / theta - V / D_c."""
    return math.exp(-log_theta) - slip_rate / prm[P_DC]


rule = rule_with(evolve)
interface = interface_with(log_state_rate)
