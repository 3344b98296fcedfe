"""The model's parameters: names, paper defaults, units and admissible values.

One table serves the FMU interface (variable names, start values, descriptions),
the core's validation and the README's interface table, so the three cannot drift.
A variant's own parameters and its defaults are declared in its module (``models``);
``models.parameters_for`` assembles a variant's full list.  Importing this module
loads nothing but the standard library.

Units follow the paper (Sec. II C): m = g = k_n = 1, lengths in delta_0 = m g / k_n,
times in tau_0 = sqrt(m / k_n).  Physical parameters are Real; the switches (integrator, initial state, readings,
scene options, integrator options) are Integer or Boolean.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

# What a value must satisfy; the message completes "must be ...".
FINITE = "finite"
POSITIVE = "positive"
NON_NEGATIVE = "non-negative"

_CHECKS = {
    FINITE: (lambda v: True, "a finite number"),
    POSITIVE: (lambda v: v > 0.0, "a finite number > 0"),
    NON_NEGATIVE: (lambda v: v >= 0.0, "a finite number >= 0"),
}


@dataclass(frozen=True)
class Parameter:
    name: str
    default: float
    unit: str
    description: str
    constraint: str = FINITE
    tunable: bool = False

    def problem(self, value) -> str | None:
        """Why ``value`` is not admissible for this parameter, or None."""
        try:
            v = float(value)
        except (TypeError, ValueError):
            return f"{self.name} = {value!r} is not a number"
        ok, wanted = _CHECKS[self.constraint]
        if not math.isfinite(v) or not ok(v):
            return f"{self.name} = {v!r} is not admissible: it must be {wanted} ({self.description})"
        return None


L, T = "delta_0", "tau_0"
# Parameters every variant has, in the FMU's order; a variant's own parameters (its
# surface and load, declared in its module under ``models``) come after ``VARIANT_AFTER``.
# ``g`` is offered only by the variants that are confined by gravity (they list it).
COMMON_PARAMETERS: tuple[Parameter, ...] = (
    Parameter("m", 1.0, "m_0", "block mass", POSITIVE),
    Parameter("g", 1.0, f"{L}/{T}^2", "gravitational acceleration (models A, B)", NON_NEGATIVE),
    Parameter("k_n", 1.0, f"m_0/{T}^2", "normal contact stiffness", POSITIVE),
    Parameter("k_t", 0.28, f"m_0/{T}^2", "tangential (Cundall-Strack) contact stiffness", NON_NEGATIVE),
    Parameter("gamma_n", 0.07, f"m_0/{T}", "normal contact damping", NON_NEGATIVE),
    Parameter("gamma_t", 2.5e-4, f"m_0/{T}", "tangential damping", NON_NEGATIVE),
    Parameter("mu_s", 0.5, "1", "static friction coefficient (Coulomb bound mu_s N)", NON_NEGATIVE),
    Parameter("k_d", 5e-4, f"m_0/{T}^2", "drive spring stiffness", NON_NEGATIVE),
    Parameter("V_d", 2e-5, f"{L}/{T}", "drive velocity of the spring's far end", FINITE),
    Parameter("A", 0.0, L, "amplitude of the internal plate drive A sin(omega t)", FINITE, tunable=True),
    Parameter("omega", 0.0, f"1/{T}", "angular frequency of the internal plate drive", NON_NEGATIVE, tunable=True),
    Parameter("dt", 4e-4, T, "internal integration step (adaptive, event_driven: the grid the state is stored on)",
              POSITIVE),
    Parameter("rtol", 1e-8, "1", "relative tolerance of the adaptive integrator's local error", POSITIVE),
    Parameter("atol", 1e-10, "delta_0, delta_0/tau_0", "absolute tolerance of the adaptive integrator's local error "
              "(lengths and velocities)", POSITIVE),
    Parameter("max_jump", 1e12, "1", "most plate periods one stroboscopic jump of the adaptive integrator may span "
              "while the block is held on a harmonically vibrating plate (below 4: every period resolved)",
              NON_NEGATIVE),
    Parameter("x_start", 0.0, L, "initial horizontal position", FINITE),
    Parameter("z_start", 0.0, L, "initial height (used when initial_state = 1)", FINITE),
    Parameter("vx_start", 0.0, f"{L}/{T}", "initial horizontal velocity", FINITE),
    Parameter("vz_start", 0.0, f"{L}/{T}", "initial vertical velocity (initial_state 0 and 1)", FINITE),
)
ALL_VARIANTS = "*"  # a scene option or parameter every registered variant offers
OPTIONAL_COMMON = ("g",)  # present only in the variants that list them in their PARAMETERS
VARIANT_AFTER = "omega"

# Scene reductions (``vibroblock.scenes``): physics a scene may drop.  Boolean
# parameters, off by default; name -> (variants that offer it, description).  One table for the FMU
# variables, the core's validation and the README.
SCENE_OPTIONS = {
    "rigid_contact": (ALL_VARIANTS, "rigid instead of compliant normal contact: the block rides the surface until the "
                      "normal force would pull, then flies and lands with restitution 0 (drops k_n, gamma_n and "
                      "their dt limit; detachment at max plate acceleration = load/m)"),
    "frozen_vertical": ("A", "vertical motion frozen on the steady in-contact orbit of the drive (external plate "
                        "acceleration pressing quasi-statically); a guard hands over to the full model when that "
                        "orbit would lose contact (A >= A_c(omega))"),
    "coulomb_friction": (ALL_VARIANTS, "plain Coulomb friction instead of the history-dependent spring: stuck while the "
                         "needed tangential force stays below mu_s N, else sliding against mu_s N (drops k_t, F)"),
}

# Options of an integrator: Boolean parameters, fixed before initialization; name ->
# (variants that offer it, default, description).  One table for the FMU variables, the
# core's validation and the README.
INTEGRATOR_OPTIONS = {
    "exact_flows": ("A", True, "adaptive on model A, whose every regime is linear: take each regime by its exact "
                    "flow (event_driven's closed forms and event search; rtol, atol and max_jump unused) wherever "
                    "event_driven runs the reading and the parameters; false: error-controlled steps as on models "
                    "B and C"),
}

# The integrator a run gets where the user does not choose one (the FMUs' start value of
# ``integrator``, the harness's and the command line's default).  ``adaptive`` is the one
# integrator every variant and every reading runs, and the accurate and cheap choice on each:
# on model A it takes event_driven's exact flows (option exact_flows: the same results and
# cost as event_driven), on models B and C its error-controlled steps (README, "Choosing
# speed or accuracy").  The paper's first-order scheme stays one parameter away
# (integrator = symplectic_euler, 0).  The core's ``Block`` keeps the paper's scheme as its
# own Python default, which its tests rely on.
DEFAULT_INTEGRATOR = "adaptive"

INITIAL_STATES = {
    0: "equilibrium: at rest (vx_start, vz_start) at the rest penetration under the plate's initial position",
    1: "given: x_start, z_start, vx_start, vz_start as set",
    2: "steady_orbit: on the steady in-contact orbit of the harmonic drive (exact for model A)",
}

# The readings of the paper a run chooses (docs/physics.md): Integer parameters, fixed
# before initialization; name -> (variants that offer it, {value: "name: meaning"}).
# 0 is today's reading and the default.  One table for the FMU variables, the core's
# validation and the README.
READINGS = {
    "formulation": ("BC", {
        0: "fixed_axes: Newton's law for the block as a point in fixed axes, the plate moving vertically",
        1: "tangent_frame: the paper's Eqs. (3)-(6) as printed, in a frame tangent to the plate at the block",
    }),
    "flight": (ALL_VARIANTS, {
        0: "surface: off contact the load and tangential dashpot act as on the surface under the block",
        1: "free: off contact a free particle (vertical load, dashpot on dx/dt); fixed_axes only",
    }),
}
# The laws (contact, Coulomb bound, ...) are Integer choices of the same kind, registered
# in ``vibroblock.laws``; ``vibroblock.readings.CHOICES`` holds both tables.


def reading_names(name: str, table: dict | None = None) -> dict[int, str]:
    """value -> short name of one reading (e.g. 0 -> "fixed_axes"), or of one choice of ``table``."""
    return {value: text.split(":", 1)[0] for value, text in (table or READINGS)[name][1].items()}
