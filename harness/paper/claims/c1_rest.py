"""C1 -- model A without vibration: rest penetration m g/k_n, creep V_S = V_d k_d/(k_t + k_d),
stick time mu_s m g/(k_t V_S) and slip length mu_s m g/k_d.

Criterion: each measured quantity within ``FORMULA_TOLERANCE`` (rest penetration:
``PENETRATION_TOLERANCE``) of its formula, relative."""
from __future__ import annotations

import math

from harness.runs.settings import InitialCondition, PointSettings

from .measure import OBSERVE_A, SCALED, observe_json, run_and_measure
from .study import Claim, Runner, Study
from .verdicts import AGREES, DISAGREES, FORMULA_TOLERANCE, NOT_REPRODUCED, Row, combine, fmt, relative

PENETRATION_TOLERANCE = 0.02

TEXT = {
    "C1": "A, no vibration: rest penetration mg/k_n, creep V_S = V_d k_d/(k_t+k_d), stick time mu_s "
          "mg/(k_t V_S), slip mu_s mg/k_d",
}
FIGURES = {
    "C1": ["fig1b.png"],
}


def study_c1(runner: Runner) -> Study:
    """Model A at rest: penetration, creep, stick time and slip length against their formulas."""
    res = runner.resolution
    parameters = {**SCALED, "A": 0.0, "omega": 0.0}
    horizon = max(res.horizon_a, 20_000.0)
    point = PointSettings(run=runner.run("A", parameters=parameters, horizon=horizon,
                                         initial=InitialCondition("equilibrium")), observe=OBSERVE_A)
    [result] = runner.tasks(run_and_measure, [{"point": point, "extras": ["rest_penetration", "creep", "trace"]}])
    m = g = k_n = 1.0
    k_t, mu_s = 0.28, 0.5
    k_d, v_d = SCALED["k_d"], SCALED["V_d"]
    creep = v_d * k_d / (k_t + k_d)
    obs = result["observables"]
    measured = {
        "rest_penetration": result["rest_penetration"], "rest_penetration_formula": m * g / k_n,
        "creep_velocity": result["creep_velocity"], "creep_velocity_formula": creep,
        "stick_time": obs["stick_time_mean"], "stick_time_formula": mu_s * m * g / (k_t * creep),
        "slip_length": obs["slip_length_mean"], "slip_length_formula": mu_s * m * g / k_d,
        "slip_events": obs["slip_events"], "regime": obs["regime"],
    }
    settings = {"model": "A", "parameters": "scaled", **parameters, "horizon": horizon,
                "initial": "equilibrium (plate at rest)", **observe_json(OBSERVE_A)}
    return Study("C1", measured, settings, {"trace": result["trace"]})


def verdict_c1(m: dict) -> Row:
    checks = [("rest penetration", m["rest_penetration"], m["rest_penetration_formula"], PENETRATION_TOLERANCE),
              ("creep V_S", m["creep_velocity"], m["creep_velocity_formula"], FORMULA_TOLERANCE),
              ("stick time", m["stick_time"], m["stick_time_formula"], FORMULA_TOLERANCE),
              ("slip length", m["slip_length"], m["slip_length_formula"], FORMULA_TOLERANCE)]
    measured = ", ".join(f"{name} {fmt(v)} vs {fmt(f)} ({fmt(100 * relative(v, f), 2)} %)"
                         for name, v, f, _ in checks)
    parts = []
    for name, value, formula, tolerance in checks:
        if value is None or not math.isfinite(float(value)):
            parts.append((NOT_REPRODUCED, f"{name} not measured"))
        elif relative(value, formula) <= tolerance:
            parts.append((AGREES, f"{name} within {tolerance:.0%}"))
        else:
            parts.append((DISAGREES, f"{name} off by {relative(value, formula):.0%} > {tolerance:.0%}"))
    verdict, reason = combine(parts)
    return Row("C1", measured, verdict, reason)


CLAIM = Claim("C1", study_c1, verdict_c1, TEXT, FIGURES, None)
