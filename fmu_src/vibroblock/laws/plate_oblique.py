"""Oblique plate motion: the harmonic drive A sin(omega t) along a direction drive_angle from the vertical, plus the external input in z and x.

The plate moves rigidly, corrugation included, by (p_x(t), p_z(t)): the drive's
A cos(drive_angle) sin(omega t) vertically and A sin(drive_angle) sin(omega t) along +x
(the drive spring's direction), plus the external input plate_z, plate_v, plate_a and
plate_x, plate_vx, plate_ax, each held at constant acceleration over a communication
step as under the vertical law.  drive_angle = pi/2 shakes horizontally.

The kernels integrate the block in the plate's frame, X = x - p_x(t): there the
surface, the contact and the friction spring see the block's motion relative to the
plate, and the plate's horizontal motion enters as the force -m p_x'' - k_d p_x (the
inertial force of the frame, and the drive spring's far end being fixed in the lab).
The outputs x and vx are the lab's, X + p_x and X' + p_x'; phi integrates the slip
velocity relative to the plate, (X' - V_d)^2, which is the paper's phi under vertical
shaking and keeps its meaning (zero drift while stuck) under horizontal shaking.  The
energy balance is kept in the plate's frame, the force above booked as work.
"""
import math

from numba import njit

from ..parameters import FINITE, Parameter
from .plate_vertical import acceleration, motion  # noqa: F401  (the vertical part is the vertical law's)

ID = 1
SIDEWAYS = True
PARAMETERS = (
    Parameter("drive_angle", 0.0, "rad", "direction of the harmonic drive from the vertical towards +x "
              "(plate_motion = 1; pi/2: horizontal shaking)", FINITE),
)
REFUSED_BY = {
    "event_driven": "its closed-form regimes hold for a vertical plate drive only; use rk4 or symplectic_euler",
    "adaptive": "its stroboscopic jumps and event search take the plate as moving vertically only; use rk4 or "
                "symplectic_euler",
}
# Readings whose equations have no horizontal plate motion.
REFUSED_READINGS = {
    ("formulation", 1): "the tangent frame's printed equations (Eqs. 3-6) move the plate along the local normal "
                        "only; use formulation = 0 (fixed axes) with plate_motion = 1",
}


def amplitudes(amplitude: float, angle: float) -> tuple[float, float]:
    """The drive's vertical and horizontal amplitudes (``layout.D_AMP``, ``D_AMP_X``)."""
    return amplitude * math.cos(angle), amplitude * math.sin(angle)


@njit(inline="always")
def horizontal(amp_x, omega, sin_phase, cos_phase, ext_x, ext_vx, ext_ax, tau):
    """The plate's horizontal position, velocity and acceleration."""
    x = amp_x * sin_phase + ext_x + tau * (ext_vx + 0.5 * ext_ax * tau)
    v = amp_x * omega * cos_phase + ext_vx + ext_ax * tau
    a = -amp_x * omega * omega * sin_phase + ext_ax
    return x, v, a
