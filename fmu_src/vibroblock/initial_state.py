"""The block's initial state (``initial_state``): at rest, as given, or on the steady
in-contact orbit of the drive (``orbits.steady_orbit``), and its placement for a
reduced scene."""
from __future__ import annotations

import math

from . import layout as L
from .laws import law
from .models import frame
from .orbits import steady_orbit
from .settings import ModelError, Settings


def place(settings: Settings, prm, drv, y) -> bool:
    """Set position and velocity in ``y`` for a run starting at the drive phase in ``drv``.
    Returns False if a frozen vertical motion cannot start (its orbit does not keep
    contact): the caller hands over to the full model at once."""
    p, variant = settings.parameters, settings.variant
    x = p["x_start"]
    height, slope = variant.profile(x, prm)
    cos_a, sin_a = 1.0 / math.sqrt(1.0 + slope * slope), slope / math.sqrt(1.0 + slope * slope)
    phase, amplitude = drv[L.D_PHASE], drv[L.D_AMP]  # (the drive's vertical amplitude: A under the vertical law)
    plate_z = amplitude * math.sin(phase) + height
    plate_v = amplitude * p["omega"] * math.cos(phase)
    # The confining load's component into the plate sets the rest penetration.
    load_x, load_z = variant.load(cos_a, sin_a, prm)
    weight = max(0.0, -(-load_x * sin_a + load_z * cos_a))
    y[L.Y_X], y[L.Y_VX] = x, p["vx_start"]
    if settings.tangent_frame:
        _place_in_tangent_frame(settings, prm, y, weight, phase)
        return _place_for_scene(settings, prm, drv, y)
    if settings.initial_state == 0:
        y[L.Y_Z] = plate_z - weight / (_contact_at_rest(settings, weight)[0] * cos_a)
        y[L.Y_VZ] = p["vz_start"]
    elif settings.initial_state == 1:
        y[L.Y_Z], y[L.Y_VZ] = p["z_start"], p["vz_start"]
    else:
        offset, rate = _steady_orbit(settings, weight, phase, amplitude)
        y[L.Y_Z], y[L.Y_VZ] = plate_z + offset, plate_v + rate
    if drv[L.D_AMP_X] != 0.0:
        _into_plate_frame(settings, drv, y)
    return _place_for_scene(settings, prm, drv, y)


def _into_plate_frame(settings: Settings, drv, y) -> None:
    """An oblique plate's run is integrated in the plate's frame (``laws.plate_oblique``):
    x_start is where the block is in the lab, and its horizontal velocity is vx_start in
    the lab if given (initial_state = 1), else relative to the plate (resting on it, or on
    its steady orbit, moves with it)."""
    phase, omega = drv[L.D_PHASE], settings.parameters["omega"]
    plate_x, plate_vx = drv[L.D_AMP_X] * math.sin(phase), drv[L.D_AMP_X] * omega * math.cos(phase)
    y[L.Y_X] -= plate_x
    if settings.initial_state == 1:
        y[L.Y_VX] -= plate_vx


def _contact_at_rest(settings: Settings, weight: float) -> tuple[float, float, float]:
    """The run's contact law at rest under ``weight``: (secant stiffness, tangent
    stiffness, damping); the rest penetration is weight / secant (k_n for the linear laws)."""
    return law("contact", settings.readings["contact_law"]).module.rest(weight, settings.parameters)


def _steady_orbit(settings: Settings, weight, phase, amplitude=None):
    """``orbits.steady_orbit`` for the run's parameters (the drive's vertical ``amplitude``,
    A by default), about the contact's rest penetration; a nonlinear contact's orbit is its
    linearisation's there (a start close to the orbit, whose transient the contact's
    damping removes).  A drive that has none is refused."""
    p = settings.parameters
    amplitude = p["A"] if amplitude is None else amplitude
    secant, stiffness, damping = _contact_at_rest(settings, weight)
    try:
        oscillation, rate = steady_orbit(p["m"], stiffness, damping, 0.0, amplitude, p["omega"], phase)
    except ValueError as exc:
        raise ModelError(f"initial_state = 2 (steady_orbit): {exc}; start at rest or as given "
                         f"(initial_state = 0 or 1), or give the contact some damping") from None
    return -weight / secant + oscillation, rate


def point_to_frame(variant, prm, x, z, vx, vz):
    """The tangent frame's (zeta, u, w) of the point (x, z) moving at (vx, vz)
    (docs/physics.md, Sec. 4): zeta = (z - h) cos a, u = vx / cos a,
    w = cos a (vz - u sin a - zeta h'' u sin a cos a)."""
    height, slope = variant.profile(x, prm)
    cos_a, sin_a = frame.py_func(slope)
    zeta, u = (z - height) * cos_a, vx / cos_a
    return zeta, u, cos_a * (vz - u * sin_a - zeta * variant.curvature(x, prm) * u * sin_a * cos_a)


def frame_to_point(variant, prm, x, zeta, u, w):
    """The point (z, vx, vz) of a tangent-frame state (x, zeta, u, w): z = h + zeta / cos a,
    vx = u cos a, vz = u sin a + w / cos a + zeta h'' u sin a cos a."""
    height, slope = variant.profile(x, prm)
    cos_a, sin_a = frame.py_func(slope)
    return (height + zeta / cos_a, u * cos_a,
            u * sin_a + w / cos_a + zeta * variant.curvature(x, prm) * u * sin_a * cos_a)


def _place_in_tangent_frame(settings: Settings, prm, y, weight, phase) -> None:
    """The starts of Sec. 10 in the tangent frame's slots (x, zeta, u, w): the plate's
    position P along the normal, the start parameters read through the inverse map."""
    p, variant = settings.parameters, settings.variant
    x = p["x_start"]
    plate_p, plate_v = p["A"] * math.sin(phase), p["A"] * p["omega"] * math.cos(phase)
    zeta, u, w = point_to_frame(variant, prm, x, p["z_start"], p["vx_start"], p["vz_start"])
    if settings.initial_state == 0:
        zeta = plate_p - weight / _contact_at_rest(settings, weight)[0]
        height, slope = variant.profile(x, prm)
        z = height + zeta * math.sqrt(1.0 + slope * slope)  # h + zeta / cos a
        _, u, w = point_to_frame(variant, prm, x, z, p["vx_start"], p["vz_start"])
    elif settings.initial_state == 2:
        offset, rate = _steady_orbit(settings, weight, phase)
        zeta, w = plate_p + offset, plate_v + rate
    y[L.Y_Z], y[L.Y_VX], y[L.Y_VZ] = zeta, u, w


def _place_for_scene(settings: Settings, prm, drv, y) -> bool:
    """A rigid contact starts on the surface (moving with it unless initial_state = 1);
    a frozen vertical motion starts on its orbit if that orbit keeps contact."""
    p = settings.parameters
    phase = drv[L.D_PHASE]
    plate_z, plate_v = p["A"] * math.sin(phase), p["A"] * p["omega"] * math.cos(phase)
    if settings.scene["rigid_contact"] and settings.initial_state != 1:
        height, slope = settings.variant.profile(y[L.Y_X], prm)
        y[L.Y_Z], y[L.Y_VZ] = plate_z + height, plate_v + slope * y[L.Y_VX]
    if settings.scene["frozen_vertical"]:
        offset, rate = _steady_orbit(settings, p["m"] * p["g"], phase)
        if offset >= 0.0:
            return False
        y[L.Y_Z], y[L.Y_VZ] = plate_z + offset, plate_v + rate
    return True
