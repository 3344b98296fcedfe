"""The plate's vertical motion as the integrators see it: the harmonic drive
A sin(theta) plus the external input held over a communication step.

The drive's phase at grid step n is a function of n alone (anchored where omega last
changed), so a run split anywhere sees the same plate.  In the step loops its sine and
cosine advance by a rotation each step (a sin/cos pair costs more than a whole model-A
step) and are recomputed exactly every RESYNC steps from the anchor, so rounding cannot
build up and the values depend on n only.

The phase is kept reduced modulo 2 pi, and the product omega dt (n - anchor) is reduced
exactly (double-double arithmetic): summed as a plain double, omega t at t ~ 1e9 rounds
to ~1e-7 rad, so the plate would jitter by ~1e-7 A between evaluations and a run started
far from t = 0 would see another plate than one started at 0.  The phase at the start
and where omega changes is reduced exactly too (``reduced_phase``), so the phase at
grid step n is the drive's omega-dt multiple of n plus the anchor's, to ~1e-16 rad at
any n.
"""
import math
import numbers
from fractions import Fraction

from .. import jitcache  # noqa: F401  (first: numba's cache folder and locator)
from numba import njit

from ..dynamics import plate_motion
from ..laws import plate_horizontal
from ..layout import (C_PHASE_STEP, D_AMP, D_AMP_X, D_DT, D_EXT_A, D_EXT_AX, D_EXT_T, D_EXT_V, D_EXT_VX, D_EXT_X,
                      D_EXT_Z, D_OMEGA, D_PHASE, D_T0, P_KD, P_M)

RESYNC = 256
TWO_PI = 2.0 * math.pi
TWO_PI_TAIL = 2.4492935982947064e-16  # 2 pi - TWO_PI, so that the pair holds 2 pi to ~1e-32
# 2 pi to 60 digits, for the exact reductions done in Python.
TWO_PI_EXACT = Fraction("6.28318530717958647692528676655900576839433879875021164194988918")
VELTKAMP = 134217729.0  # 2**27 + 1: splits a double into two halves whose products are exact


@njit(inline="always")
def _exact_product(a, b):
    """a * b as an unevaluated sum p + e of two doubles, exactly (Dekker)."""
    p = a * b
    t = VELTKAMP * a
    a_hi = t - (t - a)
    a_lo = a - a_hi
    t = VELTKAMP * b
    b_hi = t - (t - b)
    b_lo = b - b_hi
    return p, ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo


@njit(inline="always")
def _below_one_turn(reduced):
    """A reduced phase in [0, 2 pi): one a rounding short of a whole turn (a phase of
    -1e-17, or a product a hair below k 2 pi) rounds to 2 pi itself, which is 0."""
    return reduced if reduced < TWO_PI else 0.0


@njit(inline="always")
def drive_phase(drv, cnt, n):
    """The drive's phase at grid step n, in [0, 2 pi)."""
    return grid_phase(drv, cnt[C_PHASE_STEP], n)


@njit(inline="always")
def grid_phase(drv, anchor, n):
    """The drive's phase at grid step n in [0, 2 pi): the anchor's phase plus
    (omega dt) (n - anchor), the product reduced modulo 2 pi before it is rounded."""
    rise, rise_tail = _exact_product(drv[D_OMEGA] * drv[D_DT], float(n - anchor))
    turns = math.floor(rise / TWO_PI)
    whole, whole_tail = _exact_product(turns, TWO_PI)
    # rise - whole is exact (the two agree to within a few 2 pi; Sterbenz).
    phase = ((rise - whole) + (rise_tail - whole_tail) - turns * TWO_PI_TAIL) + drv[D_PHASE]
    return _below_one_turn(phase - TWO_PI * math.floor(phase / TWO_PI))


def reduced_phase(phase, rate, elapsed):
    """(phase + rate * elapsed) modulo 2 pi, in [0, 2 pi), from the exact product of the
    two doubles: where the drive's phase is set (start, a change of omega) in Python."""
    # Python numbers only: numpy's fixed-width integers overflow inside Fraction.
    elapsed = int(elapsed) if isinstance(elapsed, numbers.Integral) else float(elapsed)
    exact = Fraction(float(phase)) + Fraction(float(rate)) * Fraction(elapsed)
    reduced = float(exact - TWO_PI_EXACT * math.floor(exact / TWO_PI_EXACT))
    return reduced if reduced < TWO_PI else 0.0  # as ``_below_one_turn``


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
    return drv[D_AMP] != 0.0 or drv[D_EXT_V] != 0.0 or drv[D_EXT_A] != 0.0 or drv[D_AMP_X] != 0.0


@njit(inline="always")
def plate_sideways(kind, drv, s, c, t):
    """The plate's horizontal position, velocity and acceleration at time t (the drive's
    phase having sine s, cosine c); zero under the vertical plate law."""
    return plate_horizontal(kind, drv[D_AMP_X], drv[D_OMEGA], s, c, drv[D_EXT_X], drv[D_EXT_VX], drv[D_EXT_AX],
                            t - drv[D_EXT_T])


@njit(inline="always")
def frame_force(kind, drv, prm, s, c, t):
    """The horizontal force on the block in the plate's frame (``laws.plate_oblique``): the
    frame's inertial force -m p_x'' and the drive spring's -k_d p_x (its far end is fixed
    in the lab, so in the plate's frame it sits at -p_x)."""
    position, _, acceleration = plate_sideways(kind, drv, s, c, t)
    return -prm[P_M] * acceleration - prm[P_KD] * position


@njit(inline="always")
def phase_after(drv, cnt, n, h):
    """The drive's phase a time h after grid step n (off the grid)."""
    return drive_phase(drv, cnt, n) + drv[D_OMEGA] * h


@njit(inline="always")
def plate_after(drv, cnt, n, h):
    """Plate height and velocity a time h after grid step n (off the grid): exact sin/cos."""
    phase = phase_after(drv, cnt, n, h)
    return plate_at(drv, math.sin(phase), math.cos(phase), drv[D_T0] + n * drv[D_DT] + h)
