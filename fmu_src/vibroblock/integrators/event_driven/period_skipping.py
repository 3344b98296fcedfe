"""Period skipping of ``event_driven``: whole plate periods added at once on a locked orbit.

With a harmonic drive only (no external input), the state at a touchdown (plate phase,
vertical velocity relative to the plate, drive-spring stretch x - V_d t, vx; F = 0 there)
determines the future.  When it repeats within PERIODIC_TOL over two consecutive periods
of q drive cycles (bouncing locked to the plate), the remaining whole periods are added
at once: t += N 2 pi q / omega, x += N V_d T, and phi, work, dissipation and slips grow by
N times their increase over one period.
"""
import math

import numpy as np
from ... import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ...layout import (D_AMP, D_DT, D_OMEGA, D_T0, P_G, P_KN, P_M, P_VD, Y_DISSIPATED, Y_PHI, Y_VX, Y_VZ, Y_WORK,
                       Y_X)
from .regimes import carry

# Touchdowns remembered, and the relative agreement of the state at touchdown (plate
# phase, relative vertical velocity, drive-spring stretch, vx) over two consecutive
# periods that counts as periodic.
TOUCHDOWNS = 16
PERIODIC_TOL = 1e-10
# Touchdown record layout.
T_PHASE, T_YDOT, T_STRETCH, T_VX, T_TIME, T_PHI, T_WORK, T_DISS, T_SLIPS = range(9)
N_RECORD = 9


@njit(inline="always")
def drive_stretch(prm, drv, n_ref, off, x):
    """The drive spring's far end minus x at t0 + n_ref dt + off."""
    v_d = prm[P_VD]
    return v_d * (drv[D_T0] + n_ref * drv[D_DT]) + v_d * off - x


@njit(cache=True)
def wrap(angle):
    return angle - 2.0 * math.pi * math.floor(angle / (2.0 * math.pi) + 0.5)


@njit(cache=True)
def same_touchdown(a, b, length):
    """Same state at two touchdowns, relative to the motion's scales: velocities against
    the impact velocity, the stretch against itself plus the plate's excursion."""
    if abs(wrap(a[T_PHASE] - b[T_PHASE])) > PERIODIC_TOL:
        return False
    speed = max(abs(a[T_YDOT]), abs(b[T_YDOT]))
    if abs(a[T_YDOT] - b[T_YDOT]) > PERIODIC_TOL * speed or abs(a[T_VX] - b[T_VX]) > PERIODIC_TOL * speed:
        return False
    return abs(a[T_STRETCH] - b[T_STRETCH]) <= PERIODIC_TOL * (max(abs(a[T_STRETCH]), abs(b[T_STRETCH])) + length)


@njit(cache=True)
def touchdown_period(book, count, length):
    """Number of touchdowns p in a period if the last touchdown repeats the one p before,
    which repeats the one 2p before; 0 otherwise."""
    last = (count - 1) % TOUCHDOWNS
    for p in range(1, TOUCHDOWNS // 2 + 1):
        if count < 2 * p + 1:
            break
        one = (count - 1 - p) % TOUCHDOWNS
        two = (count - 1 - 2 * p) % TOUCHDOWNS
        if same_touchdown(book[last], book[one], length) and same_touchdown(book[one], book[two], length):
            return p
    return 0


@njit(inline="always")
def touchdown(book, count, s, slips, prm, drv, clock, window_end, plate_end, costs):
    """Record a touchdown (the ``count``-th, state ``s``, clock (n_ref, off)); if the motion
    has locked onto a period, add the whole periods left before ``window_end`` but one.
    Returns (touchdowns recorded, slips, n_ref, off); counts the skipped plate periods in
    costs[1]."""
    n_ref, off = clock
    n_to, off_to = window_end
    th_end, _, plate_v = plate_end
    dt = drv[D_DT]
    rec = book[count % TOUCHDOWNS]
    t_now = drv[D_T0] + n_ref * dt + off
    rec[T_PHASE] = wrap(th_end)
    rec[T_YDOT] = s[Y_VZ] - plate_v
    rec[T_STRETCH] = drive_stretch(prm, drv, n_ref, off, s[Y_X])
    rec[T_VX] = s[Y_VX]
    rec[T_TIME], rec[T_PHI], rec[T_WORK] = t_now, s[Y_PHI], s[Y_WORK]
    rec[T_DISS], rec[T_SLIPS] = s[Y_DISSIPATED], slips
    count += 1
    # lengths are compared against the plate's reach plus the rest penetration
    p = touchdown_period(book, count, abs(drv[D_AMP]) + prm[P_M] * prm[P_G] / prm[P_KN])
    if p == 0:
        return count, slips, n_ref, off
    before = book[(count - 1 - p) % TOUCHDOWNS]
    cycle = 2.0 * math.pi / drv[D_OMEGA]
    period = round((t_now - before[T_TIME]) / cycle) * cycle
    u_left = (n_to - n_ref) * dt + (off_to - off)
    skips = math.floor(u_left / period) - 1.0 if period > 0.0 else -1.0
    if skips < 1.0:
        return count, slips, n_ref, off
    s[Y_X] += skips * prm[P_VD] * period
    s[Y_PHI] += skips * (s[Y_PHI] - before[T_PHI])
    s[Y_WORK] += skips * (s[Y_WORK] - before[T_WORK])
    s[Y_DISSIPATED] += skips * (s[Y_DISSIPATED] - before[T_DISS])
    slips += np.int64(skips) * np.int64(slips - before[T_SLIPS])
    costs[1] += np.int64(skips) * np.int64(round(period / cycle))
    n_ref, off = carry(n_ref, off + skips * period, dt)
    return 0, slips, n_ref, off
