"""Vertical plate motion: the internal harmonic drive A sin(omega t) plus the external input plate_z, plate_v, plate_a.

The external input is held at constant acceleration over a communication step (tau is
the time since it was set), so a master's samples of a record are played as a piecewise
parabola whose velocity is continuous where the master's samples are consistent.
"""
from numba import njit

ID = 0
SIDEWAYS = False  # no horizontal motion: the kernels skip the plate frame's force


def amplitudes(amplitude: float, angle: float) -> tuple[float, float]:
    """The drive's vertical and horizontal amplitudes (``layout.D_AMP``, ``D_AMP_X``)."""
    return amplitude, 0.0


@njit(inline="always")
def motion(amp, omega, sin_phase, cos_phase, ext_z, ext_v, ext_a, tau):
    """Plate height and velocity."""
    z = amp * sin_phase + ext_z + tau * (ext_v + 0.5 * ext_a * tau)
    v = amp * omega * cos_phase + ext_v + ext_a * tau
    return z, v


@njit(inline="always")
def acceleration(amp, omega, sin_phase, ext_a):
    """Plate acceleration (the external input's held over the step)."""
    return -amp * omega * omega * sin_phase + ext_a


@njit(inline="always")
def horizontal(amp_x, omega, sin_phase, cos_phase, ext_x, ext_vx, ext_ax, tau):
    """The plate's horizontal position, velocity and acceleration: none."""
    return 0.0, 0.0, 0.0
