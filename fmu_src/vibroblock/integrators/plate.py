"""The plate's vertical motion as the integrators see it: the harmonic drive
A sin(theta) plus the external input held over a communication step.

The drive's phase at grid step n is a function of n alone (anchored where omega last
changed), so a run split anywhere sees the same plate.  In the step loops its sine and
cosine advance by a rotation each step (a sin/cos pair costs more than a whole model-A
step) and are recomputed exactly every RESYNC steps from the anchor, so rounding cannot
build up and the values depend on n only.
"""
import math

from .. import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ..dynamics import plate_motion
from ..layout import C_PHASE_STEP, D_AMP, D_DT, D_EXT_A, D_EXT_T, D_EXT_V, D_EXT_Z, D_OMEGA, D_PHASE, D_T0

RESYNC = 256


@njit(inline="always")
def drive_phase(drv, cnt, n):
    return drv[D_PHASE] + drv[D_OMEGA] * drv[D_DT] * (n - cnt[C_PHASE_STEP])


@njit(inline="always")
def drive_sin_cos(drv, cnt, n):
    """sin and cos of the drive phase at step n, bit-identical to what a run reaching
    step n through the rotation recurrence holds."""
    since_anchor = n - cnt[C_PHASE_STEP]
    base = n - since_anchor % RESYNC
    phase = drive_phase(drv, cnt, base)
    s, c = math.sin(phase), math.cos(phase)
    rot_s, rot_c = math.sin(drv[D_OMEGA] * drv[D_DT]), math.cos(drv[D_OMEGA] * drv[D_DT])
    for _ in range(n - base):
        s, c = s * rot_c + c * rot_s, c * rot_c - s * rot_s
    return s, c


@njit(inline="always")
def next_sin_cos(drv, cnt, n, s, c, rot_s, rot_c):
    """sin and cos at step n from those at step n - 1 (resynchronised every RESYNC steps)."""
    if ((n - cnt[C_PHASE_STEP]) & (RESYNC - 1)) == 0:
        phase = drive_phase(drv, cnt, n)
        return math.sin(phase), math.cos(phase)
    return s * rot_c + c * rot_s, c * rot_c - s * rot_s


@njit(inline="always")
def plate_at(drv, s, c, t):
    """Plate height and velocity at time t, the drive's phase having sine s, cosine c."""
    return plate_motion(drv[D_AMP], drv[D_OMEGA], s, c, drv[D_EXT_Z], drv[D_EXT_V], drv[D_EXT_A],
                        t - drv[D_EXT_T])


@njit(inline="always")
def plate_moves(drv):
    """False for a plate at rest (no drive, no input): the loops then skip its kinematics,
    which gives the same bits (the plate formula returns the same height and 0 velocity)."""
    return drv[D_AMP] != 0.0 or drv[D_EXT_V] != 0.0 or drv[D_EXT_A] != 0.0


@njit(inline="always")
def phase_at_time(drv, cnt, t):
    anchor_time = drv[D_T0] + cnt[C_PHASE_STEP] * drv[D_DT]
    return drv[D_PHASE] + drv[D_OMEGA] * (t - anchor_time)


@njit(inline="always")
def plate_at_time(drv, cnt, t):
    """Plate height and velocity at an arbitrary time (off the grid): exact sin/cos."""
    phase = phase_at_time(drv, cnt, t)
    return plate_at(drv, math.sin(phase), math.cos(phase), t)
