"""Stored outputs of the core for every model x integrator x scenario, bit for bit.

``python tests/golden_outputs.py`` records them into
``data/golden_outputs.json`` (floats as hex, so nothing is lost); the test
``fmu_src/vibroblock/test_golden_outputs.py`` recomputes and compares.  A refactoring of the core must
leave every value unchanged; a change of physics must re-record on purpose and say why.
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path

DATA = Path(__file__).resolve().parent / "fmu_src" / "vibroblock" / "data" / "golden_outputs.json"
SCALED = {"k_d": 1e-2, "V_d": 1e-2, "gamma_t": 5e-3}
# Times off and on the grid (dt = 4e-4 and 1e-2), ragged to exercise the scratch steps.
STOPS = (0.0, 0.33337, 3.0, 17.25, 40.00021, 80.0)
SCENARIOS = {
    "rest": dict(A=0.0, omega=0.0, initial_state=0),
    "vibrated": dict(A=0.6, omega=1.3, initial_state=2),
    "bouncing": dict(A=2.5, omega=0.9, initial_state=0),
}
INTEGRATORS = {"A": ("symplectic_euler", "rk4", "event_driven", "implicit_contact"),
               "B": ("symplectic_euler", "rk4", "implicit_contact"),
               "C": ("symplectic_euler", "rk4", "implicit_contact")}
SCENES = {"rigid_contact": "ABC", "frozen_vertical": "A", "coulomb_friction": "ABC"}
# adaptive's own error-controlled steps (on model A with its hand-over to exact flows off).
ADAPTIVE = {"A": dict(exact_flows=False), "B": {}, "C": {}}
# Each non-default reading, for every integrator that runs it (the others refuse it).
READING_CASES = {
    "formulation": ("BC", ("symplectic_euler", "rk4", "adaptive")),
    "coulomb_normal": ("ABC", ("symplectic_euler", "rk4", "implicit_contact", "adaptive")),
    "flight": ("BC", ("symplectic_euler", "rk4", "adaptive")),
}
# Long runs that take the integrators' period-skipping paths: adaptive's stroboscopic
# jumps over a held block on a vibrated plate, event_driven's skipped periods on a locked orbit.
LONG_STOPS = (0.0, 123.4567, 2000.0, 20000.00037)
LONG_CASES = {  # (each skips thousands of plate periods: periods_jumped, not stored, says so)
    "A/event_driven/locked_orbit": ("A", dict(integrator="event_driven", A=1.2, omega=1.2, initial_state=0,
                                              x_start=3.0)),
    # held in a trough of B's corrugation (omega_x x = -pi/2) by a soft, slow drive spring
    "B/adaptive/held_vibrated": ("B", dict(integrator="adaptive", A=0.05, omega=2.0, initial_state=2, rtol=1e-6,
                                           x_start=-25.0 * math.pi, k_d=1e-4, V_d=1e-5)),
    "C/adaptive/held_vibrated": ("C", dict(integrator="adaptive", A=0.05, omega=2.0, initial_state=2, rtol=1e-6,
                                           x_start=3.0)),
}


def cases():
    for model, integrators in INTEGRATORS.items():
        for integrator in integrators:
            for scenario, settings in SCENARIOS.items():
                dt = 1e-2 if integrator in ("event_driven", "implicit_contact") else 4e-3
                yield f"{model}/{integrator}/{scenario}", model, dict(
                    integrator=integrator, energy_balance=True, dt=dt, x_start=3.0, **SCALED, **settings)
    for scene, models in SCENES.items():
        for model in models:
            for scenario, settings in SCENARIOS.items():
                yield f"{model}/{scene}/{scenario}", model, dict(
                    integrator="symplectic_euler", energy_balance=True, dt=4e-3, x_start=3.0,
                    **{scene: True}, **SCALED, **settings)
    for model, options in ADAPTIVE.items():
        for scenario, settings in SCENARIOS.items():
            yield f"{model}/adaptive/{scenario}", model, dict(
                integrator="adaptive", energy_balance=True, dt=1e-2, x_start=3.0, **options, **SCALED, **settings)
    for reading, (models, integrators) in READING_CASES.items():
        for model in models:
            for integrator in integrators:
                dt = 1e-2 if integrator in ("adaptive", "implicit_contact") else 4e-3
                yield f"{model}/{integrator}/{reading}", model, dict(
                    integrator=integrator, energy_balance=True, dt=dt, x_start=3.0, **{reading: 1}, **SCALED,
                    **SCENARIOS["bouncing"])
    for key, (model, settings) in LONG_CASES.items():
        yield key, model, dict(energy_balance=True, dt=1e-2, stops=LONG_STOPS, **{**SCALED, **settings})
    # External plate input held over communication steps.
    for model in "ABC":
        yield f"{model}/external", model, dict(integrator="symplectic_euler", energy_balance=False, dt=4e-3,
                                              external_input=True, **SCALED)


def run_case(model, settings):
    from vibroblock import Block
    from vibroblock.block import ModelError
    from vibroblock.interface import COST_OUTPUTS
    settings = dict(settings)
    integrator = settings.pop("integrator")
    initial = settings.pop("initial_state", 0)
    energy = settings.pop("energy_balance")
    external = settings.pop("external_input", False)
    stops = settings.pop("stops", STOPS)
    block = Block(model, integrator, initial, energy, **settings)
    rows = []
    try:
        block.start()
        for i, t in enumerate(stops):
            if t > 0.0:
                if external:
                    block.set_plate_input(0.01 * i, 0.02 * (-1) ** i, 0.1 * i)
                block.advance_to(t)
            # The results; the cost outputs count an adaptive run's work, not what it computed.
            rows.append({name: (float(v).hex() if isinstance(v, float) else v)
                         for name, v in block.outputs().items() if name not in COST_OUTPUTS})
    except ModelError as exc:
        rows.append({"error": str(exc).split(";")[0]})
    return rows


def record():
    out = {key: run_case(model, settings) for key, model, settings in cases()}
    DATA.write_text(json.dumps(out, indent=0, sort_keys=True))
    print(f"recorded {len(out)} cases into {DATA}")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "fmu_src"))
    record()
