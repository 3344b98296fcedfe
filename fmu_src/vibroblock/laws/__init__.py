"""The laws: contact, friction, Coulomb bound and plate motion, each a registered part.

A law is one module ``<axis prefix><name>.py`` in this package stating:

* its docstring, whose first line is its summary in the FMU and the docs;
* ``ID``: its value of the axis' Integer parameter (stable, never reused; 0 is the default);
* its compiled functions, the same for every law of an axis (below);
* optionally ``REFUSED_BY``: {integrator name: why it cannot run this law};
* optionally ``REFUSED_READINGS``: {(reading, value): why this law cannot run in it};
* optionally ``PARAMETERS``: its own parameters (``parameters.Parameter``, read in the
  kernels at ``layout.slot(name)``), offered by every variant, and ``check(parameters)``:
  why the parameters cannot run the law, or None.

The axes, their FMU parameter and the functions every law of the axis brings:

============  ================  ===============================================================
axis          parameter         functions
============  ================  ===============================================================
contact       ``contact_law``   force(delta, u_n, prm), elastic(delta, prm), dissipation(delta,
                                u_n, prm), potential(delta, prm); CONSERVATIVE: the elastic
                                force is -grad(potential) on a curved plate; LINEAR: the
                                force is linear in (delta, u_n) (event_driven needs it);
                                in Python: rest(load, p) -> (secant stiffness, tangent
                                stiffness, damping) at rest under the load (the start)
friction      ``friction_law``  spring_force(F, prm), energy(F, prm), released(F0, F1, prm),
                                rule(F, state, delta, N_b, u_t, h, prm) -> (F, state, reset):
                                the rule at the end of a step of length h, ``state``
                                the law's state (``layout.Y_FRICTION_STATE``), u_t the
                                slip rate there; in Python: initial_state(parameters),
                                the state at the start (absent: 0); in continuous time,
                                interface(F, s, N_b, prm) -> (the interface's slip rate
                                along F, ds/dt) for the integrated variable s =
                                integrated(state) (state = stored(s)), and INTERFACE_SLIPS
                                (False: the interface sticks between resets, no state to
                                integrate)
bound         ``coulomb_normal``  normal(kind, N, x, t, prm): the N of the bound mu_s N
plate         ``plate_motion``  motion(A, omega, sin, cos, ext_z, ext_v, ext_a, tau),
                                acceleration(A, omega, sin, ext_a) (the vertical motion,
                                the same for every law: D_AMP holds its amplitude);
                                horizontal(A_x, omega, sin, cos, ext_x, ext_vx, ext_ax, tau)
                                -> (x, v, a); in Python: amplitudes(A, angle) -> (A_z, A_x)
============  ================  ===============================================================

A run's laws are part of the kernels' ``kind`` (``vibroblock.readings``: a few bits per
axis), a run constant the compiled dispatch below branches on, so every law runs in the
same compiled kernels and choosing one compiles nothing.  Integrators call only these
functions (through ``vibroblock.dynamics``); no integrator writes a law's formula.
Adding a law is adding a module here (and, where an integrator's closed forms assume the
default law, a ``REFUSED_BY`` entry saying why).
"""
from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass
from types import ModuleType

from .. import jitcache  # noqa: F401  (before numba: the kernel cache's folder and locator)
from numba import njit  # noqa: E402

from ..dispatch import by_kind  # noqa: E402


@dataclass(frozen=True)
class Axis:
    name: str  # what the law decides
    parameter: str  # the FMU's Integer parameter choosing it
    prefix: str  # module prefix of its laws
    shift: int  # position of its bits in ``kind``
    width: int  # number of bits


# Bits 0-2 of kind hold the variant, 3 and 5 the readings formulation and flight
# (vibroblock.readings); bit 4 is free (the Coulomb bound's while it had two values).
AXES = {
    "contact": Axis("contact", "contact_law", "contact_", 6, 2),
    "friction": Axis("friction", "friction_law", "friction_", 8, 3),
    "bound": Axis("bound", "coulomb_normal", "bound_", 11, 2),
    "plate": Axis("plate", "plate_motion", "plate_", 13, 1),
}


@dataclass(frozen=True)
class Law:
    axis: str
    id: int
    name: str
    summary: str
    refused_by: dict
    module: ModuleType


def _discover() -> dict[str, dict[int, Law]]:
    modules = sorted(info.name for info in pkgutil.iter_modules(__path__))
    found: dict[str, dict[int, Law]] = {axis: {} for axis in AXES}
    for module_name in modules:
        axis = next((a for a in AXES.values() if module_name.startswith(a.prefix)), None)
        if axis is None:
            continue
        module = importlib.import_module(f"{__name__}.{module_name}")
        law = Law(axis.name, module.ID, module_name[len(axis.prefix):], module.__doc__.strip().splitlines()[0].rstrip("."),
                  dict(getattr(module, "REFUSED_BY", {})), module)
        if law.id in found[axis.name]:
            raise RuntimeError(f"laws {law.name} and {found[axis.name][law.id].name} share {axis.parameter} = {law.id}")
        if law.id >= 1 << axis.width and not (axis.width == 0 and law.id == 0):
            raise RuntimeError(f"{axis.parameter} = {law.id} does not fit the {axis.width} bits of kind: widen AXES")
        found[axis.name][law.id] = law
    for axis, laws in found.items():
        if 0 not in laws:
            raise RuntimeError(f"no default law (ID = 0) for the {axis} axis")
    return {axis: dict(sorted(laws.items())) for axis, laws in found.items()}


LAWS: dict[str, dict[int, Law]] = _discover()


def law(axis: str, value: int) -> Law:
    return LAWS[axis][value]


def law_parameters() -> tuple:
    """The laws' own parameters (``PARAMETERS`` of their modules), in the registry's order,
    each once (laws of one family, e.g. the two rate-and-state laws, share theirs)."""
    seen: dict = {}
    for laws in LAWS.values():
        for law_ in laws.values():
            for p in getattr(law_.module, "PARAMETERS", ()):
                seen.setdefault(p.name, p)
    return tuple(seen.values())


def friction_law_parameters(readings: dict) -> tuple:
    """The names of the chosen friction law's own parameters (e.g. rs_a under rate-and-state)."""
    module = LAWS["friction"][int(readings.get("friction_law", 0))].module
    return tuple(p.name for p in getattr(module, "PARAMETERS", ()))


def initial_friction_state(readings: dict, parameters: dict) -> float:
    """The friction law's state at the start (``layout.Y_FRICTION_STATE``)."""
    module = LAWS["friction"][int(readings.get("friction_law", 0))].module
    start = getattr(module, "initial_state", None)
    return float(start(parameters)) if start else 0.0


def encode(choices: dict) -> int:
    """The kind bits of a run's laws, from {parameter: value} (absent: the default)."""
    bits = 0
    for axis in AXES.values():
        bits |= int(choices.get(axis.parameter, 0)) << axis.shift
    return bits


def choices() -> dict[str, tuple[str, dict[int, str]]]:
    """The laws as the FMU's Integer choices: parameter -> (variants, {value: "name: summary"}),
    the format of ``parameters.READINGS``; an axis with one law has no parameter."""
    return {axis.parameter: ("*", {law.id: f"{law.name}: {law.summary}" for law in LAWS[name].values()})
            for name, axis in AXES.items() if len(LAWS[name]) > 1}


# ---------------------------------------------------------------- compiled dispatch
def _dispatch(axis_name: str, function: str, arguments: str):
    """A compiled ``(kind, arguments) -> law(kind).function(arguments)``, branching on the
    axis' bits of kind at run time (``vibroblock.dispatch``); a law that needs the variant
    (e.g. the applied load's normal) takes kind itself."""
    axis, laws = AXES[axis_name], LAWS[axis_name]
    takes_kind = arguments.startswith("kind,")
    return by_kind({law.id: getattr(law.module, function) for law in laws.values()},
                   f"(kind >> {axis.shift}) & {(1 << axis.width) - 1}",
                   arguments[len("kind, "):] if takes_kind else arguments, takes_kind, inline_default_only=True)


def _constant(axis_name: str, attribute: str):
    """A compiled ``kind -> law(kind).attribute`` for a Boolean module constant."""
    axis, laws = AXES[axis_name], LAWS[axis_name]
    mask = sum(1 << law.id for law in laws.values() if getattr(law.module, attribute))
    shift, width = axis.shift, (1 << axis.width) - 1

    @njit(inline="always")
    def constant(kind):
        return (mask >> ((kind >> shift) & width)) & 1 != 0
    return constant


contact_force = _dispatch("contact", "force", "penetration, u_n, prm")
contact_elastic = _dispatch("contact", "elastic", "penetration, prm")
contact_dissipation = _dispatch("contact", "dissipation", "penetration, u_n, prm")
contact_potential = _dispatch("contact", "potential", "penetration, prm")
contact_conservative = _constant("contact", "CONSERVATIVE")
friction_spring_force = _dispatch("friction", "spring_force", "shear, prm")
friction_energy = _dispatch("friction", "energy", "shear, prm")
friction_released = _dispatch("friction", "released", "before, after, prm")
friction_interface = _dispatch("friction", "interface", "shear, state, bound_normal, prm")
friction_interface_slips = _constant("friction", "INTERFACE_SLIPS")
friction_integrated = _dispatch("friction", "integrated", "state")
friction_stored = _dispatch("friction", "stored", "value")
friction_rule = _dispatch("friction", "rule", "shear, state, penetration, bound_normal, slip_rate, h, prm")
bound_normal = _dispatch("bound", "normal", "kind, contact_normal, x, t, prm")
plate_motion = _dispatch("plate", "motion", "amp, omega, sin_phase, cos_phase, ext_z, ext_v, ext_a, tau")
plate_horizontal = _dispatch("plate", "horizontal",
                             "amp_x, omega, sin_phase, cos_phase, ext_x, ext_vx, ext_ax, tau")
plate_moves_sideways = _constant("plate", "SIDEWAYS")
