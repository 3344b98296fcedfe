"""The outputs of a run from its observation array (``layout.O_*``): the block as a point,
the plate surface under it, and the energy balance, each energy booked as its potential.

Plain Python on the observation an observe kernel filled (an output read compiles
nothing); ``Block._observables`` caches the result per time.
"""
from __future__ import annotations

import math

from . import layout as L
from .initial_state import frame_to_point
from .laws import law


def maps_to_point(settings) -> bool:
    """Whether outputs go through ``as_point``: any reading other than the default (the
    laws do not change what the state slots mean)."""
    r = settings.readings
    return bool(r["formulation"] or r["coulomb_normal"] or r["flight"])


def as_point(settings, prm, x, z, vx, vz, pen):
    """Surface height under the block and the block as a point (z, vx, vz).  In the
    tangent frame the state (x, zeta, u, w) maps to z = h + zeta / cos a etc.
    (docs/physics.md, Sec. 4) and the plate surface under the block is at normal
    coordinate P = zeta + delta; in fixed axes the state is the point already."""
    height, slope = settings.variant.profile(x, prm)
    secant = math.sqrt(1.0 + slope * slope)  # 1 / cos a
    if settings.tangent_frame:
        z, vx, vz = frame_to_point(settings.variant, prm, x, z, vx, vz)
    return z + pen * secant, z, vx, vz


def contact_energy(settings, prm, penetration: float) -> float:
    """The contact law's potential U(delta), 0 out of contact (the law's Python function)."""
    potential = law("contact", settings.readings.get("contact_law", 0)).module.potential.py_func
    return float(potential(penetration, prm)) if penetration > 0.0 else 0.0


def stored_energy(settings, prm, obs, t: float) -> float:
    """Kinetic + drive spring + friction spring + contact energy, each booked as its
    potential at the observed state (in the tangent frame the kinetic energy is
    m (u^2 + w^2) / 2, from the state's own slots): so the energy residual measures
    the truth, also where a contact law is not conservative.  An oblique plate's balance
    is kept in the plate's frame (``laws.plate_oblique``): x and vx relative to the plate."""
    p = settings.parameters
    x, vx, vz, shear = obs[L.O_X] - obs[L.O_PLATE_X], obs[L.O_VX] - obs[L.O_PLATE_VX], obs[L.O_VZ], obs[L.O_F]
    stretch = x - p["V_d"] * t
    friction = float(law("friction", settings.readings.get("friction_law", 0)).module.energy.py_func(shear, prm))
    contact = contact_energy(settings, prm, obs[L.O_PENETRATION])
    return (0.5 * p["m"] * (vx * vx + vz * vz) + 0.5 * p["k_d"] * stretch * stretch + friction + contact)


def observables(settings, prm, obs, stored_at_start: float) -> dict:
    """The outputs but the cost counters, from the observation ``obs``."""
    residual = 0.0
    if settings.energy_balance:
        stored = stored_energy(settings, prm, obs, obs[L.O_T])
        residual = stored - stored_at_start - obs[L.O_WORK] + obs[L.O_DISSIPATED]
    pen, x, z, vx, vz = obs[L.O_PENETRATION], obs[L.O_X], obs[L.O_Z], obs[L.O_VX], obs[L.O_VZ]
    surface_z = z + pen / obs[L.O_COS]
    if maps_to_point(settings):  # (the surface at the plate's abscissa: an oblique plate carries it along x)
        surface_z, z, vx, vz = as_point(settings, prm, x - obs[L.O_PLATE_X], z, vx, vz, pen)
    return {
        "x": float(x), "z": float(z), "vx": float(vx), "vz": float(vz),
        "friction_force": float(obs[L.O_FRICTION]),
        "normal_force": float(obs[L.O_NORMAL]),
        "contact": bool(obs[L.O_CONTACT] != 0.0),
        "coulomb_resets": int(obs[L.O_SLIPS]),
        "slip_count": int(obs[L.O_SLIPS]),  # the old name of coulomb_resets (interface.OUTPUT_ALIASES)
        "phi_integral": float(obs[L.O_PHI]),
        "penetration": float(pen),
        "surface_z": float(surface_z),
        "work_input": float(obs[L.O_WORK]),
        "energy_dissipated": float(obs[L.O_DISSIPATED]),
        "energy_residual": float(residual),
    }
