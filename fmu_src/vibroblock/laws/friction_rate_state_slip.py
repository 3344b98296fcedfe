"""Rate-and-state friction (Dieterich-Ruina) with the slip law: dtheta/dt = -(V theta / D_c) ln(V theta / D_c); the contact's spring k_t in series with the slipping interface.

The friction coefficient, the interface's slip and the step are in ``laws.rate_state``.
The slip (Ruina) law evolves theta only by slip: a truly stationary contact does not
heal, and theta relaxes to D_c / V at steady sliding (mu_ss as for the aging law), the
log of V theta / D_c decaying exponentially over the slip D_c.  Over a step at the slip
rate V it is integrated exactly: ln(V theta_1 / D_c) = ln(V theta_0 / D_c) exp(-V h / D_c).
"""
import math

from numba import njit

from .friction_cundall_strack import energy, released, spring_force  # noqa: F401  (the same spring)
from .rate_state import (INTERFACE_SLIPS, P_DC, PARAMETERS, REFUSED_BY, initial_state, integrated,  # noqa: F401
                         interface_with, rule_with, stored)

ID = 4


@njit(inline="always")
def evolve(theta, slip_rate, h, prm):
    """theta after h at the slip rate V >= 0 (exact for V held over the step)."""
    if slip_rate <= 0.0:
        return theta
    x = slip_rate * h / prm[P_DC]
    return theta * math.exp(math.log(slip_rate * theta / prm[P_DC]) * math.expm1(-x))


@njit(inline="always")
def log_state_rate(log_theta, slip_rate, prm):
    """d(ln theta)/dt = -(V / D_c) ln(V theta / D_c); 0 at V = 0 (V ln V -> 0)."""
    if slip_rate <= 0.0:
        return 0.0
    return -(slip_rate / prm[P_DC]) * (math.log(slip_rate / prm[P_DC]) + log_theta)


rule = rule_with(evolve)
interface = interface_with(log_state_rate)
