"""The Block FMUs' interface as a markdown table (``python -m vibroblock.interface``).

The README's interface table is this module's output; a test keeps the two equal.
"""
from .integrators import INTEGRATOR_RECORDS, INTEGRATORS
from .models import VARIANTS, offered_by
from .parameters import DEFAULT_INTEGRATOR, INITIAL_STATES, INTEGRATOR_OPTIONS, SCENE_OPTIONS
from .readings import choices

CHOICES = choices()  # the readings and the laws

VERTICAL_INPUTS = {
    "plate_z": ("delta_0", "external plate height, added to the internal drive"),
    "plate_v": ("delta_0/tau_0", "external plate velocity"),
    "plate_a": ("delta_0/tau_0^2", "external plate acceleration; over a communication step the plate follows "
                "plate_z + plate_v tau + plate_a tau^2/2"),
}
HORIZONTAL_INPUTS = {
    "plate_x": ("delta_0", "external horizontal plate position, along +x (plate_motion = 1 only; 0 otherwise)"),
    "plate_vx": ("delta_0/tau_0", "external horizontal plate velocity (plate_motion = 1 only)"),
    "plate_ax": ("delta_0/tau_0^2", "external horizontal plate acceleration (plate_motion = 1 only); over a "
                 "communication step the plate follows plate_x + plate_vx tau + plate_ax tau^2/2"),
}
INPUTS = {**VERTICAL_INPUTS, **HORIZONTAL_INPUTS}  # the Block FMUs' (the chain has the vertical ones)
OUTPUTS = {
    "x": ("Real", "delta_0", "horizontal block position"),
    "z": ("Real", "delta_0", "vertical block position"),
    "vx": ("Real", "delta_0/tau_0", "horizontal block velocity"),
    "vz": ("Real", "delta_0/tau_0", "vertical block velocity"),
    "friction_force": ("Real", "m_0 delta_0/tau_0^2",
                       "tangential spring force -k_t F along the plate's tangent, 0 out of contact"),
    "normal_force": ("Real", "m_0 delta_0/tau_0^2", "normal contact force k_n delta - gamma_n u_n, 0 out of contact"),
    "contact": ("Boolean", "", "block penetrates the plate (delta > 0)"),
    "coulomb_resets": ("Integer", "", "Coulomb resets of the loaded tangential spring (|k_t F| >= mu_s N) since "
                       "the start; a slip of the block holds many (the spring rings and breaks again), and of a "
                       "cascade of resets before a detachment the count holds as many as the integrator resolves. "
                       "Slips are counted from the motion (harness.runs.observables)"),
    "slip_count": ("Integer", "", "old name of coulomb_resets, the same value (kept for one release): it counts "
                   "Coulomb resets, not slips"),
    "phi_integral": ("Real", "delta_0^2/tau_0", "integral of (vx - V_d)^2 dt since the start"),
    "penetration": ("Real", "delta_0", "penetration delta along the surface normal, > 0 in contact: (Z_p - z) cos(alpha) "
                    "(formulation 0), P(t) - zeta (formulation 1, zeta the block's normal coordinate)"),
    "surface_z": ("Real", "delta_0", "height of the plate surface Z_p(x, t) under the block"),
    "work_input": ("Real", "m_0 delta_0^2/tau_0^2", "work done on the block by the drive, the plate and the load "
                   "since the start (with energy_balance)"),
    "energy_dissipated": ("Real", "m_0 delta_0^2/tau_0^2", "energy dissipated by the dashpots and released by "
                          "friction resets since the start (with energy_balance)"),
    "energy_residual": ("Real", "m_0 delta_0^2/tau_0^2", "stored energy change - work + dissipated: zero for the "
                        "exact dynamics, the integration error otherwise (with energy_balance)"),
}
# The cost since the start of the integrators that are not fixed-step (0 for the
# fixed-step ones, whose steps are the grid's, (t - t0) / dt), as Integer outputs: name ->
# (``Block.counters``' key, description).  An fmi2Integer has 32 bits: held at its
# largest value beyond it.
COSTS = {
    "accepted_steps": ("accepted", "internal steps the adaptive integrator accepted since the start (none where it "
                       "takes exact flows, exact_flows on model A)"),
    "rejected_steps": ("rejected", "internal steps the adaptive integrator rejected since the start (error test "
                       "failed, or a step past the plate's cap retaken)"),
    "located_events": ("events", "switches the adaptive or event_driven integrator located since the start "
                       "(contact, detachment, Coulomb reset, zero of N)"),
    "jacobian_evaluations": ("jacobians", "Jacobians the adaptive integrator evaluated since the start "
                             "(RODAS4's linearisations)"),
    "periods_jumped": ("periods_jumped", "plate periods crossed since the start by the adaptive integrator's "
                       "stroboscopic jumps, or skipped by the exact flows (event_driven, adaptive on model A) "
                       "once the motion is periodic"),
}
OUTPUTS.update({name: ("Integer", "", text) for name, (_, text) in COSTS.items()})
# The outputs that count the integrator's work (``Block.counters``' keys).
COST_OUTPUTS = {name: key for name, (key, _) in COSTS.items()}
INTEGRATOR_CHOICES = ", ".join(f"{i} = {name}" for name, i in INTEGRATORS.items())
# The outputs kept under an old name for one release: old name -> new name.
OUTPUT_ALIASES = {"slip_count": "coulomb_resets"}
DEFAULT_INTEGRATOR_ID = INTEGRATORS[DEFAULT_INTEGRATOR]
DEFAULT_INTEGRATOR_TEXT = (f"default {DEFAULT_INTEGRATOR_ID} = {DEFAULT_INTEGRATOR} on every model: on model A it "
                           "takes event_driven's exact flows (option exact_flows), on models B and C "
                           "error-controlled steps; 0 = symplectic_euler is the paper's first-order scheme")
ENERGY_BALANCE = "account work, dissipation and stored energy (outputs work_input, energy_dissipated, " \
    "energy_residual; about a third more time per step)"
INITIAL_CHOICES = "; ".join(f"{i} = {text}" for i, text in INITIAL_STATES.items())


def reading_choices(name: str) -> str:
    """The FMU description of a reading or a law: its values and what each means."""
    return "; ".join(f"{value} = {text}" for value, text in CHOICES[name][1].items()) + \
        " (docs/physics.md; fixed before initialization)"


def _models_column(names) -> str:
    return "".join(names)


def parameter_rows():
    """Every parameter once, with the variants that have it and their defaults, in an
    order that keeps each variant's own FMU order."""
    order, specs, defaults = [], {}, {}
    for variant in VARIANTS.values():
        previous = None
        for p in variant.parameters:
            if p.name not in specs:
                specs[p.name] = p
                order.insert(order.index(previous) + 1 if previous else 0, p.name)
            defaults.setdefault(p.name, {})[variant.name] = p.default
            previous = p.name
    return [(specs[name], defaults[name]) for name in order]


def markdown_table() -> str:
    rows = ["| name | kind | models | unit | default | meaning |", "|---|---|---|---|---|---|"]
    every = _models_column(sorted(VARIANTS))
    for p, defaults in parameter_rows():
        kind = "parameter, tunable" if p.tunable else "parameter"
        default = f"{p.default:g}"
        overridden = sorted(m for m, value in defaults.items() if value != p.default)
        if overridden:
            default += f" ({', '.join(overridden)}: {defaults[overridden[0]]:g})"
        rows.append(f"| `{p.name}` | {kind} | {_models_column(sorted(defaults))} | {p.unit} | {default} | "
                    f"{p.description} |")
    rows.append(f"| `integrator` | parameter (Integer) | {every} | | {DEFAULT_INTEGRATOR_ID} | {INTEGRATOR_CHOICES} "
                f"({DEFAULT_INTEGRATOR_TEXT}) |")
    for name, (models, default, text) in INTEGRATOR_OPTIONS.items():
        rows.append(f"| `{name}` | parameter (Boolean) | {_models_column(offered_by(models))} | | "
                    f"{str(default).lower()} | {text} |")
    rows.append(f"| `initial_state` | parameter (Integer) | {every} | | 0 | {INITIAL_CHOICES} |")
    for name, (models, _) in CHOICES.items():
        rows.append(f"| `{name}` | parameter (Integer) | {_models_column(offered_by(models))} | | 0 | "
                    f"{reading_choices(name)} |")
    rows.append(f"| `energy_balance` | parameter (Boolean) | {every} | | false | {ENERGY_BALANCE} |")
    for name, (models, text) in SCENE_OPTIONS.items():
        rows.append(f"| `{name}` | parameter (Boolean) | {_models_column(offered_by(models))} | | false | {text} |")
    for name, (unit, text) in INPUTS.items():
        rows.append(f"| `{name}` | input | {every} | {unit} | 0 | {text} |")
    for name, (kind, unit, text) in OUTPUTS.items():
        rows.append(f"| `{name}` | output ({kind}) | {every} | {unit} | | {text} |")
    return "\n".join(rows)


def integrator_table() -> str:
    """The integrators as a markdown table (the README's), from the registry."""
    rows = ["| id | name | models | force evaluations per step | what it is |", "|---|---|---|---|---|"]
    for record in INTEGRATOR_RECORDS.values():
        cost = str(record.force_evaluations) if record.force_evaluations else "per event"
        rows.append(f"| {record.id} | `{record.name}` | {_models_column(offered_by(record.models))} | {cost} | "
                    f"{record.summary} |")
    return "\n".join(rows)


if __name__ == "__main__":
    print(markdown_table())
