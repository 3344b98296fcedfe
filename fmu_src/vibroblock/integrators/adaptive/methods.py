"""The two embedded pairs under one error control, and the choice between them.

Where the motion is not stiff DOP853 takes the steps (``dop853``); where its steps would
meet its stability bound (a long stick whose ringing has died, the block creeping at
~1e-8 delta_0/tau_0: an explicit step is held to h ~ 1 there) RODAS4 does (``rodas4``).
A run starts with one Jacobian and takes the explicit pair if its first step lies inside
the bound for every mode the contact can have (h max(||J||_inf, the fastest contact or
friction-spring rate) < EXPLICIT_CALM).  The explicit pair hands over to RODAS4 once
h rho > EXPLICIT_STIFF on STIFF_AFTER accepted steps (rho from its last two rates:
Hairer's DOP853 test); RODAS4 hands back, at least STIFF_HOLD steps later, once its step
is again inside the bound.  A step is accepted when the weighted RMS of its embedded
error over the state components (theta where it moves) is <= 1 (weights atol + rtol max(|y0|, |y1|)); the
next step is h SAFETY err^(-1/(q+1)) (q the estimator's order: 3 for RODAS4, 7 for
DOP853's combination), within [SHRINK, GROW] h.
"""
import math

from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ...layout import P_GN, P_GT, P_KN, P_KT, P_M
from .dop853 import explicit_step, hermite
from .regimes import NS
from .rodas4 import dense, rosenbrock

# Step-size control.
SAFETY, GROW, SHRINK = 0.9, 6.0, 0.2
# Points of each step's interpolant at which the event values are checked.
EVENT_SAMPLES = 4
EXPLICIT_STIFF = 6.1
STIFF_AFTER = 15
STIFF_FORGET = 6  # non-stiff steps in a row that clear the count of stiff ones (as DOP853)
EXPLICIT_CALM = 1.0
STIFF_HOLD = 32


@njit(inline="always")
def step(explicit, system, clk, v, t_abs, u, h, ws, out):
    """One step of the method in use; its weighted RMS error."""
    if explicit:
        return explicit_step(system, clk, v, t_abs, u, h, ws, out)
    return rosenbrock(system, clk, v, t_abs, u, h, ws, out)


@njit(inline="always")
def interpolate(explicit, v, out, ws, h, s, res):
    """The step's interpolant at fraction s (state components): RODAS4's own, or for the
    explicit pair the cubic Hermite of its end values and rates (event values are only
    sampled on it; switches are refined on full steps)."""
    if explicit:
        hermite(v, out, ws, h, s, res)
    else:
        dense(v, out, ws, s, res)


@njit(inline="always")
def sample_state(explicit, v, out, ws, h, sample, res):
    """The state at the step's sample point sample / EVENT_SAMPLES: the step's own end at
    the last one, the interpolant before."""
    if sample == EVENT_SAMPLES:
        for i in range(NS):
            res[i] = out[i]
    else:
        interpolate(explicit, v, out, ws, h, sample / EVENT_SAMPLES, res)


@njit(inline="always")
def control_exponent(explicit):
    """The step control's exponent, -1 / (order of the error estimate + 1)."""
    return -0.125 if explicit else -0.25


@njit(inline="always")
def growth(err, explicit):
    """Factor of the next step after a step accepted with error err."""
    return min(GROW, max(SHRINK, SAFETY * (max(err, 1e-12) ** control_exponent(explicit))))


@njit(inline="always")
def shrink(err, explicit):
    """Factor of the retaken step after a step rejected with error err."""
    return SHRINK if not math.isfinite(err) else max(SHRINK, SAFETY * err ** control_exponent(explicit))


@njit(inline="always")
def _mode_rate(k, gamma, m):
    """The largest |lambda| of m s^2 + gamma s + k."""
    disc = gamma * gamma - 4.0 * k * m
    if disc >= 0.0:
        return (gamma + math.sqrt(disc)) / (2.0 * m)
    return math.sqrt(k / m)


@njit(inline="always")
def stiffest_rate(prm):
    """The fastest rate of the contact's and the friction spring's modes: the explicit pair
    is chosen only for steps inside its bound for them, whatever the regime (a step taken
    in flight would otherwise meet them at the next landing, where the explicit pair can
    only resolve what RODAS4 steps across)."""
    m = prm[P_M]
    return max(_mode_rate(prm[P_KN], prm[P_GN], m), _mode_rate(prm[P_KT], prm[P_GT], m))

